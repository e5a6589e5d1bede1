// The small numeric and naming helpers every part of the discovery method uses: residual
// RMS and fit %, correlations and their variance inflation, the F quantile, options checks.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/discovery/discovery_internal.h"
#include "core/ident/evaluation.h"

namespace flexarm {

const std::vector<EffectKind>& discoveryCandidateKinds() {
  static const std::vector<EffectKind> kinds = [] {
    std::vector<EffectKind> v;
    for (EffectKind k : allEffectKinds())
      if (effectDefinition(k).discoveryCandidate()) v.push_back(k);
    return v;
  }();
  return kinds;
}

bool DiscoveryOptions::isValid(std::string* why) const {
  auto fail = [why](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (candidates.empty()) return fail("at least one candidate effect is needed");
  auto candidate = [](EffectKind k) { return effectDefinition(k).discoveryCandidate(); };
  for (EffectKind k : candidates)
    if (!candidate(k)) return fail(std::string(toString(k)) + " is not a candidate of discovery; fit it with fit --effect");
  for (const Effect& e : startEffects)
    if (!candidate(e.kind))
      return fail(std::string("the start effect ") + toString(e.kind) + " is not one discovery refits; fit it with fit --effect");
  for (std::size_t i = 0; i < startEffects.size(); ++i) {
    std::string reason;
    if (!startEffects[i].isValid(&reason)) return fail("start effect: " + reason);
    for (std::size_t j = 0; j < i; ++j)
      if (startEffects[j].kind == startEffects[i].kind)
        return fail(std::string("the start effect ") + toString(startEffects[i].kind) + " is given twice");
  }
  if (maxEffects < 1 || maxEffects > 6) return fail("the number of effects to find must be in 1..6");
  if (!(observerBandwidthHz >= 0.0) || !std::isfinite(observerBandwidthHz))
    return fail("the observer bandwidth must be >= 0 Hz");
  if (!(maxRateHz > 0.0)) return fail("the maximum rate must be positive");
  if (substeps < 0 || substeps > 200) return fail("substeps must be in 0..200");
  if (baseIterations < 1 || candidateIterations < 1) return fail("iterations must be >= 1");
  if (!(level > 0.5 && level < 1.0)) return fail("the level must be in (0.5, 1)");
  if (!(minValidationImprovement >= 0.0 && minValidationImprovement < 1.0))
    return fail("the minimum validation improvement must be in [0, 1)");
  if (!(heldOutFraction >= 0.1 && heldOutFraction <= 0.5))
    return fail("the held-out part of the log must be in [0.1, 0.5]");
  if (!(tieTolerance >= 0.0 && tieTolerance < 1.0)) return fail("the tie tolerance must be in [0, 1)");
  if (!(minTorqueShare >= 0.0 && minTorqueShare < 1.0)) return fail("the minimum torque share must be in [0, 1)");
  if (threads < 1 || threads > 64) return fail("threads must be in 1..64");
  if (why) why->clear();
  return true;
}

double fQuantile(double p, int d1, int d2) {
  if (d1 < 1 || d2 < 1 || !(p > 0.0 && p < 1.0))
    throw std::invalid_argument("fQuantile: needs d1, d2 >= 1 and 0 < p < 1");
  // Paulson's normal approximation of the cube root of F, solved for the quantile.
  const double z = twoSidedNormalQuantile(2.0 * p - 1.0);
  const double c1 = 2.0 / (9.0 * d1), c2 = 2.0 / (9.0 * d2);
  const double a = 1.0 - c2, b = 1.0 - c1;
  const double qa = a * a - z * z * c2;
  const double disc = std::max(0.0, a * a * b * b - qa * (b * b - z * z * c1));
  const double w = (a * b + std::sqrt(disc)) / qa;
  return w * w * w;
}

std::pair<std::unique_ptr<PhysicalModel>, std::vector<Effect>> mergedModel(const PhysicalModel& model,
                                                                           const std::vector<Effect>& effects) {
  std::unique_ptr<PhysicalModel> m(static_cast<PhysicalModel*>(model.clone().release()));
  std::vector<Effect> rest;
  for (const Effect& e : effects) {
    const EffectDefinition& d = effectDefinition(e);
    if (!d.structural()) {
      rest.push_back(e);
      continue;
    }
    std::string why;
    auto bigger = d.structure(*m, e, &why);
    if (!bigger) throw std::invalid_argument(why);
    m = std::move(bigger);
  }
  return {std::move(m), std::move(rest)};
}

namespace discovery_detail {

double rms(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return a.empty() ? 0.0 : std::sqrt(s / static_cast<double>(a.size()));
}

void setFit(DiscoveryScore& s, bool validation, const std::vector<double>& y, const std::vector<double>& yhat) {
  FitPercents f{-INFINITY, -INFINITY};
  double r = INFINITY;
  if (!yhat.empty() && yhat.size() == y.size()) {
    const Eigen::Map<const Eigen::VectorXd> a(y.data(), static_cast<Eigen::Index>(y.size()));
    const Eigen::Map<const Eigen::VectorXd> b(yhat.data(), static_cast<Eigen::Index>(yhat.size()));
    f = fitPercents(a, b);
    r = rms(y, yhat);
  }
  (validation ? s.fitPercentValidation : s.fitPercent) = f.seed52;
  (validation ? s.fitPercentValidationNrmse : s.fitPercentNrmse) = f.nrmse;
  (validation ? s.rmsValidation : s.rmsEstimation) = r;
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n < 2) return 0.0;
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < n; ++k) ma += a[k], mb += b[k];
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t k = 0; k < n; ++k) {
    sab += (a[k] - ma) * (b[k] - mb);
    saa += (a[k] - ma) * (a[k] - ma);
    sbb += (b[k] - mb) * (b[k] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

// Variance inflation 1 + 2 sum (1 - k/(M+1)) rho(k) of a correlated residual (Bartlett): the
// number of independent samples is N divided by it.
double correlationInflation(const Eigen::VectorXd& e) {
  const Eigen::Index N = e.size();
  const Eigen::Index M = std::min<Eigen::Index>(100, N / 4);
  const double r0 = e.squaredNorm();
  if (!(r0 > 0.0)) return 1.0;
  double s = 1.0;
  for (Eigen::Index k = 1; k <= M; ++k) {
    const double rk = e.head(N - k).dot(e.tail(N - k)) / r0;
    s += 2.0 * (1.0 - static_cast<double>(k) / static_cast<double>(M + 1)) * rk;
  }
  return std::max(1.0, s);
}

// Variance of coordinate j by the Gauss approximation, lambda / |psi_j - P psi_j|^2 with P
// the projection on the other columns of psi (rank-revealing QR): the (j, j) element of
// lambda (psi^T psi)^{-1} when that exists, and still meaningful when other parameters are
// collinear among themselves; infinite when psi_j lies in their span.
double conditionalVariance(const LeastSquaresSolution& sol, Eigen::Index j) {
  const Eigen::MatrixXd& psi = sol.psi;
  const Eigen::Index n = psi.rows(), p = psi.cols();
  if (n <= p) return INFINITY;
  const double lambda = sol.sumSquares / static_cast<double>(n - p);
  Eigen::MatrixXd others(n, p - 1);
  for (Eigen::Index c = 0, o = 0; c < p; ++c)
    if (c != j) others.col(o++) = psi.col(c);
  Eigen::VectorXd rest = psi.col(j);
  if (p > 1) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(others);
    qr.setThreshold(1e-9);
    const Eigen::VectorXd coef = qr.solve(rest);
    rest -= others * coef;
  }
  const double norm2 = rest.squaredNorm();
  if (!(norm2 > 1e-12 * psi.col(j).squaredNorm()) || !(norm2 > 0.0)) return INFINITY;
  return lambda / norm2;
}

double heldOutZ(const std::vector<double>& y, const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = y.size();
  if (n < 10 || a.size() != n || b.size() != n) return 0.0;
  Eigen::VectorXd share(static_cast<Eigen::Index>(n)), e(static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) {
    share[static_cast<Eigen::Index>(k)] = b[k] - a[k];
    e[static_cast<Eigen::Index>(k)] = y[k] - a[k];
  }
  const double ss = share.squaredNorm();
  if (!(ss > 0.0)) return 0.0;
  const double c = share.dot(e) / ss;
  const Eigen::VectorXd r = e - c * share;
  const double var = r.squaredNorm() / static_cast<double>(n - 1) * correlationInflation(r) / ss;
  return var > 0.0 ? c / std::sqrt(var) : 0.0;
}

double percentile99(const std::vector<double>& a) {
  if (a.empty()) return 0.0;
  std::vector<double> m(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) m[k] = std::abs(a[k]);
  const std::size_t q = std::min(m.size() - 1, m.size() * 99 / 100);
  std::nth_element(m.begin(), m.begin() + static_cast<long>(q), m.end());
  return m[q];
}

bool hasGearSpring(const PhysicalModel& m) {
  return !m.topology().gearStiffness.empty() && m.topology().gearDeflectionState >= 0;
}

std::string number(double v, int digits) { return effect_text::number(v, digits); }

std::string plusMinus(const EffectParameterEstimate& p, double factor) { return effect_text::plusMinus(p, factor); }

Eigen::MatrixXd blockCovariance(const LeastSquaresSolution& sol, const std::vector<Eigen::Index>& block) {
  const Eigen::MatrixXd& psi = sol.psi;
  const Eigen::Index n = psi.rows(), p = psi.cols();
  const auto b = static_cast<Eigen::Index>(block.size());
  Eigen::MatrixXd inf = Eigen::MatrixXd::Constant(b, b, INFINITY);
  if (n <= p || b == 0) return inf;
  const double lambda = sol.sumSquares / static_cast<double>(n - p);
  Eigen::MatrixXd S(n, b), others(n, p - b);
  for (Eigen::Index c = 0, o = 0; c < p; ++c) {
    const auto at = std::find(block.begin(), block.end(), c);
    if (at != block.end()) S.col(at - block.begin()) = psi.col(c);
    else others.col(o++) = psi.col(c);
  }
  if (p > b) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(others);
    qr.setThreshold(1e-9);
    S -= others * qr.solve(S);
  }
  const Eigen::MatrixXd G = S.transpose() * S;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(G);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * std::max(1e-300, ldlt.vectorD().maxCoeff())))
    return inf;
  return lambda * ldlt.solve(Eigen::MatrixXd::Identity(b, b));
}

std::string structureWith(const PhysicalModel& base, const std::vector<Effect>& effects) {
  static const char* kOrder[] = {"rigid", "two-mass", "three-mass", "four-mass"};
  int at = -1;
  for (int i = 0; i < 4; ++i)
    if (base.structureName() == kOrder[i]) at = i;
  if (at < 0) return base.structureName();
  for (const Effect& e : effects)
    if (effectDefinition(e).structural()) ++at;
  return at <= 3 ? kOrder[at] : "larger than four-mass";
}

bool hasEffect(const std::vector<Effect>& effects, EffectKind k) {
  return std::any_of(effects.begin(), effects.end(), [k](const Effect& e) { return e.kind == k; });
}

bool canJoin(const Context& ctx, const ModelFit& current, EffectKind k) {
  if (hasEffect(current.effects, k) || !current.model) return false;
  const EffectDefinition& d = effectDefinition(k);
  if (d.needsGearSpring() && !hasGearSpring(*current.model)) return false;
  if (d.structural() && structureWith(*current.model, current.effects) == "four-mass") return false;
  if (d.needsArmEncoder() && ctx.est.deflection.empty()) return false;
  const auto held = d.holds();
  for (const Effect& e : current.effects) {
    const auto others = effectDefinition(e).holds();
    if (std::find(others.begin(), others.end(), k) != others.end()) return false;
    if (std::find(held.begin(), held.end(), e.kind) != held.end()) return false;
  }
  return true;
}

}  // namespace discovery_detail
}  // namespace flexarm
