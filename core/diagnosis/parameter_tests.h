#pragma once
// The tests of the classical approach (the seed's Section 7.4.1) on one monitored parameter,
// fed one recursive estimate at a time. Each returns its statistic, the threshold it is
// compared with and whether it alarms; all compare with theta_0 (the nominal value from
// fault-free data) and its standard deviation sigma_0 (7.4).
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Dense>

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

// The joint test of the change vector (what the seed's 9.2 leaves open: the correlation
// between the parameters). The change d = theta_bar(t) - theta_0 of every monitored parameter
// at once, theta_bar the smoothed estimates of (7.12), is measured in the metric of its
// covariance C: the spread of each estimate (7.13) (plus sigma_0^2 (7.4)) on the diagonal and
// the correlations of the estimates from the full P(t) (6.13)/(6.18) off it,
//   chi2(t) = d^T C^-1 d,
// against q_p, the chi-square quantile of p degrees of freedom at the two-sided probability of
// k sigma (p = 3, k = 3: 14.2, i.e. 3.77^2). Isolation is by the change's direction: a
// fault in parameter i moves theta along e_i, which explains the part
// a_i = (e_i^T C^-1 d)^2 / (e_i^T C^-1 e_i) of chi2 and leaves r_i = chi2 - a_i. The test
// quantities follow the decision structure of the hypothesis tests (Section 7.5.2):
//   T_NF = chi2 / q_p                   (NF rejected: a change is detected)
//   T_i  = r_i / max(q_(p-1), kappa chi2) (F_i rejected: the change does not lie along
//                                         e_i; kappa = 0.25 is 30 degrees in C's metric)
// so S = {F_i} when a change is detected and only e_i explains its direction. Per-parameter
// tests read each estimate alone, so that a change in one parameter that drags a correlated
// estimate along can fire the wrong column; the direction sees the pair together.
class JointTest {
 public:
  // theta0, sigma0: per monitored parameter (theta's form); k: the "3 sigma"; lambda: the
  // smoothing (7.12)/(7.13); kappa: the isolation angle's cos^2 complement.
  JointTest(std::vector<double> theta0, std::vector<double> sigma0, double k, double lambda,
            double kappa = 0.25);
  // theta, sigma: the estimates and sqrt(lambda_0 P_ii); P: the full P(t). Returns T_NF, then
  // T_i per parameter.
  const std::vector<TestSample>& update(const Eigen::VectorXd& theta, const Eigen::VectorXd& sigma,
                                        const Eigen::MatrixXd& P);
  double chiSquare() const { return chi2_; }
  // Per parameter: the share of chi2 its direction explains, a_i / chi2 (0..1).
  const std::vector<double>& alignment() const { return alignment_; }

 private:
  std::vector<double> theta0_, sigma0_;
  double kappa_, detect_, isolate_;
  std::vector<RobustTest> smooth_;
  std::vector<TestSample> out_;
  std::vector<double> alignment_;
  double chi2_ = 0.0;
};

// The chi-square quantile the joint test compares with for p parameters and k sigma: the
// quantile at P(|z| < k) of p degrees of freedom (1 when p = 0).
double jointQuantile(std::size_t p, double k);

}  // namespace flexarm
