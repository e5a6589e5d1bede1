#include "core/ident/residuals.h"

#include <cmath>
#include <stdexcept>

#include "core/ident/evaluation.h"

namespace flexarm {

bool ResidualOptions::isValid(std::string* why) const {
  if (maxLag < 1 || !(level > 0.0 && level < 1.0)) {
    if (why) *why = "maxLag must be at least 1 and the level strictly between 0 and 1";
    return false;
  }
  return true;
}

double chiSquareQuantile(double probability, int k) {
  if (k < 1) throw std::invalid_argument("chiSquareQuantile: k must be at least 1");
  const double z = twoSidedNormalQuantile(2.0 * probability - 1.0);  // one-sided quantile
  const double h = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

ResidualAnalysis residualAnalysis(const Eigen::VectorXd& eps0, const Eigen::VectorXd& u0,
                                  const ResidualOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("residualAnalysis: " + why);
  if (eps0.size() != u0.size())
    throw std::invalid_argument("residualAnalysis: residuals and input differ in length");
  const int M = options.maxLag;
  const Eigen::Index n = eps0.size();
  if (n < 2 * M + 10)
    throw std::invalid_argument("residualAnalysis: too few samples for the number of lags");
  const Eigen::VectorXd eps = eps0.array() - eps0.mean();
  const Eigen::VectorXd u = u0.array() - u0.mean();
  const double N = static_cast<double>(n);
  auto cov = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b, int tau) {
    // 1/N sum a(t) b(t - tau)
    if (tau >= 0) return a.tail(n - tau).dot(b.head(n - tau)) / N;
    return a.head(n + tau).dot(b.tail(n + tau)) / N;
  };
  ResidualAnalysis r;
  const double z = twoSidedNormalQuantile(options.level);
  const double re0 = cov(eps, eps, 0), ru0 = cov(u, u, 0);
  std::vector<double> re(M + 1), ru(M + 1);
  for (int tau = 0; tau <= M; ++tau) {
    re[tau] = cov(eps, eps, tau);
    ru[tau] = cov(u, u, tau);
    r.lags.push_back(tau);
    r.autocorrelation.push_back(re0 > 0 ? re[tau] / re0 : 0.0);
  }
  r.autocorrelationBound = z / std::sqrt(N);
  double P = 0.0;
  for (int k = -M; k <= M; ++k)
    P += (re0 > 0 && ru0 > 0) ? re[std::abs(k)] * ru[std::abs(k)] / (re0 * ru0) : 0.0;
  r.crossCorrelationBound = z * std::sqrt(std::max(P, 0.0) / N);
  const double scale = std::sqrt(re0 * ru0);
  for (int tau = -M; tau <= M; ++tau) {
    r.crossLags.push_back(tau);
    r.crossCorrelation.push_back(scale > 0 ? cov(eps, u, tau) / scale : 0.0);
  }
  for (int tau = 1; tau <= M; ++tau) r.whitenessStatistic += N * std::pow(r.autocorrelation[tau], 2);
  r.whitenessThreshold = chiSquareQuantile(options.level, M);
  // Independence from the input at lags 0..M: r = 1/N sum eps(t) [u(t) .. u(t-M)].
  Eigen::VectorXd rv(M + 1);
  Eigen::MatrixXd Ru(M + 1, M + 1);
  for (int i = 0; i <= M; ++i) {
    rv[i] = cov(eps, u, i);
    for (int j = 0; j <= M; ++j) Ru(i, j) = ru[std::abs(i - j)];
  }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(Ru);
  if (re0 > 0 && ru0 > 0 && ldlt.info() == Eigen::Success)
    r.independenceStatistic = N * rv.dot(ldlt.solve(rv)) / re0;
  r.independenceThreshold = chiSquareQuantile(options.level, M + 1);
  r.white = r.whitenessStatistic <= r.whitenessThreshold;
  r.independent = r.independenceStatistic <= r.independenceThreshold;
  const int pct = static_cast<int>(std::lround(options.level * 100));
  r.verdict = std::string(r.white ? "The residuals look white" : "The residuals are not white") +
              " (" + std::to_string(pct) + " % test) and " +
              (r.independent ? "uncorrelated with the input." :
                               "correlated with past inputs: the system model misses dynamics.");
  if (!r.white && r.independent) r.verdict += " The noise model is too simple.";
  return r;
}

}  // namespace flexarm
