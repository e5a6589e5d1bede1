#include "core/diagnosis/friction_temperature.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace flexarm {
namespace {

TEST(FrictionTemperature, RecoversAlphaFromHealthyLogsWithinItsInterval) {
  // Twelve healthy logs between 15 and 40 degC, f_m0 = 0.0426 (Table 5.7) at 25 degC and
  // alpha = -1.2 %/degC, each estimate with a 2 % std.
  const double fm0 = 0.0426, alpha = -0.012, tref = 25.0;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> t, fm, sd;
  int misses = 0;
  for (int rep = 0; rep < 200; ++rep) {
    t.clear(); fm.clear(); sd.clear();
    for (int i = 0; i < 12; ++i) {
      const double T = 15.0 + 25.0 * i / 11.0;
      const double s = 0.02 * fm0;
      t.push_back(T);
      fm.push_back(fm0 * (1 + alpha * (T - tref)) + s * noise(rng));
      sd.push_back(s);
    }
    const auto fit = fitFrictionTemperature(t, fm, sd, tref);
    ASSERT_EQ(fit.termination, Termination::Converged) << fit.message;
    if (std::abs(fit.model.alpha - alpha) > 2.576 * fit.model.alphaStd) ++misses;
  }
  // A 99 % interval: at most 6 misses of 200 (binomial, p = 0.01, well beyond its 99.9 % point).
  EXPECT_LE(misses, 6);
  const auto fit = fitFrictionTemperature(t, fm, sd, tref);
  EXPECT_NEAR(fit.fm0, fm0, 0.03 * fm0);
  EXPECT_NEAR(fit.model.toReference(fm0 * (1 + alpha * 15.0), 40.0), fm0, 0.05 * fm0);
  EXPECT_NEAR(fit.model.atTemperature(fm0, 40.0), fm0 * (1 + alpha * 15.0), 0.05 * fm0);
}

TEST(FrictionTemperature, ScatterBeyondTheStdsWidensTheInterval) {
  const std::vector<double> t{10, 20, 30, 40}, fm{1.0, 1.3, 0.9, 1.2}, tight{0.001, 0.001, 0.001, 0.001};
  const auto fit = fitFrictionTemperature(t, fm, tight, 25.0);
  ASSERT_EQ(fit.termination, Termination::Converged);
  EXPECT_GT(fit.scatter, 100.0);
  // The slope is buried in the scatter: its interval holds zero.
  EXPECT_LT(std::abs(fit.model.alpha), 2.576 * fit.model.alphaStd);
}

TEST(FrictionTemperature, TooFewLogsOrTooNarrowASpanGiveNoCorrection) {
  auto two = fitFrictionTemperature({20, 30}, {1.0, 1.1}, {}, 25.0);
  EXPECT_EQ(two.termination, Termination::Failed);
  EXPECT_EQ(two.model.alpha, 0.0);
  EXPECT_NE(two.message.find("three or more"), std::string::npos);
  auto narrow = fitFrictionTemperature({25.0, 25.5, 26.0}, {1.0, 1.1, 1.2}, {}, 25.0);
  EXPECT_EQ(narrow.termination, Termination::Failed);
  EXPECT_NE(narrow.message.find("2 degC"), std::string::npos);
  EXPECT_THROW(fitFrictionTemperature({1, 2, std::nan("")}, {1, 1, 1}, {}, 25.0), std::invalid_argument);
}

TEST(FrictionTemperature, ModelRefusesACoefficientThatMakesFrictionNegative) {
  FrictionTemperatureModel m;
  m.alpha = 0.05;
  m.referenceC = 25.0;
  std::string why;
  EXPECT_FALSE(m.isValid(&why));
  EXPECT_NE(why.find("negative"), std::string::npos);
  m.alpha = -0.02;
  EXPECT_TRUE(m.isValid(&why));
}

}  // namespace
}  // namespace flexarm
