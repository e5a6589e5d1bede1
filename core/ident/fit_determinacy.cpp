// Step 5: which free parameters the data do not determine. A std of 0 claims perfect
// certainty and a NaN is no number; neither is shown as one. A parameter is undetermined when
// its std is 0 or not finite (the loss is flat or singular along it), when it ends on a bound
// (the Gauss approximation of Section 4.4.3 needs an interior minimum), or when its interval
// at the fit's level is wider than its value. The direction the data fix least is the
// largest eigenvector of the free physical parameters' covariance relative to their values.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

#include "core/common/text.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit_internal.h"

namespace flexarm::fit_detail {
namespace {

// "J_a +0.92, k_a -0.39" for the covariance of the named values; empty when it is not finite.
std::string leastFixedDirection(const Eigen::MatrixXd& P, const std::vector<std::string>& names,
                                const std::vector<double>& values) {
  const auto n = P.rows();
  if (n < 2 || P.cols() != n || static_cast<std::size_t>(n) != names.size() || !P.allFinite()) return {};
  Eigen::MatrixXd rel(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const double si = std::max(std::abs(values[static_cast<std::size_t>(i)]), 1e-300);
      const double sj = std::max(std::abs(values[static_cast<std::size_t>(j)]), 1e-300);
      rel(i, j) = P(i, j) / (si * sj);
    }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(rel);
  if (eig.info() != Eigen::Success) return {};
  Eigen::VectorXd v = eig.eigenvectors().col(n - 1);
  Eigen::Index big = 0;
  v.cwiseAbs().maxCoeff(&big);
  if (v(big) < 0) v = -v;
  std::string out;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (std::abs(v(i)) < 0.2) continue;
    char buf[48];
    std::snprintf(buf, sizeof buf, "%+.2f", v(i));
    out += (out.empty() ? "" : ", ") + names[static_cast<std::size_t>(i)] + " " + buf;
  }
  return out;
}

}  // namespace

void assessDeterminacy(const FitOptions& o, FitResult& r) {
  const double z = twoSidedNormalQuantile(o.level);
  const std::string level = shortNumber(100.0 * o.level);
  bool any = false;
  const bool physical = o.model.kind == FitModelKind::Physical;
  for (auto& p : r.parameters) {
    p.determined = true;
    p.undetermined.clear();
    if (!p.free) continue;
    if (!std::isfinite(p.std))
      p.undetermined = "the data give it no finite std: the loss is flat or singular along it";
    else if (p.std <= 0.0)
      p.undetermined = "its std is 0: the loss's curvature along it is singular, not infinite";
    else if (!physical)
      ;  // a black-box coefficient near 0 is no fault of the data
    else if (sitsOnBound(r, p.name))
      p.undetermined = "it sits on a bound, where the curvature's interval does not hold";
    else if (std::isfinite(p.value) && z * p.std > std::abs(p.value))
      p.undetermined = "its " + level + " % interval is wider than its value";
    p.determined = p.undetermined.empty();
    any = any || !p.determined;
  }
  r.undeterminedDirection.clear();
  if (!any || !r.physical) return;
  std::vector<std::string> names;
  std::vector<double> values;
  const auto& params = r.physical->parameters();
  for (int i : r.freeIndices) {
    if (i < 0 || static_cast<std::size_t>(i) >= params.size()) return;
    names.push_back(params[static_cast<std::size_t>(i)].name);
    values.push_back(params[static_cast<std::size_t>(i)].value);
  }
  r.undeterminedDirection = leastFixedDirection(r.covariance, names, values);
}

}  // namespace flexarm::fit_detail
