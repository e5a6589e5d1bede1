#include "core/fleet/trend.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/sim/random.h"

namespace flexarm {
namespace {

// An axis' daily estimates as the fleet's analysis gives them on the simulated plant: the
// log-to-log scatter measured there (k_T 0.2 %, J_a 0.2 %, f_m 1.6 %), f_m following the
// cell's temperature (+-10 degC about 25, weekly, plus a slow warming) with alpha = 1.2 %/degC.
struct AxisSpec {
  std::string change;        // "", "k_T", "J_a", "f_m" (a step), "wear" (f_m drift)
  double startDay = 15.5;    // days after the first log
  double size = 0.2;         // step, or rise per day for wear
  double warmingC = 0.0;     // temperature rise over the whole period
  double swingC = 8.5;       // amplitude of the weekly swing
  int days = 40;
  bool temperatures = true;  // does the manifest give them
};

constexpr double kDay0 = 20513.25;
const std::map<std::string, double> kTheta0 = {{"k_T", 1.0}, {"J_a", 1.72}, {"f_m", 0.0355}};
const std::map<std::string, double> kScatter = {{"k_T", 0.002}, {"J_a", 0.002}, {"f_m", 0.016}};
constexpr double kAlpha = 0.012;

std::vector<TrendPoint> makeAxis(const AxisSpec& s, std::uint64_t seed, double* referenceC) {
  Random rng(seed);
  const double phase = 7.0 * rng.uniform();
  std::vector<TrendPoint> out;
  double t0 = 0.0;
  for (int d = 0; d < s.days; ++d) {
    const double T = 25.0 + s.warmingC * d / s.days +
                     std::clamp(s.swingC * std::sin(2.0 * M_PI * (d + phase) / 7.0) + rng.normal(), -9.5, 9.5);
    if (d == 0) t0 = T;
    TrendPoint p;
    p.day = kDay0 + d;
    if (s.temperatures) p.temperatureC = T;
    for (const auto& [name, theta0] : kTheta0) {
      double v = theta0 * (1.0 + kScatter.at(name) * rng.normal());
      const bool after = d > s.startDay;
      if (name == "f_m") v *= 1.0 + kAlpha * (T - t0);
      if (after && s.change == name) v *= 1.0 + s.size;
      if (after && s.change == "wear" && name == "f_m") v *= 1.0 + s.size * (d - s.startDay);
      p.estimates.push_back({name, v, kScatter.at(name) * theta0, theta0});
    }
    out.push_back(p);
  }
  if (referenceC) *referenceC = t0;
  return out;
}

AxisTrend trendOf(const AxisSpec& s, std::uint64_t seed, int days = -1) {
  double refC = 0.0;
  auto points = makeAxis(s, seed, &refC);
  if (days > 0) points.resize(static_cast<std::size_t>(days));
  return analyseAxisTrend(points, s.temperatures ? std::optional<double>(refC) : std::nullopt, {});
}

TEST(FleetTrend, HealthyAxesThroughTemperatureSwingsAreNotFlagged) {
  int flagged = 0, flaggedWithoutTemperature = 0;
  const int axes = 150;
  for (int k = 0; k < axes; ++k) {
    AxisSpec s;
    s.warmingC = 10.0 * (k % 3) / 2.0;  // none, 5 and 10 degC of warming over the period
    const auto t = trendOf(s, 1000 + static_cast<std::uint64_t>(k));
    flagged += t.status != "healthy";
    if (k % 3 == 2) {
      // A cell warming by 12 degC over the period with small daily swings: corrected, healthy;
      // the same logs without their temperatures look like wear.
      s.warmingC = 12.0;
      s.swingC = 1.0;
      flagged += trendOf(s, 1000 + static_cast<std::uint64_t>(k)).status != "healthy";
      s.temperatures = false;
      flaggedWithoutTemperature += trendOf(s, 1000 + static_cast<std::uint64_t>(k)).status == "drift";
    }
  }
  EXPECT_EQ(flagged, 0);
  EXPECT_GE(flaggedWithoutTemperature, 45);  // of 50
}

TEST(FleetTrend, AlphaFromHealthyLogsHoldsTheTruthInItsInterval) {
  int inside = 0;
  for (int k = 0; k < 100; ++k) {
    const auto t = trendOf({}, 2000 + static_cast<std::uint64_t>(k));
    ASSERT_EQ(t.temperature.termination, Termination::Converged) << t.temperature.message;
    inside += std::abs(t.temperature.model.alpha - kAlpha) <= 2.5758 * t.temperature.model.alphaStd;
  }
  EXPECT_GE(inside, 97);
}

TEST(FleetTrend, StepsAreFaultsNamedWithinThreeDays) {
  for (const std::string p : {"k_T", "J_a", "f_m"}) {
    for (int k = 0; k < 30; ++k) {
      AxisSpec s;
      s.change = p;
      s.size = p == "J_a" ? 0.25 : 0.2;
      s.warmingC = 5.0;
      const auto seed = 3000 + static_cast<std::uint64_t>(k);
      const int firstAfter = static_cast<int>(std::ceil(s.startDay));
      int namedAt = -1;
      for (int days = firstAfter; days <= s.days && namedAt < 0; ++days) {
        const auto t = trendOf(s, seed, days);
        if (t.status != "healthy") {
          // A friction step seen on two or three logs fits a steep drift as well as a step:
          // named f_m either way, a step once more logs show the new level.
          if (p == "f_m")
            EXPECT_TRUE(t.status == "fault" || t.status == "drift") << t.status;
          else
            EXPECT_EQ(t.status, "fault");
          EXPECT_EQ(t.parameter, p);
          ASSERT_TRUE(t.since);
          if (t.stepSize) {
            EXPECT_EQ(*t.since, kDay0 + firstAfter) << p;
            EXPECT_NEAR(*t.stepSize, s.size, 0.03) << p;
          } else {
            EXPECT_NEAR(*t.since, kDay0 + firstAfter, 2.0) << p;
          }
          namedAt = days - firstAfter;  // logs after the first faulty one
        }
      }
      const auto whole = trendOf(s, seed);
      EXPECT_EQ(whole.status, "fault") << whole.evidence;
      EXPECT_EQ(whole.parameter, p);
      EXPECT_GE(namedAt, 0) << p;
      EXPECT_LE(namedAt, 3) << p << " seed " << seed;
    }
  }
}

TEST(FleetTrend, WearIsADriftWithItsStartSlopeAndCrossing) {
  int inside = 0, runs = 200, late = 0, crossingInside = 0;
  std::vector<int> delays;
  std::vector<double> errors;
  for (int k = 0; k < runs; ++k) {
    AxisSpec s;
    s.change = "wear";
    s.size = 0.01;  // 1 %/day
    s.startDay = 12.3;
    s.warmingC = 5.0;
    s.days = 30;
    const auto seed = 4000 + static_cast<std::uint64_t>(k);
    const auto t = trendOf(s, seed);
    ASSERT_EQ(t.status, "drift") << t.evidence;
    EXPECT_EQ(t.parameter, "f_m");
    EXPECT_NEAR(*t.since, kDay0 + s.startDay, 4.0);
    inside += *t.slopeLow <= s.size && s.size <= *t.slopeHigh;
    // The threshold (+20 %) is crossed 20 days after the start: predicted from day 29.
    const double truthDays = s.startDay + 20.0 - 29.0;
    ASSERT_TRUE(t.daysToThreshold);
    errors.push_back(std::abs(*t.daysToThreshold - truthDays));
    crossingInside += *t.daysLow <= truthDays && (!t.daysHigh || truthDays <= *t.daysHigh);
    // Days of logs after the start until the drift is named; a drift never named within the
    // log counts as late (one past the last day), not as a wait without end.
    const int firstDay = static_cast<int>(s.startDay) + 1;
    int delay = 0;
    while (firstDay + delay <= s.days && trendOf(s, seed, firstDay + delay).status != "drift") ++delay;
    EXPECT_LE(firstDay + delay, s.days) << "wear never named as a drift, seed " << seed;
    delays.push_back(delay);
    late += delay > 10;
  }
  std::sort(delays.begin(), delays.end());
  std::printf("wear of 1 %%/day named after %d days (median), %d (95th percentile); slope interval held %d of %d, "
              "days to threshold %d of %d\n",
              delays[delays.size() / 2], delays[delays.size() * 95 / 100], inside, runs, crossingInside, runs);
  EXPECT_GE(inside, runs * 97 / 100);
  EXPECT_GE(crossingInside, runs * 97 / 100);
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 1.5);  // days, median error of the predicted crossing
  EXPECT_LE(late, runs / 20);
}

TEST(FleetTrend, TooFewLogsCallNothing) {
  const auto t = trendOf({"k_T", 1.5, 0.3}, 7, 4);
  EXPECT_EQ(t.status, "healthy");
  EXPECT_NE(t.evidence.find("fewer than"), std::string::npos);
  EXPECT_THROW(analyseAxisTrend({}, std::nullopt, [] {
                 TrendOptions o;
                 o.threshold = -1;
                 return o;
               }()),
               std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
