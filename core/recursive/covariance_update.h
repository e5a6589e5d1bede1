#pragma once
// The P update and gain of the two RPEM algorithms, shared by the estimator and the pre-run
// that chooses P(0):
//  forgetting factor (Algorithm 6.1): P(t|t-1) = P(t-1) / lambda regularised by (6.9),
//      K = P(t|t-1) psi / (1 + psi^T P(t|t-1) psi), P(t) = P(t|t-1) - K psi^T P(t|t-1),
//      which is (6.13)/(6.14) when mu = 0;
//  Kalman (Algorithm 6.2): K = P(t-1) psi / (R2 + psi^T P(t-1) psi),
//      P(t) = P(t-1) - K psi^T P(t-1) + R1 regularised by (6.9), i.e. (6.18)/(6.19).
#include <Eigen/Dense>

#include "core/recursive/rpem.h"

namespace flexarm {

class CovarianceUpdate {
 public:
  // r1: diag R1 (used by the Kalman algorithm only).
  CovarianceUpdate(RecursiveAlgorithm algorithm, double lambda, Eigen::VectorXd r1, double r2,
                   double mu);
  // Updates P in place and sets K. False when psi^T P psi + (1 or R2) is not a positive
  // finite number (P is then left as it was).
  // lambda > 0 replaces the forgetting factor for this update (variable forgetting).
  bool operator()(const Eigen::VectorXd& psi, Eigen::MatrixXd& P, Eigen::VectorXd& K,
                  double lambda = 0.0);

 private:
  // P (I + mu P)^{-1} (6.9), in place.
  void regularise(Eigen::MatrixXd& P) const;

  RecursiveAlgorithm algorithm_;
  double lambda_, r2_, mu_;
  Eigen::VectorXd r1_;
  Eigen::MatrixXd prior_;
  Eigen::VectorXd Ppsi_;
};

}  // namespace flexarm
