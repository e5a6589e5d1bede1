// The verdict of one round: every candidate's statistics against the current model (the
// F-test of its parameters (on the estimation data, correlation-corrected), the AIC, its
// interval, and the held-out test of the change it predicts), the choice among several
// significant candidates by what survives refitting with the other one included, and the
// evidence in words.
#include <algorithm>
#include <cmath>

#include "core/discovery/discovery_internal.h"
#include "core/ident/evaluation.h"

namespace flexarm::discovery_detail {

namespace {

// F statistic of q parameters that lower the loss from `without` to `with` (n_eff samples,
// p parameters in the larger model), and its threshold at the level.
struct FTest {
  double f = 0.0, threshold = 0.0;
  bool passes() const { return f > threshold; }
};
FTest fTest(double without, double with, int q, int p, double nEff, double level) {
  FTest t;
  q = std::max(1, q);
  const double d2 = std::max(1.0, nEff - p);
  t.f = with > 0.0 ? (without - with) / with * d2 / q : 0.0;
  t.threshold = fQuantile(level, q, static_cast<int>(d2));
  return t;
}

}  // namespace

void judgeCandidates(const Context& ctx, const ModelFit& current, std::vector<CandidateWork>& work) {
  const DiscoveryOptions& o = *ctx.options;
  const double nEff = static_cast<double>(ctx.estY.size()) / current.inflation;
  const double aic0 = nEff * std::log(current.loss) + 2.0 * current.parameterCount;
  // The held-out data must bear the effect out (heldOutZ), one-sided at the level.
  const double zThreshold = twoSidedNormalQuantile(2.0 * o.level - 1.0);
  for (auto& w : work) {
    CandidateFit& c = w.fit;
    if (c.termination == Termination::Failed || c.termination == Termination::Cancelled || c.lossEst <= 0.0) {
      c.aic = INFINITY;
      continue;
    }
    c.aic = nEff * std::log(c.lossEst) + 2.0 * c.parameterCount;
    const FTest t = fTest(current.loss, c.lossEst, c.parameterCount - current.parameterCount, c.parameterCount, nEff, o.level);
    c.fStatistic = t.f;
    c.fThreshold = t.threshold;
    const bool aicOk = c.aic < aic0;
    c.heldOutZ = heldOutZ(ctx.valY, current.yhatVal, w.outcome.yhatVal);
    const bool valOk = c.score.rmsValidation <= (1.0 - o.minValidationImprovement) * current.score.rmsValidation &&
                       c.heldOutZ > zThreshold;
    const auto& mp = c.magnitude;
    // Without curvature in the effect's parameter (a backlash gap wider than any deflection
    // in the data leaves the loss flat in b: a motor running free of the arm, which explains
    // much of any data) the effect is not named.
    const bool statistics = t.passes() && aicOk && valOk && c.intervalExcludesZero;
    // Nor is one whose torque is too small to matter against the model's own.
    if (statistics) {
      c.size = effectSize(ctx, w.outcome, w.outcome.effects.size() - 1);
      c.matters = !c.size.measured() || c.size.share() >= o.minTorqueShare;
    }
    c.significant = statistics && c.matters;
    const std::string held = "the held-out residual RMS " + number(current.score.rmsValidation) + " -> " +
                             number(c.score.rmsValidation) + " rad/s (z = " + number(c.heldOutZ, 2) + ")";
    const std::string size = sizeText(c.size);
    if (c.significant) {
      c.reason = "significant: F = " + number(c.fStatistic) + " > " + number(c.fThreshold) + ", " + mp.name +
                 " interval excludes 0, " + held + (size.empty() ? "" : "; " + size);
    } else if (statistics) {
      c.reason = "too small to matter: " + size + " (at least " + number(100.0 * o.minTorqueShare, 2) +
                 " % needed), though " + mp.name + " interval excludes 0 and " + held;
    } else if (!c.intervalExcludesZero) {
      c.reason = "the " + number(100 * o.level, 2) + " % interval of " + mp.name + " [" + number(mp.lower) + ", " +
                 number(mp.upper) + "] includes 0";
    } else if (!t.passes() || !aicOk) {
      c.reason = "the loss drop does not pay for the extra parameters (F = " + number(c.fStatistic) + ", threshold " +
                 number(c.fThreshold) + ")";
    } else {
      c.reason = "not borne out on held-out data: " + held + ", needs z > " + number(zThreshold, 3);
    }
  }
}

std::vector<std::size_t> rankSignificant(const Context& ctx, const ModelFit& current, std::vector<CandidateWork>& work,
                                         const EffectBounds& bounds, std::vector<ModelFit>& pairFits,
                                         std::string& decision, std::vector<EffectKind>& tied) {
  const DiscoveryOptions& o = *ctx.options;
  std::vector<std::size_t> sig;
  for (std::size_t i = 0; i < work.size(); ++i)
    if (work[i].fit.significant) sig.push_back(i);
  auto measure = [&work](std::size_t i) { return work[i].fit.score.rmsValidation; };
  std::sort(sig.begin(), sig.end(), [&](std::size_t a, std::size_t b) { return measure(a) < measure(b); });
  if (sig.size() < 2) return sig;
  // Several explain the data: each pair of the best three refitted together, and every
  // candidate's parameters tested with the other one in the model. An effect that only stood
  // for a look-alike adds nothing once the look-alike is there; two real effects both survive.
  const std::size_t top = std::min<std::size_t>(3, sig.size());
  const double nEff = static_cast<double>(ctx.estY.size()) / current.inflation;
  std::vector<double> survival(work.size(), INFINITY), threshold(work.size(), 0.0);
  std::vector<std::vector<bool>> survives(work.size(), std::vector<bool>(work.size(), true));
  for (std::size_t a = 0; a < top; ++a)
    for (std::size_t b = a + 1; b < top; ++b) {
      if (ctx.cancelled()) return {};
      const std::size_t i = sig[a], j = sig[b];
      ctx.report(-1.0, std::string("refitting ") + toString(work[i].fit.kind) + " with " + toString(work[j].fit.kind));
      // An effect that holds the other as a special case (asymmetric_coulomb and
      // coulomb_friction) is the pair: nothing to refit.
      auto holdsKind = [](EffectKind general, EffectKind special) {
        const auto h = effectDefinition(general).holds();
        return std::find(h.begin(), h.end(), special) != h.end();
      };
      const bool nested = holdsKind(work[i].fit.kind, work[j].fit.kind) || holdsKind(work[j].fit.kind, work[i].fit.kind);
      ModelFit both = nested ? ModelFit{} : fitPair(ctx, work[i], work[j], bounds);
      // A pair search that ended above either effect alone has not found the pair's
      // optimum: the better single fit bounds it.
      const double pairLoss = std::min({both.ok() ? both.loss : INFINITY, work[i].fit.lossEst, work[j].fit.lossEst});
      const int pairCount = nested ? std::max(work[i].fit.parameterCount, work[j].fit.parameterCount)
                                   : work[i].fit.parameterCount + work[j].fit.parameterCount - current.parameterCount;
      for (auto [x, y] : {std::pair{i, j}, std::pair{j, i}}) {
        const FTest t = fTest(work[y].fit.lossEst, pairLoss, pairCount - work[y].fit.parameterCount, pairCount, nEff,
                              o.level);
        survival[x] = std::min(survival[x], t.f);
        threshold[x] = std::max(threshold[x], t.threshold);
        survives[x][y] = t.passes();
      }
      if (both.ok()) pairFits.push_back(std::move(both));
    }
  for (std::size_t a = 0; a < top; ++a) work[sig[a]].fit.survivalF = survival[sig[a]];
  std::vector<std::size_t> ranked(sig.begin(), sig.begin() + static_cast<long>(top));
  auto holds = [&](std::size_t i) { return survival[i] > threshold[i]; };
  std::stable_sort(ranked.begin(), ranked.end(), [&](std::size_t a, std::size_t b) {
    if (holds(a) != holds(b)) return holds(a);
    return holds(a) && survival[a] > survival[b];
  });
  ranked.insert(ranked.end(), sig.begin() + static_cast<long>(top), sig.end());
  std::string names;
  for (std::size_t a = 0; a < top; ++a) names += (names.empty() ? "" : ", ") + std::string(toString(work[sig[a]].fit.kind));
  const std::size_t bi = ranked.front();
  if (!holds(bi)) {
    // None holds its own beside another: they stand for the same thing in the data; the one
    // that predicts the held-out data best comes first, the others tie with it.
    for (std::size_t a = 1; a < top; ++a) tied.push_back(work[ranked[a]].fit.kind);
    decision = names + " are significant, but refitted in pairs none adds to another: they explain the same part "
               "of the data; " + std::string(toString(work[bi].fit.kind)) + " predicts the held-out data best.";
    return ranked;
  }
  decision = names + " are significant alone; refitted in pairs, " + toString(work[bi].fit.kind) +
             "'s parameters pass the F-test with any other in the model (smallest F = " + number(survival[bi]) +
             " > " + number(threshold[bi]) + ")";
  for (std::size_t a = 1; a < top; ++a) {
    const std::size_t i = ranked[a];
    decision += std::string("; ") + toString(work[i].fit.kind) +
                (survives[i][bi] ? " also holds (F = " : " adds nothing once " + std::string(toString(work[bi].fit.kind)) +
                                                             " is in (F = ") +
                number(survival[i]) + ")";
  }
  decision += ".";
  return ranked;
}

std::string roundEvidence(const Context& ctx, const DiscoveryRound& r, const CandidateWork* winner) {
  const DiscoveryOptions& o = *ctx.options;
  const std::string modelName = r.effects.empty() ? "base model" : "model";
  if (!winner) {
    std::string s = "No missing effect: none of the " + std::to_string(r.candidates.size()) +
                    " candidates is significant at " + number(100 * o.level, 2) + " %";
    double bestRms = INFINITY;
    const CandidateFit* closest = nullptr;
    for (const auto& c : r.candidates)
      if (c.termination != Termination::Failed && c.score.rmsValidation < bestRms) {
        bestRms = c.score.rmsValidation;
        closest = &c;
      }
    std::string unconfirmed;
    for (const auto& c : r.candidates)
      if (c.significant && c.confirmation.ran) unconfirmed += " " + std::string(toString(c.kind)) + " is significant but " + c.confirmation.text;
    if (!unconfirmed.empty()) {
      s = "No missing effect confirmed:" + unconfirmed;
    } else if (closest) {
      s += "; the closest, " + std::string(toString(closest->kind)) + ", " + closest->reason;
    }
    s += (unconfirmed.empty() ? ". " : " ") + std::string("The ") + modelName + "'s held-out residual RMS is " +
         number(r.score.rmsValidation) + " rad/s.";
    return s;
  }
  const CandidateFit& b = winner->fit;
  std::string s = effectDefinition(b.kind).describe(b.parameters);
  s[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
  s += "; the " + modelName + "'s residual correlates with the effect's simulated share, rho = " + number(b.rho, 2);
  if (b.kind == EffectKind::CoulombFriction)
    s += ", with the sign of the velocity rho = " + number(r.disagreement.correlationSignVelocity, 2);
  s += "; F = " + number(b.fStatistic) + " > " + number(b.fThreshold) + "; held-out residual RMS " +
       number(r.score.rmsValidation) + " -> " + number(b.score.rmsValidation) + " rad/s (fit " +
       number(r.score.fitPercentValidation) + " -> " + number(b.score.fitPercentValidation) + " %).";
  if (!r.decision.empty()) s += " " + r.decision;
  if (!r.tied.empty()) {
    s += " Tie: ";
    for (std::size_t i = 0; i < r.tied.size(); ++i) s += (i ? ", " : "") + std::string(toString(r.tied[i]));
    s += " explain the data as well; compare them before choosing.";
  }
  // A gap or a delay moves the response in small steps (the integration grid, the moments
  // the gap opens), so the loss is not the smooth quadratic its finite-difference Jacobian
  // assumes near the optimum: the interval from it can be far narrower than the error (issue
  // 13: a 0.2 mrad gap came out 0.187 +- 0.00028 mrad, 46 standard deviations off).
  if (const std::string size = sizeText(b.size); !size.empty()) s += " Its size: " + size + ".";
  if (effectDefinition(b.kind).roughLoss())
    s += " The " + std::string(toString(b.kind)) +
         " interval promises too much: the loss is not smooth in that parameter, so the estimate can be off by many "
         "of its standard deviations.";
  return s;
}

}  // namespace flexarm::discovery_detail
