#include "core/diagnosis/parameter_tests.h"

#include <algorithm>
#include <limits>

#include "core/ident/residuals.h"

namespace flexarm {

namespace {

TestSample compare(double statistic, double threshold) {
  TestSample s;
  s.statistic = statistic;
  s.threshold = threshold;
  const double size = std::abs(statistic);
  s.ratio = threshold > 0.0 ? size / threshold
                            : (size > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  s.alarm = s.ratio > 1.0;
  return s;
}

}  // namespace

TestSample ClassicalTest::update(double theta, double sigma) const {
  return compare(theta - theta0_, k_ * std::sqrt(sigma * sigma + sigma0_ * sigma0_));  // (7.4)
}

TestSample RobustTest::update(double theta, double sigma) {
  if (!started_) {
    variance_ = sigma * sigma;  // prior: the estimator's own variance (7.8)
    started_ = true;
  }
  // (7.10)/(7.12) with the weights normalised: weight_ = sum lambda^(t-k).
  weight_ = lambda_ * weight_ + 1.0;
  const double gain = 1.0 / weight_;
  mean_ += gain * (theta - mean_);
  // (7.13); the prior decays like any old sample, so early on the spread is not zero.
  variance_ = lambda_ * variance_ + (1.0 - lambda_) * (theta - mean_) * (theta - mean_);
  return compare(mean_ - theta0_, k_ * std::sqrt(variance_ + sigma0_ * sigma0_));  // (7.14)
}

TestSample CusumTest::update(double theta, double sigma) {
  const double d = theta - theta0_;
  const double nu = alpha1_ * sigma;  // (7.15), (7.16)
  up_ = std::max(0.0, up_ + d - nu);  // (7.1)
  down_ = std::max(0.0, down_ - d - nu);
  TestSample s = compare(std::max(up_, down_), h_);  // (7.17)
  if (s.alarm && reset_) up_ = down_ = 0.0;
  return s;
}

double jointQuantile(std::size_t p, double k) {
  if (p == 0) return 1.0;
  const double probability = std::erf(k / std::sqrt(2.0));  // P(|z| < k)
  return chiSquareQuantile(probability, static_cast<int>(p));
}

JointTest::JointTest(std::vector<double> theta0, std::vector<double> sigma0, double k,
                     double lambda, double kappa)
    : theta0_(std::move(theta0)), sigma0_(std::move(sigma0)), kappa_(kappa) {
  const std::size_t p = theta0_.size();
  sigma0_.resize(p, 0.0);
  detect_ = jointQuantile(p, k);
  isolate_ = jointQuantile(p > 1 ? p - 1 : 1, k);
  for (std::size_t i = 0; i < p; ++i) smooth_.emplace_back(theta0_[i], sigma0_[i], 1.0, lambda);
  out_.assign(p + 1, TestSample{});
  alignment_.assign(p, 0.0);
}

const std::vector<TestSample>& JointTest::update(const Eigen::VectorXd& theta,
                                                 const Eigen::VectorXd& sigma,
                                                 const Eigen::MatrixXd& P) {
  const auto p = static_cast<Eigen::Index>(theta0_.size());
  Eigen::VectorXd d(p), sd(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    const auto si = static_cast<std::size_t>(i);
    smooth_[si].update(theta[i], sigma[i]);  // (7.12), (7.13)
    d[i] = smooth_[si].smoothed() - theta0_[si];
    sd[i] = std::sqrt(smooth_[si].spread() * smooth_[si].spread() + sigma0_[si] * sigma0_[si]);
  }
  // C = D R D: the spreads with the correlations of P.
  Eigen::MatrixXd C(p, p);
  for (Eigen::Index i = 0; i < p; ++i)
    for (Eigen::Index j = 0; j < p; ++j) {
      const double denominator = std::sqrt(P(i, i) * P(j, j));
      const double rho = i == j ? 1.0 : (denominator > 0.0 ? P(i, j) / denominator : 0.0);
      C(i, j) = rho * sd[i] * sd[j];
    }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(C);
  const bool usable = ldlt.info() == Eigen::Success && sd.minCoeff() > 0.0 && d.allFinite();
  const Eigen::VectorXd w = usable ? Eigen::VectorXd(ldlt.solve(d)) : Eigen::VectorXd::Zero(p);
  chi2_ = usable ? std::max(0.0, d.dot(w)) : 0.0;
  out_[0] = compare(chi2_, detect_);
  out_[0].statistic = chi2_;
  Eigen::VectorXd e = Eigen::VectorXd::Zero(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    double a = 0.0;
    if (usable) {
      e.setZero();
      e[i] = 1.0;
      const double ce = ldlt.solve(e)[i];  // e_i^T C^-1 e_i
      a = ce > 0.0 ? w[i] * w[i] / ce : 0.0;  // (e_i^T C^-1 d)^2 / (e_i^T C^-1 e_i)
    }
    const double r = std::max(0.0, chi2_ - a);
    alignment_[static_cast<std::size_t>(i)] = chi2_ > 0.0 ? std::min(1.0, a / chi2_) : 0.0;
    out_[static_cast<std::size_t>(i) + 1] = compare(r, std::max(isolate_, kappa_ * chi2_));
  }
  return out_;
}

}  // namespace flexarm
