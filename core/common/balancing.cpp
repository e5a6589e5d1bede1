#include "core/common/balancing.h"

#include <cmath>

namespace flexarm {

Eigen::VectorXd balancingScales(const Eigen::MatrixXd& M0) {
  Eigen::MatrixXd M = M0;
  const Eigen::Index n = M.rows();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  for (int sweep = 0; sweep < 100; ++sweep) {
    bool changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double c0 = M.col(i).cwiseAbs().sum() - std::abs(M(i, i));
      const double r0 = M.row(i).cwiseAbs().sum() - std::abs(M(i, i));
      if (c0 == 0.0 || r0 == 0.0) continue;
      double c = c0, r = r0, f = 1.0;
      while (c < r / 2.0) { c *= 2.0; r /= 2.0; f *= 2.0; }
      while (c >= r * 2.0) { c /= 2.0; r *= 2.0; f /= 2.0; }
      if (f != 1.0 && (c + r) < 0.95 * (c0 + r0)) {
        d[i] *= f;
        M.col(i) *= f;
        M.row(i) /= f;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return d;
}

}  // namespace flexarm
