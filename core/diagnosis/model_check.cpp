#include "core/diagnosis/model_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace flexarm {

ModelCheck checkModel(const std::vector<double>& time, const std::vector<double>& epsilon,
                      const Eigen::VectorXd& input, double noiseVariance, double averageS,
                      double persistS, double from, double threshold, std::vector<double>* ratio) {
  if (time.size() != epsilon.size() || static_cast<std::size_t>(input.size()) < time.size())
    throw std::invalid_argument("checkModel: time, errors and input differ in length");
  if (!(noiseVariance > 0.0)) throw std::invalid_argument("checkModel: lambda_0 must be positive");
  ModelCheck c;
  c.threshold = threshold;
  const std::size_t n = time.size();
  std::vector<double> r(n, 0.0);
  if (n < 2) {
    if (ratio) *ratio = r;
    c.message = "too few samples to check the model";
    return c;
  }
  const double T = (time.back() - time.front()) / static_cast<double>(n - 1);
  const auto window = std::max<std::size_t>(1, static_cast<std::size_t>(averageS / T + 0.5));
  const auto persist = std::max<std::size_t>(1, static_cast<std::size_t>(persistS / T + 0.5));
  double sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    sum += epsilon[k] * epsilon[k];
    if (k >= window) sum -= epsilon[k - window] * epsilon[k - window];
    const std::size_t count = std::min(k + 1, window);
    r[k] = std::max(0.0, sum) / static_cast<double>(count) / noiseVariance;
  }
  // Decide only on whole windows after settling.
  std::vector<double> live;
  std::size_t above = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (time[k] < from - 1e-12 || k + 1 < window) continue;
    live.push_back(r[k]);
    above = r[k] > threshold ? above + 1 : 0;
    if (!c.mismatch && above >= persist) {
      c.mismatch = true;
      c.time = time[k];
      const std::size_t begin = k + 1 - persist;
      const Eigen::Map<const Eigen::VectorXd> e(epsilon.data() + begin, static_cast<Eigen::Index>(persist));
      ResidualOptions ro;
      if (static_cast<int>(persist) >= 2 * ro.maxLag + 10) {
        c.residuals = residualAnalysis(e, input.segment(static_cast<Eigen::Index>(begin),
                                                         static_cast<Eigen::Index>(persist)), ro);
        c.residualsTested = true;
      }
    }
  }
  if (ratio) *ratio = r;
  if (live.empty()) {
    c.message = "too few samples after settling to check the model";
    return c;
  }
  c.checked = true;
  std::vector<double> sorted = live;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  c.medianRatio = sorted[sorted.size() / 2];
  c.peakRatio = *std::max_element(live.begin(), live.end());
  char buf[400];
  if (!c.mismatch) {
    std::snprintf(buf, sizeof buf,
                  "The model fits: with the monitored parameters re-estimated the prediction errors "
                  "stay at the fault-free level (their mean square over %.3g s is %.2f times lambda_0 "
                  "at the median, %.2f at most; a mismatch is above %.2f for %.3g s).",
                  averageS, c.medianRatio, c.peakRatio, threshold, persistS);
    c.message = buf;
    return c;
  }
  std::snprintf(buf, sizeof buf,
                "with every monitored parameter re-estimated, the prediction errors stayed above %.2f "
                "times the fault-free mean square for %.3g s (until %.2f s; %.2f times at the median "
                "of the run, %.2f at most)",
                threshold, persistS, *c.time, c.medianRatio, c.peakRatio);
  c.what = buf;
  if (c.residualsTested) {
    std::string how;
    if (!c.residuals.white) how += "they are not white";
    if (!c.residuals.independent)
      how += std::string(how.empty() ? "they" : " and") + " correlate with past inputs";
    if (how.empty()) how = "yet they are white and uncorrelated with past inputs";
    c.what += "; " + how + " (residual tests at 99 %)";
  }
  c.what += ": no change of a monitored parameter explains the data";
  c.message = "The model no longer fits: " + c.what + ".";
  return c;
}

}  // namespace flexarm
