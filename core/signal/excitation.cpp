#include "core/signal/excitation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace flexarm {
namespace {

std::string number(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

}  // namespace

std::string deadSignalProblem(const std::vector<double>& values) {
  if (values.empty()) return "holds no samples";
  double lo = values.front(), hi = values.front(), largest = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!std::isfinite(v)) return "has a value that is not a finite number at sample " + std::to_string(i + 1);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    largest = std::max(largest, std::abs(v));
  }
  if (hi == lo) return "is constant (every sample is " + number(lo) + ")";
  if (largest > kMaxSignalScale)
    return "reaches " + number(largest) + " in magnitude, too large for its squares to be summed (at most " +
           number(kMaxSignalScale) + ")";
  if (largest < kMinSignalScale)
    return "is at most " + number(largest) + " in magnitude, too small for its squares to be told from zero (at least " +
           number(kMinSignalScale) + ")";
  // A stuck sensor reading a large value with rounding noise in the last digits: the spread is
  // at the level of double rounding, not a measurement.
  const double spread = hi - lo;
  if (spread <= 1e-12 * largest)
    return "varies by only " + number(spread) + " around " + number(0.5 * (hi + lo)) +
           " (constant to 12 digits: a stuck sensor)";
  return {};
}

std::string deadDataProblem(const IdData& data, const std::vector<std::string>& names) {
  std::vector<const Channel*> channels;
  if (names.empty()) {
    for (ChannelRole role : {ChannelRole::Input, ChannelRole::Output})
      if (const Channel* c = data.withRole(role)) channels.push_back(c);
    // The arm-side encoder, when logged, is measured data too (its fits use it).
    if (const Channel* c = data.channel(columns::kArmAngle); c && std::find(channels.begin(), channels.end(), c) == channels.end())
      channels.push_back(c);
  } else {
    for (const auto& n : names)
      if (const Channel* c = data.channel(n)) channels.push_back(c);
  }
  for (const Channel* c : channels) {
    std::vector<double> values;
    const std::vector<double>* v = &c->values;
    if (!data.isUniform()) {  // NaN marks "not sampled here"
      values.reserve(c->values.size());
      for (double x : c->values)
        if (!std::isnan(x)) values.push_back(x);
      v = &values;
    }
    const std::string problem = deadSignalProblem(*v);
    if (!problem.empty()) return "the channel " + c->name + " carries no signal: it " + problem;
  }
  return {};
}

}  // namespace flexarm
