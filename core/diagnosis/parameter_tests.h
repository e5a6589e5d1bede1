#pragma once
// The tests of the classical approach (the seed's Section 7.4.1) on one monitored parameter,
// fed one recursive estimate at a time. Each returns its statistic, the threshold it is
// compared with and whether it alarms; all compare with theta_0 (the nominal value from
// fault-free data) and its standard deviation sigma_0 (7.4).
#include <cmath>
#include <cstddef>

namespace flexarm {

// What a test says at one sample.
struct TestSample {
  double statistic = 0.0;  // T(t) (or g(t) for the CUSUM)
  double threshold = 0.0;  // the level |T| is compared with (h for the CUSUM)
  // How far past the threshold, as a ratio: |T| / threshold (1 at the threshold). Thresholds
  // scale it: an alarm at threshold c * threshold is ratio > c.
  double ratio = 0.0;
  bool alarm = false;
};

// (7.4), (7.7)-(7.9): T_i(t) = theta_i(t) - theta_0,i, alarm when
// |T_i(t)| > k sqrt(sigma_i(t)^2 + sigma_0,i^2), sigma_i(t) = sqrt(lambda_0 P_ii(t)) (7.8).
class ClassicalTest {
 public:
  ClassicalTest(double theta0, double sigma0, double k) : theta0_(theta0), sigma0_(sigma0), k_(k) {}
  TestSample update(double theta, double sigma) const;

 private:
  double theta0_, sigma0_, k_;
};

// (7.12)-(7.14): the smoothed estimate theta_bar (7.12) and the spread of theta around it
// (7.13), both with forgetting factor lambda; T_i(t) = theta_bar_i(t) - theta_0,i, alarm when
// |T_i| > k sqrt(sigma_i^2 + sigma_0,i^2) with the spread of (7.13). theta_bar is normalised
// by the weights seen so far ((7.10): the mean of the first samples, not a pull towards
// zero), and the spread starts from the estimator's own variance sigma(0)^2 (7.8) and forgets it
// like any old sample, so that the test neither alarms on an empty window nor needs a warm-up.
class RobustTest {
 public:
  RobustTest(double theta0, double sigma0, double k, double lambda)
      : theta0_(theta0), sigma0_(sigma0), k_(k), lambda_(lambda) {}
  // theta: the estimate theta_i(t); sigma: sqrt(lambda_0 P_ii(t)) (used only at the start).
  TestSample update(double theta, double sigma);
  double smoothed() const { return mean_; }
  double spread() const { return std::sqrt(variance_); }

 private:
  double theta0_, sigma0_, k_, lambda_;
  double weight_ = 0.0, mean_ = 0.0, variance_ = 0.0;
  bool started_ = false;
};

// (7.1), (7.15)-(7.17): two CUSUMs of the deviation d = theta_i(t) - theta_0,i run in parallel,
//   g+(t) = max(0, g+(t-1) + d - nu(t)),  g-(t) = max(0, g-(t-1) - d - nu(t)),
// with drift nu(t) = alpha_1 sigma_i(t) and threshold h = alpha_2 |theta_0,i|; the statistic is
// the larger of the two and the test alarms while it exceeds h. As in the seed's Figure 7.3,
// g is not reset at an alarm (resetOnAlarm = false); with the reset of (7.1) it restarts from 0.
class CusumTest {
 public:
  CusumTest(double theta0, double alpha1, double alpha2, bool resetOnAlarm = false)
      : theta0_(theta0), alpha1_(alpha1), h_(alpha2 * std::abs(theta0)), reset_(resetOnAlarm) {}
  TestSample update(double theta, double sigma);
  double upper() const { return up_; }
  double lower() const { return down_; }
  double threshold() const { return h_; }

 private:
  double theta0_, alpha1_, h_;
  bool reset_;
  double up_ = 0.0, down_ = 0.0;
};

}  // namespace flexarm
