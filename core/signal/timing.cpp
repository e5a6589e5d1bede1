#include "core/signal/timing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

namespace flexarm {
namespace {

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Slope b of t = a + b s, robustly: the median of the slopes between the samples half the log
// apart (long baselines for precision, the median against jittered samples).
double fitSlope(const std::vector<double>& t, const std::vector<long>& s, const std::vector<std::size_t>& use,
                double b) {
  const std::size_t half = use.size() / 2;
  std::vector<double> slopes;
  slopes.reserve(use.size() - half);
  for (std::size_t q = 0; q + half < use.size(); ++q) {
    const std::size_t i = use[q], k = use[q + half];
    if (s[k] > s[i]) slopes.push_back((t[k] - t[i]) / static_cast<double>(s[k] - s[i]));
  }
  if (slopes.empty()) return b;
  auto mid = slopes.begin() + static_cast<std::ptrdiff_t>(slopes.size() / 2);
  std::nth_element(slopes.begin(), mid, slopes.end());
  return *mid;
}

// Grid start a for the interval b: the median of t - b s, so that the samples on the grid
// lie on it exactly however the jittered ones deviate.
double gridStartFor(const std::vector<double>& t, const std::vector<long>& s, const std::vector<std::size_t>& use,
                    double b) {
  std::vector<double> r;
  r.reserve(use.size());
  for (std::size_t i : use) r.push_back(t[i] - b * static_cast<double>(s[i]));
  auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  return *mid;
}

}  // namespace

const char* toString(TimingEventKind k) {
  switch (k) {
    case TimingEventKind::Jitter: return "jitter";
    case TimingEventKind::Gap: return "gap";
    case TimingEventKind::Duplicate: return "duplicate";
    case TimingEventKind::Reversal: return "reversal";
  }
  return "jitter";
}

std::optional<TimingEventKind> timingEventKindFromString(std::string_view s) {
  for (TimingEventKind k : {TimingEventKind::Jitter, TimingEventKind::Gap, TimingEventKind::Duplicate,
                            TimingEventKind::Reversal})
    if (s == toString(k)) return k;
  return std::nullopt;
}

bool TimingOptions::isValid(std::string* why) const {
  if (!(jitterTolerance > 0.0 && jitterTolerance < 0.5)) {
    if (why) *why = "the jitter tolerance must lie between 0 and 0.5 of the interval";
    return false;
  }
  if (!(declaredRateHz >= 0.0) || !std::isfinite(declaredRateHz)) {
    if (why) *why = "the declared sample rate must be positive (or 0 for none)";
    return false;
  }
  return true;
}

std::string formatted(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string durationText(double seconds) {
  return std::abs(seconds) < 1.0 ? formatted("%.4g ms", seconds * 1e3) : formatted("%.4g s", seconds);
}

std::string placeOf(const TimingEvent& e) {
  return e.line > 0 ? "line " + std::to_string(e.line) : "sample " + std::to_string(e.index);
}

std::string TimingReport::summary() const {
  if (samples < 2) return "fewer than two samples";
  if (interval <= 0.0) return "every sample has the same time stamp";
  const std::string grid = durationText(interval) + " interval (" + formatted("%.6g", rateHz()) + " Hz)";
  if (regular()) return "regular: " + std::to_string(samples) + " samples, " + grid;
  std::vector<std::string> parts;
  if (gaps) {
    std::string s = plural(gaps, "gap", "gaps") + " (" + plural(static_cast<std::size_t>(missing), "sample", "samples") +
                    " missing, the longest " + durationText(longestGap) + " at " + formatted("%.6g s", longestGapTime);
    for (const auto& e : events)
      if (e.kind == TimingEventKind::Gap && e.size == longestGap && e.line > 0) {
        s += ", line " + std::to_string(e.line);
        break;
      }
    parts.push_back(s + ")");
  }
  if (jitter)
    parts.push_back(plural(jitter, "jittered sample", "jittered samples") + " (up to " +
                    formatted("%.2g", 100.0 * largestJitter) + " % of the interval)");
  if (duplicates) parts.push_back(plural(duplicates, "duplicate time stamp", "duplicate time stamps"));
  if (reversals) parts.push_back(plural(reversals, "reversal", "reversals") + " (time running backwards)");
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? (i + 1 == parts.size() ? " and " : ", ") : "") + parts[i];
  return out + " on a " + grid + " grid";
}

TimingReport analyzeTiming(const std::vector<double>& t, const std::vector<int>& lines,
                           const TimingOptions& o) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("analyzeTiming: " + why);
  if (!lines.empty() && lines.size() != t.size())
    throw std::invalid_argument("analyzeTiming: lines and time stamps differ in number");
  for (double v : t)
    if (!std::isfinite(v)) throw std::invalid_argument("analyzeTiming: a time stamp is not finite");
  TimingReport r;
  const std::size_t n = t.size();
  r.samples = n;
  if (n == 0) return r;
  auto lineOf = [&](std::size_t i) { return lines.empty() ? 0 : lines[i]; };
  std::vector<TimingEvent> events;
  auto add = [&](TimingEventKind kind, std::size_t i, double size, long missing = 0) {
    events.push_back({kind, i, lineOf(i), t[i], size, missing});
  };
  for (std::size_t i = 1; i < n; ++i)
    if (t[i] < t[i - 1]) {
      add(TimingEventKind::Reversal, i, t[i - 1] - t[i]);
      ++r.reversals;
    }

  // Sorted order, the nominal interval (median positive step) and each sample's grid slot.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
  std::vector<double> steps;
  steps.reserve(n);
  for (std::size_t j = 1; j < n; ++j) {
    const double d = t[order[j]] - t[order[j - 1]];
    if (d > 0.0) steps.push_back(d);
  }
  r.gridStart = t[order[0]];
  r.gridPoints = 1;
  if (steps.empty()) {  // one sample, or all at the same time
    for (std::size_t j = 1; j < n; ++j) add(TimingEventKind::Duplicate, order[j], 0.0);
    r.duplicates = n - 1;
    r.events = std::move(events);
    return r;
  }
  auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), mid, steps.end());
  const double nominal = *mid;
  std::vector<long> slot(n, 0);  // by position j in sorted order
  std::vector<double> ts(n);
  std::vector<std::size_t> firsts{0};  // positions j of the first sample in each slot
  ts[0] = t[order[0]];
  for (std::size_t j = 1; j < n; ++j) {
    ts[j] = t[order[j]];
    const double d = ts[j] - ts[j - 1];
    if (d <= 1e-6 * nominal) {
      slot[j] = slot[j - 1];
    } else {
      // Slots stay below 2^53 (exact in a double): a stamp absurdly far ahead saturates
      // rather than overflowing; such a gap is refused downstream anyway.
      constexpr long kMaxSlot = 1L << 53;
      const long step = std::max(1L, std::lround(std::min(d / nominal, static_cast<double>(kMaxSlot))));
      slot[j] = std::min(slot[j - 1] + step, kMaxSlot);
      firsts.push_back(j);
    }
  }
  double b = firsts.size() > 1 ? fitSlope(ts, slot, firsts, nominal) : nominal;
  // Prefer the declared rate, else the fitted rate to six digits, when the grid it gives
  // drifts from the fit by less than a quarter of the tolerance over the whole log.
  const double span = static_cast<double>(slot[n - 1]);
  auto accept = [&](double candidate) {
    if (!(candidate > 0.0) || std::abs(candidate - b) * span > 0.25 * o.jitterTolerance * b) return false;
    b = candidate;
    return true;
  };
  const double rate = 1.0 / b;
  const double digits = std::pow(10.0, std::floor(std::log10(rate)) - 5.0);
  if (!(o.declaredRateHz > 0.0 && accept(1.0 / o.declaredRateHz))) accept(1.0 / (std::round(rate / digits) * digits));
  const double a = gridStartFor(ts, slot, firsts, b);
  r.interval = b;
  r.gridStart = a;
  r.gridPoints = static_cast<std::size_t>(slot[n - 1]) + 1;

  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t i = order[j];
    if (j > 0 && slot[j] == slot[j - 1]) {
      add(TimingEventKind::Duplicate, i, 0.0);
      ++r.duplicates;
      continue;
    }
    const double deviation = (ts[j] - a - b * static_cast<double>(slot[j])) / b;
    r.largestJitter = std::max(r.largestJitter, std::abs(deviation));
    if (j > 0 && slot[j] - slot[j - 1] >= 2) {
      const double gap = ts[j] - ts[j - 1];
      add(TimingEventKind::Gap, i, gap, slot[j] - slot[j - 1] - 1);
      ++r.gaps;
      r.missing += static_cast<std::size_t>(slot[j] - slot[j - 1] - 1);
      if (gap > r.longestGap) {
        r.longestGap = gap;
        r.longestGapTime = ts[j];
      }
    }
    if (std::abs(deviation) > o.jitterTolerance) {
      add(TimingEventKind::Jitter, i, deviation);
      ++r.jitter;
    }
  }
  std::stable_sort(events.begin(), events.end(), [](const TimingEvent& x, const TimingEvent& y) {
    return x.time < y.time || (x.time == y.time && x.index < y.index);
  });
  if (events.size() > o.maxEvents) {
    events.resize(o.maxEvents);
    r.truncated = true;
  }
  r.events = std::move(events);
  return r;
}

}  // namespace flexarm
