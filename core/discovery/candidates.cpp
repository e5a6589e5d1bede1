// One candidate effect fitted together with the current model (the base and every effect
// found so far, all refitted), from a few starts: the effect's response is far from linear in
// its values, so short screening fits pick the start of the full refit.
#include <algorithm>
#include <cmath>
#include <functional>

#include "core/discovery/discovery_internal.h"
#include "core/ident/evaluation.h"

namespace flexarm::discovery_detail {

namespace {

// The search coordinate of an effect value as its definition describes it.
NonlinearCoordinate effectCoordinate(int effect, const EffectSearchCoordinate& ec, bool rough) {
  NonlinearCoordinate c;
  c.base = false;
  c.rough = rough;
  c.effect = effect;
  c.index = ec.index;
  c.scale = ec.scale > 0.0 ? ec.scale : 1.0;
  switch (ec.map) {
    case EffectSearchCoordinate::Map::Log:
      c.map = CoordinateMap::Log;
      if (ec.lower > 0.0) c.minPhi = std::log(ec.lower);
      if (ec.upper > 0.0) c.maxPhi = std::log(ec.upper);
      break;
    case EffectSearchCoordinate::Map::NonNegative: c.map = CoordinateMap::NonNegative; break;
    case EffectSearchCoordinate::Map::Signed: c.map = CoordinateMap::Scaled; break;
    case EffectSearchCoordinate::Map::Fraction: c.map = CoordinateMap::Fraction; break;
  }
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
  f.magnitudes.assign(f.effects.size(), {});
  for (std::size_t e = 0; e < f.effects.size(); ++e) {
    const Effect& fx = f.effects[e];
    const EffectDefinition& d = effectDefinition(fx);
    const auto info = effectParameters(fx);
    // The covariance of this effect's searched values (physical units) and which value each
    // coordinate is.
    std::vector<Eigen::Index> block;
    std::vector<std::size_t> valueOf;
    for (std::size_t j = 0; j < f.problem.coords.size(); ++j) {
      const auto& cj = f.problem.coords[j];
      if (cj.base || cj.effect != static_cast<int>(e)) continue;
      block.push_back(static_cast<Eigen::Index>(j));
      valueOf.push_back(static_cast<std::size_t>(cj.index));
    }
    Eigen::MatrixXd C = block.empty() ? Eigen::MatrixXd() : blockCovariance(sol, block);
    for (std::size_t a = 0; a < block.size(); ++a)
      for (std::size_t b = 0; b < block.size(); ++b) {
        const auto ia = static_cast<Eigen::Index>(a), ib = static_cast<Eigen::Index>(b);
        C(ia, ib) *= f.inflation * f.problem.coords[static_cast<std::size_t>(block[a])].slope(sol.phi[block[a]]) *
                     f.problem.coords[static_cast<std::size_t>(block[b])].slope(sol.phi[block[b]]);
      }
    // The standard deviation of a function of the values by the delta method (a central
    // difference per searched value).
    auto deltaStd = [&](const std::function<double(const std::vector<double>&)>& g) {
      if (block.empty()) return 0.0;
      Eigen::VectorXd grad(static_cast<Eigen::Index>(block.size()));
      for (std::size_t a = 0; a < block.size(); ++a) {
        std::vector<double> up = fx.values, down = fx.values;
        const double h = 1e-6 * (std::abs(fx.values[valueOf[a]]) + f.problem.coords[static_cast<std::size_t>(block[a])].scale);
        up[valueOf[a]] += h;
        down[valueOf[a]] -= h;
        grad[static_cast<Eigen::Index>(a)] = (g(up) - g(down)) / (2.0 * h);
      }
      const double v = grad.dot(C * grad);
      return std::isfinite(v) ? std::sqrt(std::max(0.0, v)) : INFINITY;
    };
    auto estimate = [&](const std::string& name, const std::string& unit, double value, double sd, bool estimated) {
      EffectParameterEstimate p;
      p.name = name;
      p.unit = unit;
      p.value = value;
      p.std = sd;
      p.estimated = estimated;
      p.lower = value - z * sd;
      p.upper = value + z * sd;
      return p;
    };
    for (std::size_t i = 0; i < info.size(); ++i) {
      const auto at = std::find(valueOf.begin(), valueOf.end(), i);
      const bool searched = at != valueOf.end();
      const double sd = searched ? std::sqrt(C(at - valueOf.begin(), at - valueOf.begin())) : 0.0;
      f.estimates[e].push_back(estimate(info[i].name, info[i].unit, fx.values[i], sd, searched));
    }
    for (const auto& q : d.derivedQuantities(fx)) {
      auto p = estimate(q.name, q.unit, q.value(fx.values), deltaStd(q.value), true);
      p.derived = true;
      f.estimates[e].push_back(p);
    }
    f.magnitudes[e] = estimate(d.magnitudeName(), d.displayUnit(), d.magnitude(fx),
                               deltaStd([&d, &fx](const std::vector<double>& v) {
                                 Effect probe = fx;
                                 probe.values = v;
                                 return d.magnitude(probe);
                               }),
                               !block.empty());
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

// An effect's main value profiled on a logarithmic grid up to `range` (the backlash gap up to
// the gear travel the data show), from the current model and the engineer's values: the
// response is far from smooth in it (each contact of a gap moves with it). The best three
// points, with the model they came from.
void profileStarts(const Context& ctx, const NonlinearProblem& pr, const ModelFit& current, Effect e0, int main,
                   double range, std::vector<Effect>& starts, std::vector<const PhysicalModel*>& startModels) {
  const auto at = static_cast<std::size_t>(main);
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
      effects.back().values[at] = gap;
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
    e0.values[at] = grid[i].b;
    starts.push_back(e0);
    startModels.push_back(grid[i].model);
  }
  if (starts.empty()) {
    e0.values[at] = 0.3 * range;
    starts.push_back(e0);
  }
}

}  // namespace

int addEffectCoordinates(NonlinearProblem& pr, int index, const EffectBounds& bounds) {
  const Effect& e = pr.effects[static_cast<std::size_t>(index)];
  const EffectDefinition& d = effectDefinition(e);
  for (const auto& c : d.searchCoordinates(e, bounds)) pr.coords.push_back(effectCoordinate(index, c, d.roughLoss()));
  return d.gridValues(e);
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

void fitCandidate(const Context& ctx, EffectKind kind, const ModelFit& current, const EffectBounds& bounds0,
                  double residualPeakRadS, const ModelFit* warm, CandidateWork& w) {
  const DiscoveryOptions& o = *ctx.options;
  const EffectDefinition& d = effectDefinition(kind);
  EffectBounds bounds = bounds0;
  bounds.residualPeakRadS = residualPeakRadS;
  CandidateFit& c = w.fit;
  c.kind = kind;
  std::vector<Effect> effects = current.effects;
  effects.push_back(Effect::withDefaults(kind));
  ModelFit& f = w.outcome;
  f.start = current.model;
  setupProblem(ctx, f, effects, bounds, 1);
  NonlinearProblem& pr = f.problem;
  const std::size_t at = effects.size() - 1;

  Eigen::VectorXd phi0;
  const auto warmEffects = warm && warm->ok() ? sameKinds(warm->effects, effects) : std::nullopt;
  if (warmEffects && warmEffects->back().values.size() == effects.back().values.size()) {
    // The same effects fitted in the previous round (with the one found since): start there.
    pr.effects = *warmEffects;
    phi0 = coordinatesFrom(pr, *warm->model, *warmEffects);
  } else {
    // The definition's starts (away from the defaults, a grid, or a profile of its main value).
    const EffectSearchPlan plan = d.searchPlan(effects.back(), bounds);
    std::vector<Effect> starts;
    std::vector<const PhysicalModel*> startModels;  // base of each start (default: current)
    if (plan.profileMain) {
      double range = 0.0;
      for (const auto& cj : pr.coords)
        if (!cj.base && cj.effect == static_cast<int>(at) && cj.index == d.mainParameter()) range = std::exp(cj.maxPhi);
      profileStarts(ctx, pr, current, plan.starts.empty() ? effects.back() : plan.starts.front(), d.mainParameter(),
                    range, starts, startModels);
    } else {
      starts = plan.starts;
    }
    if (starts.empty()) starts.push_back(effects.back());
    // Screening: a few iterations from every start (only this effect's coordinates when its
    // response is linear in them and the rest is fitted already).
    LeastSquaresSolution bestSol;
    Effect bestStart = starts.front();
    double bestSum = INFINITY;
    if (starts.size() > 1) {
      for (std::size_t i = 0; i < starts.size() && !ctx.cancelled(); ++i) {
        NonlinearProblem sp = pr;
        if (i < startModels.size()) sp.base = startModels[i];
        sp.effects[at] = starts[i];
        sp.coords = baseCoordinates(*sp.base);
        for (std::size_t e = 0; e < sp.effects.size(); ++e) addEffectCoordinates(sp, static_cast<int>(e), bounds);
        if (plan.screenOwnOnly)
          sp.coords.erase(std::remove_if(sp.coords.begin(), sp.coords.end(),
                                         [at](const NonlinearCoordinate& cj) { return cj.base || cj.effect != static_cast<int>(at); }),
                          sp.coords.end());
        auto sol = sp.solve(sp.coordinatesOf(sp.effects), 3);
        if (sol.eps.size() && sol.sumSquares < bestSum) {
          bestSum = sol.sumSquares;
          bestStart = sp.build(sol.phi).second[at];
          if (!plan.screenOwnOnly && sp.coords.size() == pr.coords.size())
            bestSol = std::move(sol);
          else
            bestSol = LeastSquaresSolution{};
        }
      }
    }
    pr.effects[at] = bestStart;
    phi0 = bestSol.phi.size() ? bestSol.phi : pr.coordinatesOf(pr.effects);
  }
  // A few iterations first: a candidate whose loss has not begun to fall by a quarter of what
  // its F-test asks is not refitted to the end (most candidates of a round explain nothing;
  // their full fits were most of the loop's time).
  const int first = std::min(3, o.candidateIterations);
  f.sol = pr.solve(phi0, first);
  if (f.sol.eps.size() && o.candidateIterations > first && !ctx.cancelled()) {
    const double loss = f.sol.sumSquares / static_cast<double>(f.sol.eps.size());
    const double nEff = static_cast<double>(ctx.estY.size()) / current.inflation;
    const int q = std::max(1, f.parameterCount - current.parameterCount);
    const double d2 = std::max(1.0, nEff - f.parameterCount);
    const double F = loss > 0.0 ? (current.loss - loss) / loss * d2 / q : 0.0;
    if (F > 0.25 * fQuantile(o.level, q, static_cast<int>(d2)))
      f.sol = pr.solve(f.sol.phi, o.candidateIterations - first);
  }
  finishFit(ctx, f);
  // An effect of several terms (the ripple's harmonics) grows while the next term pays for
  // itself: the F-test of its values at the level, on the estimation data.
  while (f.ok() && f.sol.summary.ok() && !ctx.cancelled()) {
    const auto bigger = d.withOneMoreTerm(f.effects[at]);
    if (!bigger) break;
    ModelFit g;
    g.start = f.model;
    std::vector<Effect> grown = f.effects;
    grown[at] = *bigger;
    setupProblem(ctx, g, grown, bounds, 1);
    g.sol = g.problem.solve(g.problem.coordinatesOf(grown), o.candidateIterations);
    finishFit(ctx, g);
    if (!g.ok() || !g.sol.summary.ok()) break;
    const double nEff = static_cast<double>(ctx.estY.size()) / f.inflation;
    const int q = g.parameterCount - f.parameterCount;
    const double d2 = std::max(1.0, nEff - g.parameterCount);
    const double F = g.loss > 0.0 ? (f.loss - g.loss) / g.loss * d2 / std::max(1, q) : 0.0;
    if (!(F > fQuantile(o.level, std::max(1, q), static_cast<int>(d2)))) break;
    f = std::move(g);
  }
  c.termination = ctx.cancelled() ? Termination::Cancelled : f.sol.summary.termination;
  c.parameterCount = f.parameterCount;
  if (!f.sol.summary.ok() || f.sol.eps.size() == 0 || !f.ok()) {
    c.termination = ctx.cancelled() ? Termination::Cancelled : Termination::Failed;
    c.reason = "the fit did not finish: " + f.sol.summary.message;
    c.effect = f.problem.effects[at];
    return;
  }
  c.effect = f.effects[at];
  c.parameters = f.estimates[at];
  c.magnitude = f.magnitudes[at];
  c.effects = f.effects;
  c.effectEstimates = f.estimates;
  c.model = f.model;
  const auto& mp = c.magnitude;
  c.intervalExcludesZero = std::isfinite(mp.std) && (mp.lower > 0.0 || (d.signedMagnitude() && mp.upper < 0.0));
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
    const EffectDefinition& od = effectDefinition(other.fit.kind);
    effects.back() = od.withMagnitude(effects.back(), od.magnitude(effects.back()) * (od.structural() ? 0.5 : 0.1));
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
