// The loop of the discovery method: fit the base (with any effects it starts with), locate
// where it disagrees, fit every candidate with it, name the one that survives (or none),
// confirm it on held-out data, add it, refit the base and every effect found so far together,
// and look again, until nothing is missing or the number asked for is found.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "core/discovery/discovery_internal.h"
#include "core/models/nonlinear_plant.h"

namespace flexarm {

using namespace discovery_detail;

namespace {

using Clock = std::chrono::steady_clock;

// The candidates a round tests on the current model: those asked for that it lacks and can
// take (a gear effect needs a gear spring, a mass a structure below four-mass).
std::vector<EffectKind> candidateKinds(const Context& ctx, const DiscoveryOptions& o, const ModelFit& current) {
  std::vector<EffectKind> kinds;
  for (EffectKind k : o.candidates) {
    if (std::find(kinds.begin(), kinds.end(), k) != kinds.end() || !canJoin(ctx, current, k)) continue;
    kinds.push_back(k);
  }
  return kinds;
}

DiscoveryTrace trace(const NonlinearSeries& s, const std::vector<double>& before, const std::vector<double>& after) {
  DiscoveryTrace t;
  t.time.resize(s.y.size());
  for (std::size_t k = 0; k < s.y.size(); ++k) t.time[k] = s.startTime + static_cast<double>(k) * s.Ts;
  t.measured = s.y;
  t.base = before;
  t.augmented = after;
  return t;
}

}  // namespace

DiscoveryResult discoverMissingEffect(const PhysicalModel& base, const IdData& estimation, const IdData* validation,
                                      const DiscoveryOptions& o, const ProgressCallback& progress) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("discoverMissingEffect: " + why);
  if (!hasGearSpring(base) || base.structureName() == "two-mass-theta")
    throw std::invalid_argument("discoverMissingEffect: the base model needs a gear spring "
                                "(two-mass, three-mass or four-mass), not " + base.structureName());
  {
    std::unique_ptr<PhysicalModel> check(static_cast<PhysicalModel*>(base.clone().release()));
    check->setOptions(ModelOptions{});
    try {
      const NonlinearPlant plant(*check, o.startEffects);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("discoverMissingEffect: the start effects: ") + e.what());
    }
  }
  const auto t0 = Clock::now();
  DiscoveryResult R;
  auto done = [&R, t0](Termination t, std::string msg) {
    R.termination = t;
    R.message = std::move(msg);
    R.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return std::move(R);
  };
  std::atomic<bool> cancel{false};
  Context ctx;
  ctx.options = &o;
  ctx.cancel = &cancel;
  if (!prepareContext(ctx, estimation, validation, &why)) return done(Termination::Failed, why);
  R.sampleTime = ctx.est.Ts;
  R.hasValidation = true;
  R.heldOutSplit = ctx.heldOutSplit;
  R.validationData = ctx.validationData;
  {
    char basis[200];
    std::snprintf(basis, sizeof basis, "%s, with the model's effects, means kept, at %.4g Hz",
                  o.observerBandwidthHz > 0.0
                      ? ("one-step prediction through the " + number(o.observerBandwidthHz) + " Hz load observer").c_str()
                      : "simulation (open loop from the input)",
                  1.0 / ctx.est.Ts);
    R.fitBasis = basis;
  }
  ctx.substeps = o.substeps > 0 ? o.substeps : defaultSubsteps(ctx.est.Ts);
  ctx.observer = loadObserver(base, o.observerBandwidthHz);
  {
    std::unique_ptr<PhysicalModel> nominal(static_cast<PhysicalModel*>(base.clone().release()));
    nominal->setOptions(ModelOptions{});
    ctx.nominal = std::shared_ptr<const PhysicalModel>(std::move(nominal));
  }
  std::mutex progressMutex;
  double lastFraction = 0.0;
  const double rounds = static_cast<double>(o.maxEffects + 1);
  int round = 0;
  double roundStart = 0.0;
  ctx.report = [&](double f, const std::string& stage) {
    std::lock_guard<std::mutex> lock(progressMutex);
    if (f >= 0.0) lastFraction = std::min(1.0, roundStart + f / rounds);
    if (reportProgress(progress, lastFraction, stage)) cancel = true;
  };

  // 1. The base model (with the start effects), all its parameters free.
  ctx.report(0.0, o.startEffects.empty() ? "fitting the base model" : "fitting the base model with its effects");
  const EffectBounds startBounds = effectBounds(ctx.est, {}, *ctx.nominal, o.startEffects);
  ModelFit current = fitModel(ctx, ctx.nominal, o.startEffects, startBounds, o.baseIterations, o.threads);
  if (cancel.load()) return done(Termination::Cancelled, "cancelled by the user");
  if (!current.ok())
    return done(Termination::Failed, "the base model could not be fitted: " +
                                         (current.sol.summary.message.empty() ? std::string("its simulation blows up")
                                                                              : current.sol.summary.message));
  R.baseModel = current.model;
  R.baseParameterCount = current.parameterCount;
  R.baseLoss = current.loss;
  R.base = current.score;
  const std::vector<double> baseEst = current.yhatEst, baseVal = current.yhatValFull;

  // 2. Rounds.
  std::vector<ModelFit> warmFits;
  bool cancelled = false;
  for (;; ++round) {
    roundStart = static_cast<double>(round) / rounds;
    DiscoveryRound D;
    D.effects = current.effects;
    D.model = current.model;
    D.parameterCount = current.parameterCount;
    D.loss = current.loss;
    const double nEff = static_cast<double>(ctx.estY.size()) / current.inflation;
    D.aic = nEff * std::log(current.loss) + 2.0 * current.parameterCount;
    D.score = current.score;
    D.disagreement = mapDisagreement(ctx.est, current.yhatEst, current.deflection, *current.model, current.effects,
                                     current.score, true);
    const EffectBounds bounds = effectBounds(ctx.est, current.deflection, *current.model, current.effects);
    const std::vector<EffectKind> kinds = candidateKinds(ctx, o, current);
    if (kinds.empty()) {
      R.stopReason = "every candidate effect is in the model";
      break;
    }
    std::vector<CandidateWork> work(kinds.size());
    std::atomic<std::size_t> next{0}, finished{0};
    auto worker = [&]() {
      for (;;) {
        const std::size_t i = next++;
        if (i >= kinds.size() || cancel.load()) return;
        const ModelFit* warm = nullptr;
        for (const auto& f : warmFits)
          if (f.ok() && f.effects.size() == current.effects.size() + 1 && hasEffect(f.effects, kinds[i])) warm = &f;
        fitCandidate(ctx, kinds[i], current, bounds, D.disagreement.spectrumPeakRadS, warm, work[i]);
        const std::size_t n = ++finished;
        ctx.report(0.1 + 0.75 * static_cast<double>(n) / static_cast<double>(kinds.size()),
                   (round ? "round " + std::to_string(round + 1) + ": fitted " : std::string("fitted ")) +
                       toString(kinds[i]));
      }
    };
    ctx.report(0.05, round ? "round " + std::to_string(round + 1) + ": fitting the candidate effects"
                           : std::string("fitting the candidate effects"));
    {
      std::vector<std::thread> pool;
      const int nt = std::min<int>(o.threads, static_cast<int>(kinds.size()));
      for (int t = 1; t < nt; ++t) pool.emplace_back(worker);
      worker();
      for (auto& t : pool) t.join();
    }
    if (cancel.load()) {
      cancelled = true;
      break;
    }
    judgeCandidates(ctx, current, work);
    std::vector<ModelFit> pairFits;
    ctx.report(0.88, "choosing among the significant candidates");
    const std::vector<std::size_t> ranked = rankSignificant(ctx, current, work, bounds, pairFits, D.decision, D.tied);
    // The first of them that the second method confirms is named (the best three tried in
    // their order); those passed over are reported apart, as tried. When none confirms, the
    // first is named as it stands, "not confirmed", and the loop ends with it: the list of
    // effects ends with the last one that holds.
    int best = -1;
    bool unconfirmedLast = false;
    for (std::size_t r = 0; r < ranked.size() && r < 3 && best < 0 && !cancel.load(); ++r) {
      const std::size_t i = ranked[r];
      ctx.report(0.93, std::string("confirming ") + toString(work[i].fit.kind));
      work[i].fit.confirmation = confirmEffect(ctx, current, work[i].outcome, work[i].fit.kind, work);
      if (work[i].fit.confirmation.confirmed) best = static_cast<int>(i);
    }
    if (best < 0 && !ranked.empty() && !cancel.load()) {
      best = static_cast<int>(ranked.front());
      unconfirmedLast = true;
    }
    if (cancel.load()) {
      cancelled = true;
      break;
    }
    for (auto& w : work) D.candidates.push_back(w.fit);
    // Tried and rejected: significant but not named, or a real statistic of no size.
    for (const auto& w : work) {
      const CandidateFit& c = w.fit;
      if (static_cast<int>(&w - work.data()) == best) continue;
      const bool noSize = !c.significant && !c.matters;
      if (!c.significant && !noSize) continue;
      DiscoveryResult::Rejected t{round, c.kind, c.effect, c.magnitude, c.size, c.reason};
      if (c.significant)
        t.reason = c.confirmation.ran ? c.confirmation.text
                                      : (best >= 0 ? std::string("significant, but ") +
                                                         toString(work[static_cast<std::size_t>(best)].fit.kind) +
                                                         " explains the data better (" + c.reason + ")"
                                                   : c.reason);
      R.alsoTried.push_back(std::move(t));
    }
    D.best = best;
    if (best < 0) {
      D.estimation = trace(ctx.est, current.yhatEst, current.yhatEst);
      D.validation = trace(ctx.valSeries(), current.yhatValFull, current.yhatValFull);
      D.augmented = D.score;
      D.evidence = roundEvidence(ctx, D, nullptr);
      R.rounds.push_back(std::move(D));
      R.stopReason = "none of the candidates is significant";
      break;
    }
    CandidateWork& w = work[static_cast<std::size_t>(best)];
    D.effect = w.fit.kind;
    D.estimation = trace(ctx.est, current.yhatEst, w.outcome.yhatEst);
    D.validation = trace(ctx.valSeries(), current.yhatValFull, w.outcome.yhatValFull);
    D.augmented = w.outcome.score;
    D.confirmation = w.fit.confirmation;
    D.evidence = roundEvidence(ctx, D, &w);
    if (D.confirmation.ran) {
      std::string c = D.confirmation.text;
      c[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(c[0])));
      D.evidence += " " + c;
    }
    FoundEffect found;
    found.kind = w.fit.kind;
    found.size = w.fit.size;
    found.before = current.score;
    found.after = w.outcome.score;
    found.evidence = D.evidence;
    found.confirmation = D.confirmation;
    R.found.push_back(std::move(found));
    R.rounds.push_back(std::move(D));
    current = std::move(w.outcome);
    warmFits = std::move(pairFits);
    if (unconfirmedLast) {
      R.stopReason = std::string(toString(R.found.back().kind)) +
                     " is significant but not confirmed on the held-out data; the loop ends with it";
      break;
    }
    if (static_cast<int>(R.found.size()) >= o.maxEffects) {
      R.stopReason = o.maxEffects == 1 ? "one effect asked for"
                                       : "the " + std::to_string(o.maxEffects) + " effects asked for are found";
      break;
    }
  }

  // 3. The final model, every effect found refitted together once more to convergence, its
  // values and intervals those of the report.
  if (!R.found.empty() && !cancelled) {
    ctx.report(-1.0, "refitting the final model");
    const EffectBounds bounds = effectBounds(ctx.est, current.deflection, *current.model, current.effects);
    ModelFit polished = fitModel(ctx, current.model, current.effects, bounds, o.baseIterations, o.threads);
    if (polished.ok() && polished.loss <= current.loss) current = std::move(polished);
  }
  // 4. What the final model still needs: an effect named early can have stood in for one named
  // later (a delay for a stiffening spring whose first fit had not found its level), and shrink
  // to nothing once that one is in. Each effect of the final model is set to its null value
  // (the others as fitted, nothing refitted, so the held-out residual rises at least as much as
  // after a refit without it); one whose absence raises the held-out residual by less than a
  // candidate must lower it to be named (minValidationImprovement) is dropped, reported as
  // tried, and the others refitted without it.
  while (R.found.size() > 1 && !cancelled && current.ok()) {
    if (cancel.load()) {
      cancelled = true;
      break;
    }
    auto heldOutRms = [&](const std::vector<Effect>& effects) -> double {
      std::vector<double> y;
      try {
        const NonlinearPlant plant(*current.model, effects);
        if (!predictOutput(plant, ctx.valSeries(), ctx.substeps, ctx.observer, PredictedOutput::DifferentiatedAngle, y))
          return INFINITY;
      } catch (const std::invalid_argument&) {
        return INFINITY;
      }
      return rms(ctx.valY, ctx.pickVal(y));
    };
    const double with = heldOutRms(current.effects);
    if (!std::isfinite(with)) break;
    std::size_t weakest = current.effects.size();
    double weakestRms = INFINITY, weakestGain = INFINITY;
    for (std::size_t e = 0; e < current.effects.size(); ++e) {
      const EffectDefinition& d = effectDefinition(current.effects[e]);
      // Only effects the loop named are weighed (the start effects were the engineer's), and
      // no structural one (a mass changes the base itself).
      bool named = false;
      for (const auto& f : R.found) named = named || f.kind == current.effects[e].kind;
      if (d.structural() || !named) continue;
      std::vector<Effect> without = current.effects;
      without[e] = d.withMagnitude(without[e], 0.0);
      const double rmsWithout = heldOutRms(without);
      const double gain = std::isfinite(rmsWithout) && rmsWithout > 0.0 ? 1.0 - with / rmsWithout : INFINITY;
      if (gain < weakestGain) weakestGain = gain, weakest = e, weakestRms = rmsWithout;
    }
    if (weakest >= current.effects.size() || weakestGain >= o.minValidationImprovement) break;
    const EffectKind dropped = current.effects[weakest].kind;
    ctx.report(-1.0, std::string("refitting the final model without ") + toString(dropped));
    std::vector<Effect> rest = current.effects;
    rest.erase(rest.begin() + static_cast<long>(weakest));
    const EffectBounds bounds = effectBounds(ctx.est, current.deflection, *current.model, rest);
    ModelFit refit = fitModel(ctx, current.model, rest, bounds, o.baseIterations, o.threads);
    if (!refit.ok()) break;
    const auto at = std::find_if(R.found.begin(), R.found.end(), [&](const FoundEffect& f) { return f.kind == dropped; });
    int namedIn = 0;
    for (std::size_t i = 0; i < R.rounds.size(); ++i)
      if (R.rounds[i].effect == dropped) namedIn = static_cast<int>(i);
    DiscoveryResult::Rejected t{namedIn, dropped, current.effects[weakest], current.magnitudes[weakest], at != R.found.end() ? at->size : EffectSize{}, ""};
    t.reason = "named in round " + std::to_string(namedIn + 1) + ", but adds nothing once the effects named after it "
               "are in: set to 0 in the final model, the held-out residual RMS goes only from " + number(with) +
               " to " + number(weakestRms) + " rad/s (" + number(100.0 * weakestGain, 2) + " %, at least " +
               number(100.0 * o.minValidationImprovement, 2) + " % needed); dropped and the rest refitted";
    R.alsoTried.push_back(std::move(t));
    if (at != R.found.end()) R.found.erase(at);
    R.stopReason += "; " + std::string(toString(dropped)) + " dropped from the final model (it adds nothing once the others are in)";
    current = std::move(refit);
  }
  // The final model: every effect found with the values of the last refit.
  for (auto& f : R.found)
    for (std::size_t e = 0; e < current.effects.size(); ++e)
      if (current.effects[e].kind == f.kind) {
        f.effect = current.effects[e];
        f.parameters = current.estimates[e];
        f.magnitude = current.magnitudes[e];
      }
  R.augmentedModel = current.model;
  R.augmentedEffects = current.effects;
  R.augmented = current.score;
  R.estimation = trace(ctx.est, baseEst, current.yhatEst);
  R.validation = trace(ctx.valSeries(), baseVal, current.yhatValFull);
  if (!R.rounds.empty()) {
    const DiscoveryRound& first = R.rounds.front();
    R.effect = first.effect;
    R.tied = first.tied;
    R.evidence = first.evidence;
    R.candidates = first.candidates;
    R.best = first.best;
    R.disagreement = first.disagreement;
    R.baseAic = first.aic;
  }
  ctx.report(1.0, "done");
  std::string names;
  for (const auto& f : R.found) names += (names.empty() ? "" : ", ") + std::string(toString(f.kind));
  if (cancelled)
    return done(Termination::Cancelled, "cancelled by the user after " + std::to_string(R.found.size()) +
                                            " effect" + (R.found.size() == 1 ? "" : "s") +
                                            (names.empty() ? "" : " (" + names + ")"));
  if (R.found.empty()) return done(Termination::Converged, "no missing effect found");
  return done(Termination::Converged, (R.found.size() == 1 ? "missing effect: " : "missing effects: ") + names);
}

}  // namespace flexarm
