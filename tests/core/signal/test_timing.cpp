// Irregular time stamps reported exactly: injected jitter, dropped samples, a duplicate and a
// reversal are found with their count, time and line, and nothing else is.
#include <gtest/gtest.h>

#include <cmath>

#include "core/signal/timing.h"

using namespace flexarm;

namespace {

// A 2 kHz log's stamps with the data starting on line 6: jitter +3 % at sample 1200 and -2.5 %
// at 4711, sample 3000 and samples 6000-6002 dropped, sample 8000 written twice, samples 9000
// and 9001 written in swapped order.
struct Stamps {
  std::vector<double> time;
  std::vector<int> lines;
};

Stamps injected() {
  Stamps s;
  int line = 6;
  auto put = [&](double t) {
    s.time.push_back(t);
    s.lines.push_back(line++);
  };
  for (int k = 0; k < 10000; ++k) {
    const double t = 0.25 + k * 0.0005;
    if (k == 3000 || (k >= 6000 && k <= 6002) || k == 9000) continue;
    if (k == 1200) {
      put(t + 0.03 * 0.0005);
    } else if (k == 4711) {
      put(t - 0.025 * 0.0005);
    } else if (k == 9001) {
      put(t);
      put(0.25 + 9000 * 0.0005);
    } else {
      put(t);
      if (k == 8000) put(t);
    }
  }
  return s;
}

}  // namespace

TEST(Timing, RegularStampsHaveNoEvents) {
  std::vector<double> t(5000);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = 1.0 + i * 0.001 + 2e-6 * std::sin(0.3 * i);  // 0.2 % wobble
  const auto r = analyzeTiming(t);
  EXPECT_TRUE(r.regular()) << r.summary();
  EXPECT_NEAR(r.interval, 0.001, 1e-12) << "rounded to six digits of the rate";
  EXPECT_EQ(r.gridPoints, 5000u);
  EXPECT_NEAR(r.largestJitter, 0.002, 1e-4);
  EXPECT_NE(r.summary().find("regular: 5000 samples, 1 ms interval (1000 Hz)"), std::string::npos) << r.summary();
}

TEST(Timing, InjectedIrregularitiesAreReportedExactly) {
  const Stamps s = injected();
  TimingOptions o;
  o.declaredRateHz = 2000;
  const auto r = analyzeTiming(s.time, s.lines, o);
  EXPECT_EQ(r.jitter, 2u);
  EXPECT_EQ(r.gaps, 2u);
  EXPECT_EQ(r.missing, 4u);
  EXPECT_EQ(r.duplicates, 1u);
  EXPECT_EQ(r.reversals, 1u);
  EXPECT_DOUBLE_EQ(r.interval, 0.0005) << "the declared rate, which the stamps agree with";
  EXPECT_NEAR(r.gridStart, 0.25, 1e-9);
  EXPECT_EQ(r.gridPoints, 10000u);
  EXPECT_NEAR(r.largestJitter, 0.03, 1e-6);
  EXPECT_NEAR(r.longestGap, 0.002, 1e-12);
  EXPECT_NEAR(r.longestGapTime, 0.25 + 6003 * 0.0005, 1e-12);
  ASSERT_EQ(r.events.size(), 6u);
  // In time order; lines are file lines (6 + the sample's row).
  struct Want {
    TimingEventKind kind;
    double time;
    int line;
  };
  const Want want[] = {
      {TimingEventKind::Jitter, 0.25 + 1200 * 0.0005 + 0.015 * 0.001, 6 + 1200},
      {TimingEventKind::Gap, 0.25 + 3001 * 0.0005, 6 + 3000},
      {TimingEventKind::Jitter, 0.25 + 4711 * 0.0005 - 0.0125 * 0.001, 6 + 4710},
      {TimingEventKind::Gap, 0.25 + 6003 * 0.0005, 6 + 5999},
      {TimingEventKind::Duplicate, 0.25 + 8000 * 0.0005, 6 + 7997},
      {TimingEventKind::Reversal, 0.25 + 9000 * 0.0005, 6 + 8998},
  };
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(r.events[i].kind, want[i].kind) << i;
    EXPECT_NEAR(r.events[i].time, want[i].time, 1e-12) << i;
    EXPECT_EQ(r.events[i].line, want[i].line) << i;
  }
  EXPECT_NEAR(r.events[0].size, 0.03, 1e-6);
  EXPECT_NEAR(r.events[2].size, -0.025, 1e-6);
  EXPECT_EQ(r.events[1].missing, 1);
  EXPECT_EQ(r.events[3].missing, 3);
  EXPECT_NEAR(r.events[3].size, 0.002, 1e-12);
  EXPECT_NEAR(r.events[5].size, 0.0005, 1e-12) << "back by one interval";
  const std::string text = r.summary();
  for (const char* part : {"2 gaps (4 samples missing, the longest 2 ms at 3.2515 s, line 6005)",
                           "2 jittered samples (up to 3 % of the interval)", "1 duplicate time stamp",
                           "1 reversal"})
    EXPECT_NE(text.find(part), std::string::npos) << part << " in: " << text;
  EXPECT_EQ(placeOf(r.events[1]), "line 3006");
}

TEST(Timing, EventListIsCappedButCountsAreNot) {
  std::vector<double> t;
  for (int k = 0; k < 1000; ++k)
    if (k % 10 != 5) t.push_back(k * 0.01);  // every tenth sample dropped
  TimingOptions o;
  o.maxEvents = 20;
  const auto r = analyzeTiming(t, {}, o);
  EXPECT_EQ(r.gaps, 100u);
  EXPECT_EQ(r.events.size(), 20u);
  EXPECT_TRUE(r.truncated);
  EXPECT_EQ(r.events[0].line, 0);
  EXPECT_EQ(placeOf(r.events[0]), "sample 5");
}

TEST(Timing, MisuseThrows) {
  EXPECT_THROW(analyzeTiming({0.0, std::nan("")}), std::invalid_argument);
  EXPECT_THROW(analyzeTiming({0.0, 1.0}, {1}), std::invalid_argument);
  TimingOptions o;
  o.jitterTolerance = 0.7;
  EXPECT_THROW(analyzeTiming({0.0, 1.0}, {}, o), std::invalid_argument);
}
