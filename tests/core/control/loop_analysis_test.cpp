// Nyquist encirclements, Bode's integral and the describing function on loops whose answers
// are known in closed form.
#include "core/control/loop_analysis.h"

#include <gtest/gtest.h>

#include <cmath>

namespace flexarm {
namespace {

using C = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

TEST(Nyquist, UnstableOpenLoopStabilizedEncirclesOnceCounterClockwise) {
  // L = 2/(s - 1): P = 1, closed-loop pole at -1, so P - Z = 1.
  const NyquistCurve c = nyquist([](C s) { return 2.0 / (s - 1.0); }, -1.0, {1.0});
  EXPECT_EQ(c.encirclements, 1);
  EXPECT_LT(c.windingError, 1e-6);
}

TEST(Nyquist, HighGainThirdOrderLoopEncirclesTwiceClockwise) {
  // L = k/(s + 1)^3 is closed-loop unstable for k > 8 with Z = 2, P = 0.
  auto loop = [](double k) { return [k](C s) { return k / ((s + 1.0) * (s + 1.0) * (s + 1.0)); }; };
  EXPECT_EQ(nyquist(loop(10.0), -1.0, {1.0}).encirclements, -2);
  EXPECT_EQ(nyquist(loop(7.0), -1.0, {1.0}).encirclements, 0);
}

TEST(Nyquist, IntegratorsAreIndentedAround) {
  // L = 1/(s^2 (s + 1)) with closed loop s^3 + s^2 + 1: two RHP roots, P = 0 -> -2.
  const auto l = [](C s) { return 1.0 / (s * s * (s + 1.0)); };
  EXPECT_EQ(nyquist(l, -1.0, {0.0, 1.0}).encirclements, -2);
  // L = 2/(s (s + 1)): stable closed loop, no encirclement.
  EXPECT_EQ(nyquist([](C s) { return 2.0 / (s * (s + 1.0)); }, -1.0, {0.0, 1.0}).encirclements, 0);
}

TEST(BodeIntegral, MatchesPiTimesUnstablePoleForKnownLoop) {
  // L = 30 (s + 2)/((s - 1)(s + 3)(s + 4)): relative degree 2, closed loop s^3 + 6s^2 + 35s + 48
  // is stable;
  // (8.37) gives pi * 1.
  const auto l = [](C s) { return 30.0 * (s + 2.0) / ((s - 1.0) * (s + 3.0) * (s + 4.0)); };
  const NyquistCurve c = nyquist(l, -1.0, {1.0, 2.0, 3.0, 4.0});
  ASSERT_EQ(c.encirclements, 1);  // P = 1, Z = 0
  EXPECT_NEAR(bodeSensitivityIntegral(l, c.frequencies), kPi, 1e-6);
  // A stable loop: the integral vanishes.
  const auto s = [](C x) { return 3.0 / ((x + 1.0) * (x + 2.0)); };
  EXPECT_NEAR(bodeSensitivityIntegral(s, nyquist(s, -1.0, {1.0, 2.0}).frequencies), 0.0, 1e-6);
}

TEST(DescribingFunction, SaturationValues) {
  EXPECT_EQ(saturationDescribingFunction(0.5), 1.0);
  EXPECT_EQ(saturationDescribingFunction(1.0), 1.0);
  // (8.30) at C = 2: (2/pi)(pi/6 + sqrt(3)/4).
  EXPECT_NEAR(saturationDescribingFunction(2.0), 2.0 / kPi * (kPi / 6 + std::sqrt(3.0) / 4), 1e-15);
  EXPECT_NEAR(saturationDescribingFunction(1e6), 4.0 / (kPi * 1e6), 1e-12);
}

TEST(DescribingFunction, CrossingOfThirdOrderLoop) {
  // L = 16/(s + 1)^3 meets the real axis at w = sqrt(3) with L = -2: C with Y_f(C) = 1/2.
  const auto l = [](C s) { return 16.0 / ((s + 1.0) * (s + 1.0) * (s + 1.0)); };
  const NyquistCurve c = nyquist(l, -1.0, {1.0});
  const auto x = describingFunctionCrossings(l, c);
  ASSERT_EQ(x.size(), 1u);
  EXPECT_NEAR(x[0].frequency, std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(x[0].realPart, -2.0, 1e-9);
  EXPECT_NEAR(saturationDescribingFunction(x[0].amplitude), 0.5, 1e-9);
  // Lower gain: the crossing lies right of -1 and is not reported.
  const auto low = [](C s) { return 4.0 / ((s + 1.0) * (s + 1.0) * (s + 1.0)); };
  EXPECT_TRUE(describingFunctionCrossings(low, nyquist(low, -1.0, {1.0})).empty());
}

TEST(Nyquist, SampledDenselyWhereItBends) {
  // A lightly damped resonance draws a large circle far from -1: the curve is sampled so
  // that its direction turns by at most maxBendStep between chords a reader can see, and the
  // circle has enough points to look round (its radius is about 25 around 25 - 25i).
  const auto l = [](C s) { return 50.0 / (s * s + 0.02 * s + 1.0) / (s / 50.0 + 1.0); };
  const NyquistOptions o;
  const NyquistCurve c = nyquist(l, -1.0, {1.0, 50.0}, o);
  EXPECT_FALSE(c.gridLimitReached);
  double worst = 0.0;
  int onCircle = 0;
  for (std::size_t i = 1; i + 1 < c.values.size(); ++i) {
    const C d1 = c.values[i] - c.values[i - 1], d2 = c.values[i + 1] - c.values[i];
    if (std::max(std::abs(d1), std::abs(d2)) <= o.bendMinChord * std::abs(c.values[i] + 1.0)) continue;
    worst = std::max(worst, std::abs(std::arg(d2 / d1)));
    if (std::abs(c.values[i]) > 10.0) ++onCircle;
  }
  EXPECT_LE(worst, o.maxBendStep + 1e-9);
  EXPECT_GE(onCircle, 60);  // 2 pi / 0.1 turns of a smooth circle
}

TEST(Nyquist, InvalidOptionsThrow) {
  NyquistOptions o;
  o.maxAngleStep = 0.0;
  EXPECT_THROW(nyquist([](C s) { return 1.0 / (s + 1.0); }, -1.0, {1.0}, o), std::invalid_argument);
  EXPECT_THROW(nyquist([](C s) { return 1.0 / (s + 1.0); }, -1.0, {}), std::invalid_argument);
  NyquistOptions bend;
  bend.maxBendStep = 0.0;
  EXPECT_THROW(nyquist([](C s) { return 1.0 / (s + 1.0); }, -1.0, {1.0}, bend), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
