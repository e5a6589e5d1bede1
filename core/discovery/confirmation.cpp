// The second method behind a verdict, on data the fits did not see (the validation log, or
// the held-out blocks of the log): (1) the held-out residual with and without the effect: the
// current model's residual regressed on the change the effect predicts; (2) a test specific to the effect, which does not
// reuse the fit's loss: the current model's held-out residual regressed on the effect's own
// signature (the response of the current model to the effect alone: a torque -F_c sign(phi_m')
// for friction, the torque lost in the gear's dead zone for backlash, k beta delta^3 for a
// stiffening spring, the lag of a delay, A sin(n phi_m) for ripple, a mass at omega) beside the
// signatures of every look-alike (each at the size its own fit, or a profile of its size on
// the estimation data, gave) and the base parameters' sensitivities. The coefficient of the
// effect's own signature is its size by this test. The effect is confirmed when both hold at
// the level: the held-out residual falls (one-sided), and its own signature's coefficient is
// positive and no rival's is significantly positive where its own is not (a look-alike that
// explains the residual instead).
#include <algorithm>
#include <cmath>

#include "core/discovery/discovery_internal.h"
#include "core/ident/evaluation.h"
#include "core/models/nonlinear_plant.h"

namespace flexarm::discovery_detail {

namespace {

// The size of a look-alike that has no fit of its own this round: its main value profiled
// on a logarithmic grid (a hundredth to ten times its default) with the current model held.
double profiledSize(const Context& ctx, const ModelFit& current, Effect e) {
  const EffectDefinition& def = effectDefinition(e);
  double d = std::abs(def.magnitude(Effect::withDefaults(e.kind)));
  if (!(d > 0.0)) d = std::abs(effectParameters(e.kind)[static_cast<std::size_t>(def.mainParameter())].defaultValue);
  if (!(d > 0.0)) d = 1e-3;
  double best = d, bestLoss = INFINITY;
  std::vector<double> y;
  for (int i = 0; i <= 12; ++i) {
    e = def.withMagnitude(e, d * std::pow(10.0, -2.0 + 3.0 * i / 12.0));
    std::vector<Effect> effects = current.effects;
    effects.push_back(e);
    try {
      const NonlinearPlant plant(*current.model, effects);
      if (!predictOutput(plant, ctx.est, ctx.substeps, ctx.observer, PredictedOutput::DifferentiatedAngle, y)) continue;
    } catch (const std::invalid_argument&) {
      continue;
    }
    const double l = rms(ctx.estY, ctx.pickEst(y));
    if (l < bestLoss) bestLoss = l, best = def.magnitude(e);
  }
  return best;
}

}  // namespace

Confirmation confirmEffect(const Context& ctx, const ModelFit& current, const ModelFit& augmented, EffectKind kind,
                           const std::vector<CandidateWork>& rivals) {
  const DiscoveryOptions& o = *ctx.options;
  Confirmation C;
  if (current.yhatVal.empty() || augmented.yhatVal.empty() || !current.ok()) return C;
  const NonlinearSeries& v = ctx.valSeries();
  const std::size_t N = ctx.valY.size();
  C.ran = true;
  C.heldOutData = ctx.validationData;
  C.rmsBefore = current.score.rmsValidation;
  C.rmsAfter = augmented.score.rmsValidation;
  C.heldOutZ = heldOutZ(ctx.valY, current.yhatVal, augmented.yhatVal);
  const double zOne = twoSidedNormalQuantile(2.0 * o.level - 1.0);
  const double zTwo = twoSidedNormalQuantile(o.level);
  C.heldOutPasses = C.rmsAfter < C.rmsBefore && C.heldOutZ > zOne;

  // The signatures, each the response of the current model to its probe minus its own.
  const Effect* fitted = nullptr;
  for (const Effect& e : augmented.effects)
    if (e.kind == kind) fitted = &e;
  if (!fitted) return C;
  const EffectDefinition& def = effectDefinition(kind);
  C.fitted = def.magnitude(*fitted);
  C.unit = def.displayUnit();
  C.test = def.signature();
  std::vector<std::vector<double>> columns;
  auto signature = [&](const Effect& e, double size) {
    std::vector<Effect> effects = current.effects;
    effects.push_back(effectDefinition(e).withMagnitude(e, size));
    std::vector<double> y;
    try {
      const NonlinearPlant plant(*current.model, effects);
      if (!predictOutput(plant, v, ctx.substeps, ctx.observer, PredictedOutput::DifferentiatedAngle, y)) return false;
    } catch (const std::invalid_argument&) {
      return false;
    }
    const double h = effectDefinition(e).magnitude(effects.back());
    if (!(std::abs(h) > 0.0)) return false;
    y = ctx.pickVal(y);
    for (std::size_t k = 0; k < N; ++k) y[k] = (y[k] - current.yhatVal[k]) / h;
    columns.push_back(std::move(y));
    return true;
  };
  const double size = std::abs(C.fitted) > 0.0 ? C.fitted : profiledSize(ctx, current, *fitted);
  if (!signature(*fitted, size)) return C;
  // Rivals: every other effect of the seed's six the current model lacks (whether or not it is
  // a candidate), at the values its own candidate fit found this round (ripple and a mass need
  // those: a period count, a frequency), else at a profiled size.
  for (EffectKind k : seedEffectKinds()) {
    if (k == kind || !canJoin(ctx, current, k)) continue;
    const EffectDefinition& rd = effectDefinition(k);
    // Two forms of one effect (asymmetric_coulomb holds coulomb_friction) are no rivals.
    const auto held = rd.holds(), holding = def.holds();
    if (std::find(held.begin(), held.end(), kind) != held.end() ||
        std::find(holding.begin(), holding.end(), k) != holding.end())
      continue;
    const CandidateFit* fit = nullptr;
    for (const auto& w : rivals)
      if (w.fit.kind == k && w.fit.termination != Termination::Failed && !w.fit.parameters.empty()) fit = &w.fit;
    if (!fit && (rd.gridValues(Effect::withDefaults(k)) > 0 || rd.structural())) continue;
    Effect e = fit ? fit->effect : Effect::withDefaults(k);
    const double s = fit && std::abs(rd.magnitude(e)) > 0.0 ? rd.magnitude(e) : profiledSize(ctx, current, e);
    if (signature(e, s)) C.rivals.push_back(toString(k));
  }
  // The base parameters' (and the current effects') sensitivities on the held-out data.
  {
    NonlinearProblem pr = current.problem;
    pr.base = current.model.get();
    pr.effects = current.effects;
    pr.series = {&v};
    const Eigen::VectorXd phi = pr.coordinatesOf(current.effects);
    std::vector<double> y;
    for (std::size_t j = 0; j < pr.coords.size(); ++j) {
      Eigen::VectorXd p2 = phi;
      const auto jj = static_cast<Eigen::Index>(j);
      p2[jj] += pr.coords[j].step(phi[jj]);
      pr.coords[j].project(p2[jj]);
      const double d = p2[jj] - phi[jj];
      if (d == 0.0 || !pr.simulate(p2, v, y)) continue;
      y = ctx.pickVal(y);
      for (std::size_t k = 0; k < N; ++k) y[k] = (y[k] - current.yhatVal[k]) / d;
      columns.push_back(y);
    }
  }
  // Least squares of the held-out residual on every column (each signature per unit of its
  // main value); the first column's coefficient is the effect's size by its signature, its
  // variance corrected for the correlated residual.
  const auto n = static_cast<Eigen::Index>(N);
  const auto m = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd X(n, m);
  Eigen::VectorXd e(n);
  for (Eigen::Index k = 0; k < n; ++k) e[k] = ctx.valY[static_cast<std::size_t>(k)] - current.yhatVal[static_cast<std::size_t>(k)];
  Eigen::VectorXd scale(m);
  for (Eigen::Index j = 0; j < m; ++j) {
    X.col(j) = Eigen::Map<const Eigen::VectorXd>(columns[static_cast<std::size_t>(j)].data(), n);
    scale[j] = X.col(j).norm() > 0.0 ? X.col(j).norm() : 1.0;
    X.col(j) /= scale[j];
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  qr.setThreshold(1e-10);
  const Eigen::VectorXd beta = qr.solve(e);
  const Eigen::VectorXd r = e - X * beta;
  const double sigma2 = r.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, n - qr.rank()));
  // Standard error of beta_j: sigma over the norm of the part of column j the others do not
  // explain.
  const double inflation = correlationInflation(r);
  auto stdOf = [&](Eigen::Index j) {
    Eigen::VectorXd rest = X.col(j);
    if (m > 1) {
      Eigen::MatrixXd others(n, m - 1);
      for (Eigen::Index c = 0, at = 0; c < m; ++c)
        if (c != j) others.col(at++) = X.col(c);
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> q2(others);
      q2.setThreshold(1e-10);
      rest -= others * q2.solve(rest);
    }
    const double norm2 = rest.squaredNorm();
    return norm2 > 1e-12 ? std::sqrt(sigma2 * inflation / norm2) : INFINITY;
  };
  C.value = beta[0] / scale[0];
  C.std = stdOf(0) / scale[0];
  C.z = std::isfinite(C.std) && C.std > 0.0 ? C.value / C.std : 0.0;
  // A rival that explains the residual where this effect does not (its own coefficient
  // positive and significant) rejects it; when neither can be told from the other, the
  // effect's own coefficient must still be positive.
  std::string strongerRival;
  for (std::size_t i = 0; i < C.rivals.size(); ++i) {
    const auto j = static_cast<Eigen::Index>(i + 1);
    const double sd = stdOf(j);
    if (beta[j] > 0.0 && std::isfinite(sd) && beta[j] / sd > zTwo && C.z * (C.fitted < 0.0 ? -1.0 : 1.0) <= zTwo)
      strongerRival += (strongerRival.empty() ? "" : ", ") + C.rivals[i] + " (z = " + number(beta[j] / sd, 3) + ")";
  }
  // The signature's coefficient is the size by this test, per unit of the fitted size: the
  // same sign as the fit's.
  C.specificPasses = C.value * (C.fitted < 0.0 ? -1.0 : 1.0) > 0.0 && std::isfinite(C.std) && strongerRival.empty();
  C.confirmed = C.heldOutPasses && C.specificPasses;

  // The verdict in words.
  const double factor = def.displayFactor();
  const std::string unit = def.displayUnit();
  const std::string pname = def.magnitudeName();
  std::string s = C.confirmed ? "confirmed" : "not confirmed";
  s += " on " + C.heldOutData + ": residual RMS " + number(C.rmsBefore) + " -> " + number(C.rmsAfter) +
       " rad/s (z = " + number(C.heldOutZ, 3) + (C.heldOutPasses ? ", passes" : ", fails") + "); " + C.test;
  if (!C.rivals.empty()) {
    s += ", beside ";
    for (std::size_t i = 0; i < C.rivals.size(); ++i) s += (i ? ", " : "") + C.rivals[i];
    s += " and the base parameters,";
  } else {
    s += ", beside the base parameters,";
  }
  s += " gives " + pname + " = " + number(C.value * factor) + " +- " + number(C.std * factor, 2) + " " + unit +
       " (z = " + number(C.z, 3) + (C.specificPasses ? ", passes" : ", fails") + "; the fit: " +
       number(C.fitted * factor) + " " + unit + ")" +
       (strongerRival.empty() ? std::string(".") : "; " + strongerRival + " explains the residual instead.");
  C.text = s;
  return C;
}

}  // namespace flexarm::discovery_detail
