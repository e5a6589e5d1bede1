// The tests of the classical approach on sequences whose answers are known by hand: (7.4),
// (7.12)-(7.14) and the two-sided CUSUM (7.1), (7.15)-(7.17).
#include <gtest/gtest.h>

#include <cmath>

#include "core/diagnosis/parameter_tests.h"

namespace flexarm {
namespace {

TEST(ClassicalTest, ComparesTheDeviationWithThreeSigmas) {
  const ClassicalTest t(1.0, 0.03, 3.0);  // theta_0 = 1, sigma_0 = 0.03
  // (7.4): 3 sqrt(0.04^2 + 0.03^2) = 0.15.
  const auto inside = t.update(1.14, 0.04);
  EXPECT_NEAR(inside.threshold, 0.15, 1e-12);
  EXPECT_NEAR(inside.statistic, 0.14, 1e-12);
  EXPECT_FALSE(inside.alarm);
  const auto below = t.update(0.84, 0.04);  // the test is two-sided
  EXPECT_TRUE(below.alarm);
  EXPECT_NEAR(below.ratio, 0.16 / 0.15, 1e-12);
}

TEST(RobustTest, SmoothsAndEstimatesTheSpread) {
  const double lambda = 0.9;
  RobustTest t(0.0, 0.0, 3.0, lambda);
  // (7.12)/(7.13) by hand for theta = 1, 3 with the weights normalised (7.10).
  t.update(1.0, 0.5);
  EXPECT_DOUBLE_EQ(t.smoothed(), 1.0);
  EXPECT_NEAR(t.spread() * t.spread(), lambda * 0.25, 1e-12);  // the prior decays
  const auto s = t.update(3.0, 0.5);
  const double mean = (lambda * 1.0 + 3.0) / (lambda + 1.0);
  EXPECT_NEAR(t.smoothed(), mean, 1e-12);
  const double variance = lambda * lambda * 0.25 + (1.0 - lambda) * (3.0 - mean) * (3.0 - mean);
  EXPECT_NEAR(t.spread(), std::sqrt(variance), 1e-12);
  EXPECT_NEAR(s.statistic, mean, 1e-12);  // (7.14) with theta_0 = 0
  EXPECT_NEAR(s.threshold, 3.0 * std::sqrt(variance), 1e-12);
  EXPECT_TRUE(s.alarm);
}

TEST(RobustTest, StaysQuietOnNoiseAroundTheNominalValue) {
  RobustTest t(2.0, 0.0, 3.0, 0.99);
  int alarms = 0;
  for (int k = 0; k < 5000; ++k) alarms += t.update(2.0 + 0.1 * std::sin(0.7 * k), 0.1).alarm;
  EXPECT_EQ(alarms, 0);
  EXPECT_NEAR(t.smoothed(), 2.0, 0.01);
  EXPECT_NEAR(t.spread(), 0.1 / std::sqrt(2.0), 0.01);
}

TEST(CusumTest, AccumulatesTheExcessOverTheDrift) {
  // theta_0 = 0.5: h = 20 * 0.5 = 10 (7.17); sigma = 0.1, alpha_1 = 3: nu = 0.3 (7.15).
  CusumTest up(0.5, 3.0, 20.0);
  EXPECT_DOUBLE_EQ(up.threshold(), 10.0);
  // A deviation of 0.8 adds 0.5 per sample: the 20th sample reaches 10, the 21st passes it.
  TestSample s;
  for (int k = 0; k < 20; ++k) s = up.update(1.3, 0.1);
  EXPECT_NEAR(s.statistic, 10.0, 1e-9);
  EXPECT_FALSE(s.alarm);
  s = up.update(1.3, 0.1);
  EXPECT_TRUE(s.alarm);
  EXPECT_NEAR(up.upper(), 10.5, 1e-9);
  EXPECT_EQ(up.lower(), 0.0);
  // Not reset at the alarm (Figure 7.3); the negative side runs in parallel.
  CusumTest down(0.5, 3.0, 20.0);
  for (int k = 0; k < 21; ++k) s = down.update(-0.3, 0.1);
  EXPECT_TRUE(s.alarm);
  EXPECT_NEAR(down.lower(), 21 * 0.5, 1e-9);
  // Small deviations inside the drift never accumulate.
  CusumTest quiet(0.5, 3.0, 20.0);
  for (int k = 0; k < 1000; ++k) s = quiet.update(0.5 + 0.25 * ((k % 2) ? 1 : -1), 0.1);
  EXPECT_EQ(s.statistic, 0.0);
  // With the reset of (7.1), g restarts after an alarm.
  CusumTest reset(0.5, 3.0, 20.0, true);
  for (int k = 0; k < 21; ++k) s = reset.update(1.3, 0.1);
  EXPECT_TRUE(s.alarm);
  EXPECT_EQ(reset.upper(), 0.0);
}

}  // namespace
}  // namespace flexarm
