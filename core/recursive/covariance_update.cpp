#include "core/recursive/covariance_update.h"

#include <cmath>
#include <utility>

namespace flexarm {

CovarianceUpdate::CovarianceUpdate(RecursiveAlgorithm algorithm, double lambda, Eigen::VectorXd r1,
                                   double r2, double mu)
    : algorithm_(algorithm), lambda_(lambda), r2_(r2), mu_(mu), r1_(std::move(r1)) {}

void CovarianceUpdate::regularise(Eigen::MatrixXd& P) const {
  if (mu_ <= 0.0) return;
  const Eigen::Index p = P.rows();
  const Eigen::MatrixXd M = Eigen::MatrixXd::Identity(p, p) + mu_ * P;
  P = M.partialPivLu().solve(P);  // (I + mu P)^{-1} P = P (I + mu P)^{-1}: they commute
  P = 0.5 * (P + P.transpose()).eval();
}

bool CovarianceUpdate::operator()(const Eigen::VectorXd& psi, Eigen::MatrixXd& P,
                                  Eigen::VectorXd& K, double lambda) {
  const bool forgetting = algorithm_ == RecursiveAlgorithm::ForgettingFactor;
  prior_ = P;
  if (forgetting) {
    prior_ /= lambda > 0.0 ? lambda : lambda_;
    regularise(prior_);
  }
  Ppsi_.noalias() = prior_ * psi;
  const double s = (forgetting ? 1.0 : r2_) + psi.dot(Ppsi_);
  if (!(s > 0.0) || !std::isfinite(s)) return false;
  K = Ppsi_ / s;
  prior_.noalias() -= K * Ppsi_.transpose();
  if (!forgetting) {
    prior_.diagonal() += r1_;
    regularise(prior_);
  }
  P = 0.5 * (prior_ + prior_.transpose());
  return true;
}

}  // namespace flexarm
