// One candidate effect fitted together with the current model (the base and every effect
// found so far, all refitted), from a few starts: the effect's response is far from linear in
// its values, so short screening fits pick the start of the full refit.
#include <algorithm>
#include <cmath>

#include "core/discovery/discovery_internal.h"
#include "core/ident/evaluation.h"

namespace flexarm::discovery_detail {

namespace {

NonlinearCoordinate effectCoordinate(int effect, int index, CoordinateMap map, EffectKind kind) {
  NonlinearCoordinate c;
  c.base = false;
  c.rough = true;
  c.effect = effect;
  c.index = index;
  c.map = map;
  c.scale = std::abs(effectParameters(kind)[static_cast<std::size_t>(index)].defaultValue);
  return c;
}

// The problem of a base with effects over the estimation data, its coordinates set.
void setupProblem(const Context& ctx, ModelFit& f, const std::vector<Effect>& effects, const EffectBounds& bounds,
                  int threads) {
  NonlinearProblem& pr = f.problem;
  pr.base = f.start.get();
  pr.effects = effects;
  pr.series = {&ctx.est};
  pr.substeps = ctx.substeps;
  pr.observer = ctx.observer;
  pr.cancel = ctx.cancel;
  pr.threads = threads;
  pr.coords = baseCoordinates(*f.start);
  f.gridParameters = 0;
  for (std::size_t i = 0; i < effects.size(); ++i)
    f.gridParameters += addEffectCoordinates(pr, static_cast<int>(i), bounds);
  f.parameterCount = static_cast<int>(pr.coords.size()) + f.gridParameters;
}

// Model, effects, scores and estimates of a finished search.
void finishFit(const Context& ctx, ModelFit& f) {
  const LeastSquaresSolution& sol = f.sol;
  if (sol.eps.size() == 0 || ctx.cancelled()) return;
  auto built = f.problem.build(sol.phi);
  f.effects = built.second;
  f.inflation = correlationInflation(sol.eps);
  f.loss = sol.sumSquares / static_cast<double>(sol.eps.size());
  if (!f.problem.simulate(sol.phi, ctx.est, f.yhatEst, &f.deflection)) return;
  setFit(f.score, false, ctx.estY, ctx.pickEst(f.yhatEst));
  if (ctx.valLog) {
    if (!f.problem.simulate(sol.phi, *ctx.valLog, f.yhatValFull)) f.yhatValFull.clear();
  } else {
    f.yhatValFull = f.yhatEst;
  }
  f.yhatVal = ctx.pickVal(f.yhatValFull);
  setFit(f.score, true, ctx.valY, f.yhatVal);
  const double z = twoSidedNormalQuantile(ctx.options->level);
  f.estimates.assign(f.effects.size(), {});
  for (std::size_t e = 0; e < f.effects.size(); ++e) {
    const auto& info = effectParameters(f.effects[e].kind);
    for (std::size_t i = 0; i < info.size(); ++i) {
      EffectParameterEstimate p;
      p.name = info[i].name;
      p.unit = info[i].unit;
      p.value = f.effects[e].values[i];
      p.estimated = false;
      for (std::size_t j = 0; j < f.problem.coords.size(); ++j) {
        const auto& cj = f.problem.coords[j];
        if (cj.base || cj.effect != static_cast<int>(e) || cj.index != static_cast<int>(i)) continue;
        p.estimated = true;
        const double slope = cj.slope(sol.phi[static_cast<Eigen::Index>(j)]);
        p.std = std::abs(slope) * std::sqrt(f.inflation * conditionalVariance(sol, static_cast<Eigen::Index>(j)));
      }
      p.lower = p.value - z * p.std;
      p.upper = p.value + z * p.std;
      f.estimates[e].push_back(p);
    }
  }
  f.model = std::shared_ptr<const PhysicalModel>(std::move(built.first));
}

// Coordinates of `to`'s base and effects in from's coordinate system (same free parameters,
// same effects in the same order), projected into its bounds.
Eigen::VectorXd coordinatesFrom(const NonlinearProblem& pr, const PhysicalModel& base, const std::vector<Effect>& effects) {
  NonlinearProblem tmp = pr;
  tmp.base = &base;
  Eigen::VectorXd x = tmp.coordinatesOf(effects);
  for (std::size_t i = 0; i < pr.coords.size(); ++i) pr.coords[i].project(x[static_cast<Eigen::Index>(i)]);
  return x;
}

// warm's effects in the order of `effects` (the same kinds in any order); nullopt otherwise.
std::optional<std::vector<Effect>> sameKinds(const std::vector<Effect>& warm, const std::vector<Effect>& effects) {
  if (warm.size() != effects.size()) return std::nullopt;
  std::vector<Effect> out;
  for (const Effect& e : effects) {
    auto it = std::find_if(warm.begin(), warm.end(), [&e](const Effect& w) { return w.kind == e.kind; });
    if (it == warm.end()) return std::nullopt;
    out.push_back(*it);
  }
  return out;
}

// The backlash gap profiled on a logarithmic grid up to the gear travel the data show, from
// the current model and the engineer's values: the response is far from smooth in the gap b
// (each contact moves with it). The best three points, with the model they came from.
void backlashStarts(const Context& ctx, const NonlinearProblem& pr, const ModelFit& current, Effect e0, double range,
                    std::vector<Effect>& starts, std::vector<const PhysicalModel*>& startModels) {
  struct GridPoint {
    double loss;
    const PhysicalModel* model;
    double b;
  };
  std::vector<GridPoint> grid;
  std::vector<double> yhat;
  const int points = 24;
  auto gapAt = [range, points](double i) { return range * std::pow(10.0, -2.0 + 2.0 * i / (points - 1)); };
  std::vector<Effect> effects = current.effects;
  effects.push_back(e0);
  for (const PhysicalModel* m : {current.model.get(), ctx.nominal.get()}) {
    NonlinearProblem gp = pr;
    gp.base = m;
    auto lossAt = [&](double gap) {
      effects.back().values[0] = gap;
      return gp.simulate(gp.coordinatesOf(effects), ctx.est, yhat) ? rms(ctx.estY, ctx.pickEst(yhat)) : INFINITY;
    };
    double bestLoss = INFINITY;
    int best = -1;
    for (int i = 0; i < points && !ctx.cancelled(); ++i) {
      const double l = lossAt(gapAt(i));
      if (l < bestLoss) bestLoss = l, best = i;
    }
    if (best < 0) continue;
    // The minimum is sharp (a gap a little too wide loses the contacts): golden-section
    // search between the neighbouring grid points.
    double a = best - 1.0, c = best + 1.0;
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double x1 = c - g * (c - a), x2 = a + g * (c - a);
    double f1 = lossAt(gapAt(x1)), f2 = lossAt(gapAt(x2));
    for (int it = 0; it < 8 && !ctx.cancelled(); ++it) {
      if (f1 < f2) {
        c = x2, x2 = x1, f2 = f1;
        x1 = c - g * (c - a);
        f1 = lossAt(gapAt(x1));
      } else {
        a = x1, x1 = x2, f1 = f2;
        x2 = a + g * (c - a);
        f2 = lossAt(gapAt(x2));
      }
    }
    grid.push_back({bestLoss, m, gapAt(best)});
    grid.push_back({std::min(f1, f2), m, gapAt(f1 < f2 ? x1 : x2)});
  }
  std::sort(grid.begin(), grid.end(), [](const GridPoint& a, const GridPoint& b) { return a.loss < b.loss; });
  for (std::size_t i = 0; i < grid.size() && i < 3; ++i) {
    e0.values[0] = grid[i].b;
    starts.push_back(e0);
    startModels.push_back(grid[i].model);
  }
  if (starts.empty()) {
    e0.values[0] = 0.3 * range;
    starts.push_back(e0);
  }
}

}  // namespace

int addEffectCoordinates(NonlinearProblem& pr, int index, const EffectBounds& bounds) {
  const Effect& e = pr.effects[static_cast<std::size_t>(index)];
  switch (e.kind) {
    case EffectKind::CoulombFriction:  // F_c searched, the smoothing speed v_s held
    case EffectKind::NonlinearSpring:
    case EffectKind::InputDelay:
      pr.coords.push_back(effectCoordinate(index, 0, CoordinateMap::NonNegative, e.kind));
      return 0;
    case EffectKind::TorqueRipple:  // A searched; n chosen on a grid, counted as a parameter
      pr.coords.push_back(effectCoordinate(index, 0, CoordinateMap::NonNegative, e.kind));
      return 1;
    case EffectKind::Backlash: {
      // A gap wider than the gear travel the data show is a motor that never meets the arm:
      // its loss is flat in b and its interval does not exclude zero.
      const double range = std::max({bounds.gapRange, 3.0 * e.value(0), 1e-3 * effectParameters(e.kind)[0].defaultValue});
      auto c = effectCoordinate(index, 0, CoordinateMap::Log, e.kind);
      c.minPhi = std::log(1e-3 * range);
      c.maxPhi = std::log(range);
      pr.coords.push_back(c);
      return 0;
    }
    case EffectKind::ExtraMass: {
      // The new mode lies within a band around the model's resonance that the data inform
      // (0.25 to 6 times it): far below it a mass on a very soft spring would stand for a
      // motor running free of the arm, which is not a mass the arm has.
      auto c = effectCoordinate(index, 0, CoordinateMap::Log, e.kind);
      const double w = std::max(bounds.resonanceRadS, 1e-3);
      c.minPhi = std::log(std::min(0.25 * w, 0.5 * e.value(0)));
      c.maxPhi = std::log(std::max(6.0 * w, 2.0 * e.value(0)));
      pr.coords.push_back(c);
      pr.coords.push_back(effectCoordinate(index, 1, CoordinateMap::Fraction, e.kind));
      return 0;
    }
  }
  return 0;
}

ModelFit fitModel(const Context& ctx, std::shared_ptr<const PhysicalModel> start, const std::vector<Effect>& effects,
                  const EffectBounds& bounds, int iterations, int threads, const Eigen::VectorXd* phi0) {
  ModelFit f;
  f.start = std::move(start);
  setupProblem(ctx, f, effects, bounds, threads);
  const Eigen::VectorXd x0 = phi0 ? *phi0 : f.problem.coordinatesOf(effects);
  f.sol = f.problem.solve(x0, iterations);
  finishFit(ctx, f);
  return f;
}

void fitCandidate(const Context& ctx, EffectKind kind, const ModelFit& current, const EffectBounds& bounds,
                  double residualPeakRadS, const ModelFit* warm, CandidateWork& w) {
  const DiscoveryOptions& o = *ctx.options;
  CandidateFit& c = w.fit;
  c.kind = kind;
  std::vector<Effect> effects = current.effects;
  effects.push_back(Effect::withDefaults(kind));
  ModelFit& f = w.outcome;
  f.start = current.model;
  setupProblem(ctx, f, effects, bounds, 1);
  NonlinearProblem& pr = f.problem;
  const auto& info = effectParameters(kind);
  const std::size_t at = effects.size() - 1;
  Effect e0 = effects.back();

  Eigen::VectorXd phi0;
  const auto warmEffects = warm && warm->ok() ? sameKinds(warm->effects, effects) : std::nullopt;
  if (warmEffects) {
    // The same effects fitted in the previous round (with the one found since): start there.
    phi0 = coordinatesFrom(pr, *warm->model, *warmEffects);
    pr.effects = *warmEffects;
  } else {
    // Starts well away from the defaults (half of them, or a grid).
    std::vector<Effect> starts;
    std::vector<const PhysicalModel*> startModels;  // base of each start (default: current)
    switch (kind) {
      case EffectKind::CoulombFriction:
        e0.values[0] = 0.5 * info[0].defaultValue;
        starts.push_back(e0);
        break;
      case EffectKind::Backlash:
        backlashStarts(ctx, pr, current, e0, std::exp(pr.coords.back().maxPhi), starts, startModels);
        break;
      case EffectKind::NonlinearSpring:
      case EffectKind::InputDelay:
        // Responses far from linear in the value: a few starts over a decade.
        for (double x : {0.2, 0.5, 1.2}) {
          e0.values[0] = x * info[0].defaultValue;
          starts.push_back(e0);
        }
        break;
      case EffectKind::TorqueRipple:
        e0.values[0] = 0.5 * info[0].defaultValue;
        for (int n = 1; n <= 12; ++n) {
          Effect e = e0;
          e.values[1] = n;
          starts.push_back(e);
        }
        break;
      case EffectKind::ExtraMass: {
        const double w0 = bounds.resonanceRadS;
        std::vector<double> omegas = {0.5 * w0, 0.8 * w0, 1.3 * w0, 2.0 * w0};
        if (residualPeakRadS > 1.2 * w0) omegas.push_back(residualPeakRadS);
        for (double om : omegas) {
          Effect e = e0;
          e.values[0] = om;
          e.values[1] = 0.25;
          starts.push_back(e);
        }
        break;
      }
    }
    // Screening: a few iterations from every start; the ripple grid fits A alone (linear in A).
    LeastSquaresSolution bestSol;
    Effect bestStart = starts.front();
    double bestSum = INFINITY;
    if (starts.size() > 1) {
      for (std::size_t i = 0; i < starts.size() && !ctx.cancelled(); ++i) {
        NonlinearProblem sp = pr;
        if (i < startModels.size()) sp.base = startModels[i];
        sp.effects[at] = starts[i];
        if (kind == EffectKind::TorqueRipple) sp.coords.erase(sp.coords.begin(), sp.coords.end() - 1);  // A only
        auto sol = sp.solve(sp.coordinatesOf(sp.effects), 3);
        if (sol.eps.size() && sol.sumSquares < bestSum) {
          bestSum = sol.sumSquares;
          bestStart = sp.build(sol.phi).second[at];
          if (kind != EffectKind::TorqueRipple) bestSol = std::move(sol);
        }
      }
    }
    pr.effects[at] = bestStart;
    phi0 = bestSol.phi.size() ? bestSol.phi : pr.coordinatesOf(pr.effects);
  }
  f.sol = pr.solve(phi0, o.candidateIterations);
  finishFit(ctx, f);
  c.termination = ctx.cancelled() ? Termination::Cancelled : f.sol.summary.termination;
  c.parameterCount = f.parameterCount;
  if (!f.sol.summary.ok() || f.sol.eps.size() == 0 || !f.ok()) {
    c.termination = ctx.cancelled() ? Termination::Cancelled : Termination::Failed;
    c.reason = "the fit did not finish: " + f.sol.summary.message;
    c.effect = pr.effects[at];
    return;
  }
  c.effect = f.effects[at];
  c.parameters = f.estimates[at];
  c.effects = f.effects;
  c.effectEstimates = f.estimates;
  c.model = f.model;
  const auto& mp = c.parameters[static_cast<std::size_t>(mainParameter(kind))];
  c.intervalExcludesZero = std::isfinite(mp.std) && mp.lower > 0.0;
  c.lossEst = f.loss;
  c.score = f.score;
  std::vector<double> share(f.yhatEst.size());
  std::vector<double> eCurrent(f.yhatEst.size());
  for (std::size_t k = 0; k < share.size(); ++k) {
    share[k] = f.yhatEst[k] - current.yhatEst[k];
    eCurrent[k] = ctx.est.y[k] - current.yhatEst[k];
  }
  c.rho = correlation(eCurrent, share);
}

ModelFit fitPair(const Context& ctx, const CandidateWork& first, const CandidateWork& second,
                 const EffectBounds& bounds) {
  // From each of the two fits, the other effect at a tenth of its own value (where one effect
  // stood in for both, its look-alike's own value is far from the shared optimum); the
  // better of the two searches.
  ModelFit best;
  for (const auto* from : {&first, &second}) {
    const CandidateWork& other = from == &first ? second : first;
    std::vector<Effect> effects = from->outcome.effects;
    effects.push_back(other.fit.effect);
    const int m = mainParameter(other.fit.kind);
    effects.back().values[static_cast<std::size_t>(m)] *= m == 0 ? 0.1 : 0.5;
    ModelFit f;
    f.start = from->outcome.model;
    setupProblem(ctx, f, effects, bounds, ctx.options->threads);
    const Eigen::VectorXd phi0 = f.problem.coordinatesOf(effects);
    f.sol = f.problem.solve(phi0, ctx.options->candidateIterations);
    finishFit(ctx, f);
    if (f.ok() && (!best.ok() || f.loss < best.loss)) best = std::move(f);
  }
  return best;
}

}  // namespace flexarm::discovery_detail
