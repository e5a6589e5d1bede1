#pragma once
// The hypothesis tests of the seed's Section 7.5.2 as sums over a window: for each predictor
// of the bank (NF: the nominal model theta_0, fixed; F_i: only parameter i estimated
// recursively) the sum of squared prediction errors (7.18)/(7.19), normalised by that of the
// recursive estimate of every monitored parameter ((7.20)/(7.21)):
//   T_NF(t) = sum (y - yhat(theta_0))^2 / sum (y - yhat(theta(k)))^2,
//   T_i(t)  = sum (y - yhat(theta_i(k)))^2 / sum (y - yhat(theta(k)))^2.
// The sums run from the first sample (cumulative, the seed's evaluation) or over the last
// `window` samples (sliding, for on-line use).
#include <cstddef>
#include <vector>

namespace flexarm {

// Running sums of squares over a window of samples (0: cumulative).
class WindowedSum {
 public:
  explicit WindowedSum(std::size_t window = 0) : window_(window) {}
  void add(double value);
  double sum() const { return sum_; }
  std::size_t count() const { return window_ ? std::min(count_, window_) : count_; }

 private:
  std::size_t window_;
  std::vector<double> ring_;
  std::size_t count_ = 0;
  double sum_ = 0.0;
  void recompute();
};

// The normalised statistics of the bank at one sample: index 0 is T_NF, then T_i.
class HypothesisStatistics {
 public:
  // hypotheses: NF plus one per monitored parameter; window in samples (0: cumulative).
  HypothesisStatistics(std::size_t hypotheses, std::size_t window);
  // errors: the prediction error of each hypothesis' predictor (NF first); full: that of the
  // estimate of every parameter. Returns the statistics T_h (7.20)/(7.21).
  const std::vector<double>& update(const std::vector<double>& errors, double full);
  const std::vector<double>& statistics() const { return t_; }

 private:
  std::vector<WindowedSum> sums_;
  WindowedSum full_;
  std::vector<double> t_;
};

}  // namespace flexarm
