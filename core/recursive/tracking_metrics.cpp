#include "core/recursive/tracking_metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace flexarm {

TrackingMetrics trackingMetrics(const std::vector<double>& time, const std::vector<double>& theta,
                                const std::function<double(double)>& truth, double before,
                                double after, double from, double band) {
  if (time.size() != theta.size()) throw std::invalid_argument("trackingMetrics: lengths differ");
  TrackingMetrics m;
  const bool change = before != after;
  const double half = 0.5 * (before + after);
  const bool rising = after > before;
  auto passed = [&](double v) { return rising ? v >= half : v <= half; };
  double truthPassed = NAN, estimatePassed = NAN;
  double sum = 0.0;
  int n = 0;
  bool out = false;
  for (std::size_t k = 0; k < time.size(); ++k) {
    const double t = time[k], real = truth(t);
    if (t < from) continue;
    const double e = theta[k] / real - 1.0;
    sum += e * e;
    ++n;
    const bool moved = std::abs(real - before) > 1e-12 * std::abs(before);
    if (!moved) {
      const bool outside = std::abs(e) > band;
      if (outside && !out) ++m.excursions;
      out = outside;
    }
    if (change && std::isnan(truthPassed) && passed(real)) truthPassed = t;
    if (change && !std::isnan(truthPassed) && std::isnan(estimatePassed) && passed(theta[k]))
      estimatePassed = t;
  }
  m.rmsError = n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  if (change)
    m.delayS = std::isnan(estimatePassed) ? std::numeric_limits<double>::infinity()
                                          : estimatePassed - truthPassed;
  return m;
}

}  // namespace flexarm
