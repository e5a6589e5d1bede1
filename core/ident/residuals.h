#pragma once
// Residual analysis as SITB's resid: autocorrelation of the prediction errors and their
// cross-correlation with the input for lags 0..M, with 99 % bounds and test verdicts.
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace flexarm {

struct ResidualOptions {
  int maxLag = 25;      // M
  double level = 0.99;  // confidence level of bounds and tests
  bool isValid(std::string* why) const;
};

struct ResidualAnalysis {
  std::vector<int> lags;                 // 0..M
  std::vector<double> autocorrelation;   // r_eps(tau) / r_eps(0)
  double autocorrelationBound = 0.0;     // z / sqrt(N)
  std::vector<int> crossLags;            // -M..M
  std::vector<double> crossCorrelation;  // r_eps,u(tau) / sqrt(r_eps(0) r_u(0)), eps(t) u(t-tau)
  double crossCorrelationBound = 0.0;    // z sqrt(P/N), P = sum r_eps(k) r_u(k) normalized
  // Portmanteau statistic N sum_{tau=1..M} r^2 against the chi^2(M) quantile.
  double whitenessStatistic = 0.0, whitenessThreshold = 0.0;
  // N r^T (lambda R_u)^{-1} r over lags 0..M against the chi^2(M+1) quantile (Ljung (16.61)).
  double independenceStatistic = 0.0, independenceThreshold = 0.0;
  bool white = false;        // residuals pass the whiteness test
  bool independent = false;  // residuals uncorrelated with past inputs
  std::string verdict;       // a sentence for the user
};

// Correlation tests on residuals eps and input u (same length, at least 2 M + 10 samples;
// throws std::invalid_argument otherwise).
ResidualAnalysis residualAnalysis(const Eigen::VectorXd& eps, const Eigen::VectorXd& u,
                                  const ResidualOptions& options = {});

// Quantile of the chi-square distribution with k degrees of freedom (Wilson-Hilferty).
double chiSquareQuantile(double probability, int k);

}  // namespace flexarm
