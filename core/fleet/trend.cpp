#include "core/fleet/trend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "core/fleet/manifest.h"

namespace flexarm {

namespace {

constexpr double kZ99 = 2.5758;  // two-sided 99 % normal quantile

// Measured on the simulated plant (docs/plant.md): 12 s logs at 1 kHz decimated to 200 Hz.
const char* kEstimateCaveat =
    "Sizes, slopes and alpha are those of the recursive estimates against theta_0; on simulated axes "
    "f_m's estimate moved about 1.2 times as much as the arm's f_m (alpha 1.2 for 1.0 %/degC, wear "
    "2.4 for 2 %/day) and J_a's 1.1 times, k_T's one to one, so a drift's interval may miss the "
    "arm's own slope while the axis, the parameter and the start are named right.";

// The two-sided 99 % quantile of Student's t with dof degrees of freedom (the Cornish-Fisher
// expansion about the normal one; within 0.3 % from 5 degrees of freedom on): the scatter
// behind an interval is itself estimated from the logs.
double t99(double dof) {
  const double z = kZ99, z3 = z * z * z, z5 = z3 * z * z;
  dof = std::max(dof, 3.0);
  return z + (z3 + z) / (4.0 * dof) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * dof * dof);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(m), v.end());
  const double hi = v[m];
  if (v.size() % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<long>(m)));
}

// Log-to-log scatter from successive differences (robust to one step and to a slow drift):
// 1.4826 MAD of the differences / sqrt 2.
double scatterOf(const std::vector<double>& y) {
  if (y.size() < 3) return 0.0;
  std::vector<double> d;
  for (std::size_t i = 1; i < y.size(); ++i) d.push_back(y[i] - y[i - 1]);
  const double m = median(d);
  for (auto& x : d) x = std::abs(x - m);
  return 1.4826 * median(d) / std::sqrt(2.0);
}

struct StepFit {
  std::size_t at = 0;  // first index of the second level
  double before = 0.0, after = 0.0, z = 0.0, rss = std::numeric_limits<double>::infinity();
};

StepFit bestStep(const std::vector<double>& y, std::size_t minBefore, std::size_t minAfter) {
  StepFit best;
  const std::size_t n = y.size();
  for (std::size_t k = minBefore; k + minAfter <= n; ++k) {
    const double n1 = static_cast<double>(k), n2 = static_cast<double>(n - k);
    const double m1 = std::accumulate(y.begin(), y.begin() + static_cast<long>(k), 0.0) / n1;
    const double m2 = std::accumulate(y.begin() + static_cast<long>(k), y.end(), 0.0) / n2;
    double rss = 0.0;
    for (std::size_t i = 0; i < n; ++i) rss += std::pow(y[i] - (i < k ? m1 : m2), 2);
    const double s = std::sqrt(rss / std::max(1.0, static_cast<double>(n) - 2.0));
    const double z = std::abs(m2 - m1) / std::max(1e-12, s * std::sqrt(1.0 / n1 + 1.0 / n2));
    if (z > best.z || !std::isfinite(best.rss)) best = {k, m1, m2, z, rss};
  }
  return best;
}

struct DriftFit {
  double t0 = 0.0, a = 0.0, b = 0.0, z = 0.0, rss = std::numeric_limits<double>::infinity();
  double slope = 0.0, slopeSe = 0.0;  // from the logs after t0 alone (see bestDrift)
  double level = 0.0, levelSe = 0.0;  // that line at the last log
  double dof = 1.0;                   // of the residual variance
};

// y = a + b max(0, t - t0) by least squares for each start t0 (every log's day and the
// midpoints between them, leaving minAfter logs after it); the one with the smallest residual.
// Its z is b over b's standard error in that model. The slope reported, and its standard
// error, come from a straight line through the logs after t0 alone (intercept free), with the
// hinge model's residual variance: choosing t0 by the smallest residual makes the hinge's own
// standard error too small (the 99 % interval held the truth in about 91 % of simulated axes),
// the line after t0 does not lean on the choice.
DriftFit bestDrift(const std::vector<double>& t, const std::vector<double>& y, std::size_t minAfter) {
  DriftFit best;
  const std::size_t n = y.size();
  std::vector<double> starts;
  for (std::size_t j = 0; j + minAfter < n; ++j) {
    starts.push_back(t[j]);
    if (j + 1 < n) starts.push_back(0.5 * (t[j] + t[j + 1]));
  }
  for (double t0 : starts) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    std::size_t after = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = std::max(0.0, t[i] - t0);
      after += x > 0.0;
      sx += x; sy += y[i]; sxx += x * x; sxy += x * y[i];
    }
    if (after < minAfter) continue;
    const double nn = static_cast<double>(n);
    const double det = nn * sxx - sx * sx;
    if (!(det > 0.0)) continue;
    const double b = (nn * sxy - sx * sy) / det;
    const double a = (sy - b * sx) / nn;
    double rss = 0.0;
    for (std::size_t i = 0; i < n; ++i) rss += std::pow(y[i] - a - b * std::max(0.0, t[i] - t0), 2);
    if (rss >= best.rss) continue;
    const double s2 = rss / std::max(1.0, nn - 3.0);  // a, b and t0
    const double se = std::sqrt(s2 * nn / det);
    best = {t0, a, b, b / std::max(1e-15, se), rss, b, se, 0.0, 0.0, std::max(1.0, nn - 3.0)};
  }
  if (!std::isfinite(best.rss)) return best;
  // The line through the logs after t0.
  double m = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(t[i] > best.t0)) continue;
    const double x = t[i] - best.t0;
    m += 1; sx += x; sy += y[i]; sxx += x * x; sxy += x * y[i];
  }
  const double det = m * sxx - sx * sx;
  if (m >= 3 && det > 0.0) {
    const double s2 = best.rss / std::max(1.0, static_cast<double>(n) - 3.0);
    best.slope = (m * sxy - sx * sy) / det;
    best.slopeSe = std::sqrt(s2 * m / det);
    const double mean = sx / m, last = t.back() - best.t0;
    best.level = (sy - best.slope * sx) / m + best.slope * last;
    best.levelSe = std::sqrt(s2 * (1.0 / m + (last - mean) * (last - mean) * m / det));
  } else {
    best.level = best.a + best.b * (t.back() - best.t0);
    best.levelSe = best.slopeSe * (t.back() - best.t0);
  }
  return best;
}

std::string percent(double v, int digits = 1) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.*f %%", digits, 100.0 * v);
  return buf;
}

std::string number(double v, const char* fmt = "%.3g") {
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string dateOf(double day) { return isoFromDay(day).substr(0, 10); }

// The series of one parameter, the wear parameter at the reference temperature.
ParameterSeries seriesOf(const std::string& name, const std::vector<TrendPoint>& points,
                         const FrictionTemperatureModel* temperature) {
  ParameterSeries s;
  s.name = name;
  for (const auto& p : points) {
    const FleetEstimate* e = nullptr;
    for (const auto& x : p.estimates)
      if (x.name == name) e = &x;
    if (!e || !(e->reference != 0.0)) continue;
    s.reference = e->reference;
    double v = e->value, sd = e->std;
    if (temperature && p.temperatureC) {
      const double f = temperature->toReference(1.0, *p.temperatureC);
      v *= f;
      sd *= f;
    }
    s.day.push_back(p.day);
    s.raw.push_back(e->value);
    s.temperatureC.push_back(p.temperatureC);
    s.value.push_back(v / e->reference - 1.0);
    s.std.push_back(sd / std::abs(e->reference));
  }
  return s;
}

// Finds a step (any parameter) or a drift (the wear parameter) in the series; alphaStd (of the
// temperature correction applied) adds to the uncertainty of a drift's level at the last log.
void detectChange(ParameterSeries& s, bool wear, const TrendOptions& o, const FrictionTemperatureModel* temperature) {
  // The temperature's own trend over the logs from `from` on (degC per day): alpha's error
  // times it adds to a drift's slope.
  auto temperatureSlope = [&](double from) {
    double m = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < s.day.size(); ++i)
      if (s.day[i] > from && s.temperatureC[i]) {
        const double x = s.day[i] - from, y = *s.temperatureC[i];
        m += 1; sx += x; sy += y; sxx += x * x; sxy += x * y;
      }
    const double det = m * sxx - sx * sx;
    return m >= 2 && det > 0.0 ? (m * sxy - sx * sy) / det : 0.0;
  };
  const std::size_t n = s.value.size();
  s.scatter = scatterOf(s.value);
  const double mean = n ? std::accumulate(s.value.begin(), s.value.end(), 0.0) / static_cast<double>(n) : 0.0;
  s.fitted.assign(n, mean);
  s.level = mean;
  if (n < static_cast<std::size_t>(o.minLogs)) return;
  const auto minAfter = static_cast<std::size_t>(o.minAfter);
  const StepFit step = bestStep(s.value, 2, minAfter);
  const bool stepCalled = step.z >= o.stepZ && std::abs(step.after - step.before) >= o.minStep;
  DriftFit drift;
  bool driftCalled = false;
  if (wear) {
    drift = bestDrift(s.day, s.value, minAfter);
    const double rise = drift.b * (s.day.back() - drift.t0);
    driftCalled = drift.b > 0.0 && drift.z >= o.driftZ && rise >= o.minStep;
  }
  if (stepCalled && (!driftCalled || step.rss <= drift.rss)) {
    s.kind = "step";
    s.since = s.day[step.at];
    s.size = step.after - step.before;
    s.z = step.z;
    s.level = step.after;
    for (std::size_t i = 0; i < n; ++i) s.fitted[i] = i < step.at ? step.before : step.after;
  } else if (driftCalled) {
    s.kind = "drift";
    s.since = drift.t0;
    s.z = drift.z;
    double slopeSe = drift.slopeSe;
    if (temperature) slopeSe = std::hypot(slopeSe, temperature->alphaStd * temperatureSlope(drift.t0));
    const double q = t99(drift.dof);
    s.slope = drift.slope;
    s.slopeLow = drift.slope - q * slopeSe;
    s.slopeHigh = drift.slope + q * slopeSe;
    s.quantile = q;
    for (std::size_t i = 0; i < n; ++i) s.fitted[i] = drift.a + drift.b * std::max(0.0, s.day[i] - drift.t0);
    s.level = drift.level;
    s.levelSe = drift.levelSe;
    if (temperature && s.temperatureC.back()) {
      const double dT = (*s.temperatureC.back() - temperature->referenceC) * temperature->alphaStd;
      s.levelSe = std::sqrt(s.levelSe * s.levelSe + dT * dT);
    }
  }
}

}  // namespace

bool TrendOptions::isValid(std::string* why) const {
  auto fail = [&](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (parameters.empty()) return fail("a trend needs at least one parameter");
  if (!(stepZ > 0.0) || !(driftZ > 0.0) || !(minStep >= 0.0))
    return fail("the step and drift significances must be positive");
  if (!(threshold > 0.0) || !std::isfinite(threshold)) return fail("the threshold must be a positive fraction");
  if (!(nextStopDays >= 0.0)) return fail("the next stop must be zero or more days away");
  if (minLogs < 3 || minAfter < 1) return fail("a trend needs at least 3 logs and 1 after a change");
  if (temperature && !temperature->isValid(why)) return false;
  return true;
}

const ParameterSeries* AxisTrend::find(const std::string& name) const {
  for (const auto& s : series)
    if (s.name == name) return &s;
  return nullptr;
}

AxisTrend analyseAxisTrend(const std::vector<TrendPoint>& input, std::optional<double> referenceTemperatureC,
                           const TrendOptions& o) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("trend: " + why);
  std::vector<TrendPoint> points = input;
  std::stable_sort(points.begin(), points.end(), [](const TrendPoint& a, const TrendPoint& b) { return a.day < b.day; });
  AxisTrend t;
  t.threshold = o.threshold;
  t.logs = static_cast<int>(points.size());
  t.lastDay = points.empty() ? 0.0 : points.back().day;
  t.referenceTemperatureC = referenceTemperatureC;
  if (!referenceTemperatureC) {
    for (const auto& p : points)
      if (p.temperatureC) {
        t.referenceTemperatureC = p.temperatureC;
        break;
      }
  }

  // alpha from the healthy logs: first every log, then those before the earliest change found.
  double healthyUntil = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2; ++pass) {
    if (o.temperature) {
      t.temperature = {};
      t.temperature.termination = Termination::Converged;
      t.temperature.model = *o.temperature;
      t.temperature.message = "alpha = " + number(100.0 * o.temperature->alpha) + " %/degC as given";
    } else if (t.referenceTemperatureC) {
      std::vector<double> temps, fm, sd;
      for (const auto& p : points) {
        if (!p.temperatureC || p.day >= healthyUntil) continue;
        for (const auto& e : p.estimates)
          if (e.name == o.wearParameter && e.std > 0.0) {
            temps.push_back(*p.temperatureC);
            fm.push_back(e.value);
            sd.push_back(e.std);
          }
      }
      t.temperature = fitFrictionTemperature(temps, fm, {}, *t.referenceTemperatureC);
    } else {
      t.temperature = {};
      t.temperature.message = "the logs carry no temperature, so f_m is compared without a temperature correction";
    }
    const bool corrected = t.temperature.termination == Termination::Converged;
    t.series.clear();
    for (const auto& name : o.parameters) {
      const bool wear = name == o.wearParameter;
      const FrictionTemperatureModel* model = wear && corrected ? &t.temperature.model : nullptr;
      t.series.push_back(seriesOf(name, points, model));
      detectChange(t.series.back(), wear, o, model);
    }
    double earliest = std::numeric_limits<double>::infinity();
    for (const auto& s : t.series)
      if (s.since) earliest = std::min(earliest, *s.since);
    if (!(earliest < healthyUntil) || o.temperature) break;
    healthyUntil = earliest;
  }

  // The axis' status: the most significant change, a fault before a drift.
  const ParameterSeries* changed = nullptr;
  for (const auto& s : t.series) {
    if (s.kind == "none") continue;
    const bool better = !changed || (s.kind == "step" && changed->kind != "step") ||
                        (s.kind == changed->kind && s.z > changed->z);
    if (better) changed = &s;
  }
  std::string scatter;
  for (const auto& s : t.series)
    scatter += std::string(scatter.empty() ? "" : ", ") + s.name + " " + number(100.0 * s.scatter, "%.2g") + " %";
  const std::string temperatureNote =
      t.temperature.termination == Termination::Converged
          ? o.wearParameter + " compared at " + number(t.temperature.model.referenceC, "%.1f") + " degC (" +
                t.temperature.message + ")"
          : o.wearParameter + " without a temperature correction (" + t.temperature.message + ")";
  if (!changed) {
    t.evidence = t.logs < o.minLogs
                     ? std::to_string(t.logs) + " logs, fewer than the " + std::to_string(o.minLogs) +
                           " a trend needs; no change called"
                     : "no step or drift over " + std::to_string(t.logs) + " logs; log-to-log scatter " + scatter +
                           "; " + temperatureNote + ".";
    t.suggestion = "no service needed";
    return t;
  }
  t.parameter = changed->name;
  t.since = changed->since;
  // The sizes are those of the recursive estimates (at the seed's 200 Hz) against theta_0, not
  // of the arm itself: see kEstimateCaveat.
  t.caveat = kEstimateCaveat;
  if (changed->kind == "step") {
    t.status = "fault";
    t.stepSize = changed->size;
    int named = 0, after = 0;
    for (const auto& p : points)
      if (p.day >= *changed->since) {
        ++after;
        named += p.verdict == changed->name;
      }
    const std::string what = changed->name == "J_a" ? " (a load change)" : changed->name == "k_T" ? " (the motor's torque constant)" : "";
    t.evidence = changed->name + what + " stepped " + percent(changed->size) + " from " + dateOf(*changed->since) +
                 " (" + number(changed->z, "%.1f") + " standard errors of the two levels, scatter " +
                 number(100.0 * changed->scatter, "%.2g") + " % per log); the chapter-7 diagnosis of the logs since "
                 "names " + changed->name + " in " + std::to_string(named) + " of " + std::to_string(after) + "; " +
                 temperatureNote + ".";
    if (std::abs(changed->size) >= o.threshold) t.daysToThreshold = t.daysLow = t.daysHigh = 0.0;
    t.serviceAtNextStop = true;
    t.suggestion = "inspect " + changed->name + " at the next stop: " +
                   (changed->name == "J_a" ? "confirm the new load or tool, and take a new reference if it is intended"
                                           : changed->name == "k_T" ? "check the motor and its drive"
                                                                    : "check the gearbox and its lubrication");
  } else {
    t.status = "drift";
    t.slopePerDay = changed->slope;
    t.slopeLow = changed->slopeLow;
    t.slopeHigh = changed->slopeHigh;
    // Days until the threshold, and their 99 % range from the extremes of the level's and the
    // slope's 99 % intervals.
    const double level = changed->level;
    const double levelHigh = level + changed->quantile * changed->levelSe;
    const double levelLow = level - changed->quantile * changed->levelSe;
    auto daysAt = [&](double from, double slope) { return std::max(0.0, (o.threshold - from) / slope); };
    t.daysToThreshold = level >= o.threshold ? 0.0 : daysAt(level, changed->slope);
    t.daysLow = daysAt(levelHigh, changed->slopeHigh);
    if (changed->slopeLow > 0.0) t.daysHigh = daysAt(levelLow, changed->slopeLow);
    // When passed, the day the fitted drift crossed it.
    t.crossingDay = t.lastDay + (level >= o.threshold ? (o.threshold - level) / changed->slope : *t.daysToThreshold);
    t.evidence = changed->name + " has risen " + number(100.0 * changed->slope, "%.2f") + " %/day (99 %: " +
                 number(100.0 * changed->slopeLow, "%.2f") + " to " + number(100.0 * changed->slopeHigh, "%.2f") +
                 ") since " + dateOf(*changed->since) + ", now " + percent(level) + " over theta_0 (" +
                 number(changed->z, "%.1f") + " standard errors, scatter " + number(100.0 * changed->scatter, "%.2g") +
                 " % per log); the threshold " + percent(o.threshold, 0) + " is " +
                 (level >= o.threshold ? "passed (about " + dateOf(*t.crossingDay) + ")"
                                            : "reached in " + number(*t.daysToThreshold, "%.1f") + " days (" +
                                                  number(*t.daysLow, "%.1f") + " to " +
                                                  (t.daysHigh ? number(*t.daysHigh, "%.1f") : std::string("unbounded")) +
                                                  ", 99 %), about " + dateOf(*t.crossingDay)) +
                 "; " + temperatureNote + ".";
    t.serviceAtNextStop = *t.daysLow <= o.nextStopDays;
    t.suggestion = level >= o.threshold ? "service the gearbox at the next stop (the threshold is passed)"
                   : t.serviceAtNextStop
                       ? "service the gearbox at the next stop (the threshold may be reached within " +
                             number(o.nextStopDays, "%.0f") + " days)"
                       : "plan a gearbox service before " + dateOf(t.lastDay + *t.daysLow);
  }
  return t;
}

std::string daysToThresholdText(const AxisTrend& t) {
  if (!t.daysToThreshold) return "-";
  return *t.daysToThreshold <= 0.0 ? "passed" : number(*t.daysToThreshold, "%.1f");
}

}  // namespace flexarm
