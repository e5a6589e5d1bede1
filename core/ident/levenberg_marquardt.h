#pragma once
// The damped Gauss-Newton / Levenberg-Marquardt search (4.17)-(4.21) shared by the black-box
// and grey-box prediction-error estimators: R = sum psi psi^T (4.21) plus lambda diag(R).
#include <functional>
#include <vector>

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
  // Optional, used instead of evaluate when set: the sum of squared errors at phi and, when R
  // and g are non-null, the normal equations R = psi^T psi (N times (4.21)) and g = psi^T eps
  // (-N times (4.19)), for problems that reduce psi as they form it (psi is then never
  // stored). The evaluation may stop as soon as the sum exceeds `bound` and return that
  // partial sum (R and g are then not set): such a step is rejected anyway. Returns false
  // when phi is not admissible.
  std::function<bool(const Eigen::VectorXd& phi, double bound, double& sumSquares,
                     Eigen::MatrixXd* R, Eigen::VectorXd* g)>
      normalEquations;
  Eigen::Index samples = 0;  // N, the number of errors, when normalEquations is used
};

struct LeastSquaresSolution {
  Eigen::VectorXd phi, eps;
  Eigen::MatrixXd psi;  // at phi; eps and psi stay empty when the problem gives normalEquations
  Eigen::MatrixXd R;    // psi^T psi at phi, with normalEquations only
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
// The same from R = psi^T psi of N rows.
Eigen::MatrixXd gaussNewtonCovariance(const Eigen::MatrixXd& R, Eigen::Index n, double sumSquares);

// Long-run covariance Q = Var(sum_i psi_i^T eps_i) of sums of regressors (columns of psi_i,
// treated as given) times stationary, possibly coloured and mutually correlated errors eps_i:
// Q = sum_{i,j} sum_{|tau| <= lags} w_tau R_ij(tau) sum_t psi_i(t) psi_j(t - tau)^T, with the
// error covariances R_ij(tau) = (1/N) sum_t eps_i(t) eps_j(t - tau) weighted by the Bartlett
// (Newey-West) window w_tau = 1 - |tau| / (lags + 1). Computed with FFTs in O(N log N p^2).
// Every psi_i has N rows and the same columns; every eps_i N entries.
struct RegressorErrorPair {
  const Eigen::MatrixXd* psi;
  const Eigen::VectorXd* eps;
};
Eigen::MatrixXd longRunCovariance(const std::vector<RegressorErrorPair>& terms, int lags);

// Covariance of the least-squares estimate that holds when the errors are coloured (and
// independent of psi): the sandwich H^{-1} Q H^{-1} N / (N - p) with H = sum psi psi^T
// (4.21) and Q = longRunCovariance({psi, eps}), the sample form of R^{-1} Q R^{-1} / N for
// coloured noise (Ljung's (9.17), which (4.37) simplifies for white noise). With white errors
// and lags = 0 it equals gaussNewtonCovariance. Empty when H is singular.
Eigen::MatrixXd sandwichCovariance(const Eigen::MatrixXd& psi, const Eigen::VectorXd& eps,
                                   int lags);

// Lag window for the sandwich: a tenth of the record (at least 10 lags): the errors' long
// correlations (slow disturbances) must fit inside the window.
int automaticCovarianceLags(const Eigen::VectorXd& eps);

// Sets loss (4.6), FPE and AIC from the sum of squared errors of N samples and p parameters.
void fillStatistics(EstimateSummary& s, double sumSquares, Eigen::Index n, int p);

}  // namespace flexarm
