#pragma once
// The damped Gauss-Newton / Levenberg-Marquardt search (4.17)-(4.21) shared by the black-box
// and grey-box prediction-error estimators: R = sum psi psi^T (4.21) plus lambda diag(R).
#include <functional>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"

namespace flexarm {

struct LeastSquaresProblem {
  // Prediction errors eps at phi and, when psi is non-null, psi = -d eps / d phi (4.20).
  // Returns false when phi is not admissible (e.g. an unstable predictor).
  std::function<bool(const Eigen::VectorXd& phi, Eigen::VectorXd& eps, Eigen::MatrixXd* psi)>
      evaluate;
  // Maps a trial point into the admissible set (bounds, reflected roots); may be empty.
  std::function<void(Eigen::VectorXd& phi)> project;
};

struct LeastSquaresSolution {
  Eigen::VectorXd phi, eps;
  Eigen::MatrixXd psi;  // at phi
  double sumSquares = 0.0;
  EstimateSummary summary;  // termination, message, iterations, lossHistory (mean squares)
};

// Minimizes sum eps^2 from phi0. Fails with a sentence when phi0 is not admissible.
LeastSquaresSolution levenbergMarquardt(const LeastSquaresProblem& problem,
                                        const Eigen::VectorXd& phi0, int maxIterations,
                                        double relativeTolerance, double initialDamping,
                                        const ProgressCallback& progress = {});

// Covariance lambda (psi^T psi)^{-1} with lambda = sumSquares / (N - p); empty when singular.
Eigen::MatrixXd gaussNewtonCovariance(const Eigen::MatrixXd& psi, double sumSquares);

// Sets loss (4.6), FPE and AIC from the sum of squared errors of N samples and p parameters.
void fillStatistics(EstimateSummary& s, double sumSquares, Eigen::Index n, int p);

}  // namespace flexarm
