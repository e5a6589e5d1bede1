#include "core/diagnosis/parameter_tests.h"

#include <algorithm>
#include <limits>

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

}  // namespace flexarm
