// The seed's chapter-8 results: Sections 8.3-8.7, Figures 8.3, 8.5-8.8, 8.10.
#include "core/control/lqg_analysis.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/control/frequency_response.h"

namespace flexarm {
namespace {

class SeedDesigns : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    caseI = new LqgAnalysis(analyzeLqg(LqgOptions::seedCaseI()));
    caseII = new LqgAnalysis(analyzeLqg(LqgOptions::seedCaseII()));
    acc = new LqgAnalysis(analyzeLqg(LqgOptions::seedAccelerationFeedback()));
  }
  static void TearDownTestSuite() {
    delete caseI;
    delete caseII;
    delete acc;
  }
  static LqgAnalysis* caseI;
  static LqgAnalysis* caseII;
  static LqgAnalysis* acc;
};
LqgAnalysis* SeedDesigns::caseI = nullptr;
LqgAnalysis* SeedDesigns::caseII = nullptr;
LqgAnalysis* SeedDesigns::acc = nullptr;

TEST_F(SeedDesigns, AllAnalysesSucceed) {
  for (const LqgAnalysis* a : {caseI, caseII, acc}) {
    ASSERT_TRUE(a->ok()) << a->message;
    EXPECT_FALSE(a->loop.gridLimitReached);
    EXPECT_EQ(a->sensitivity.size(), a->loop.frequencies.size());
  }
}

TEST_F(SeedDesigns, NyquistEncirclesMinusOneTwiceForTheUnstableRegulator) {
  // Section 8.6: F_y has two RHP poles, so the stable loop's curve encircles -1 twice.
  EXPECT_EQ(caseII->openLoopRhpPoles, 2);
  EXPECT_EQ(caseII->loop.encirclements, 2);
  EXPECT_EQ(caseII->loop.encirclements, caseII->expectedEncirclements);
  EXPECT_EQ(caseI->loop.encirclements, 0);
  EXPECT_EQ(acc->loop.encirclements, 0);
  for (const LqgAnalysis* a : {caseI, caseII, acc}) EXPECT_LT(a->loop.windingError, 1e-3);
}

TEST_F(SeedDesigns, BodeIntegralMatchesPrediction) {
  // (8.37): the integral of log|S| equals pi * sum Re(p_i) over the RHP poles of F_y G.
  double sumRe = 0.0;
  for (Eigen::Index i = 0; i < caseII->design.regulatorPoles.size(); ++i)
    if (caseII->design.regulatorPoles(i).real() > 1e-6)
      sumRe += caseII->design.regulatorPoles(i).real();
  EXPECT_NEAR(caseII->bodePrediction, 3.14159265358979 * sumRe, 1e-9 * sumRe);
  EXPECT_GT(caseII->bodePrediction, 50.0);
  EXPECT_NEAR(caseII->bodeIntegral, caseII->bodePrediction, 1e-6 * caseII->bodePrediction);
  EXPECT_EQ(caseI->bodePrediction, 0.0);
  EXPECT_NEAR(caseI->bodeIntegral, 0.0, 1e-5);
  EXPECT_NEAR(acc->bodeIntegral, 0.0, 1e-5);
}

TEST_F(SeedDesigns, SensitivityPeaksAsInFigures88And810) {
  // The unstable regulator lifts |S| (Figure 8.8: around two); acceleration feedback lowers
  // it again with a stable regulator (Figure 8.10).
  EXPECT_GT(caseII->maxSensitivity, caseI->maxSensitivity);
  EXPECT_GT(caseII->maxSensitivity, 2.0);
  EXPECT_LT(acc->maxSensitivity, caseII->maxSensitivity);
  for (const LqgAnalysis* a : {caseI, caseII, acc}) {
    EXPECT_NEAR(a->minDistanceToMinusOne * a->maxSensitivity, 1.0, 1e-12);
    // Independent check of the peak on a uniform dense grid.
    const TransferEvaluator G(plantTransfer(a->design)), Fy(regulatorFy(a->design));
    double dense = 0.0;
    for (int i = 0; i <= 20000; ++i) {
      const std::complex<double> s(0.0, std::pow(10.0, -1.0 + 4.0 * i / 20000.0));
      const std::complex<double> l = (Fy(s) * G(s))(0, 0);
      dense = std::max(dense, 1.0 / std::abs(1.0 + l));
    }
    EXPECT_LE(dense, a->maxSensitivity * (1.0 + 1e-9));
    EXPECT_GE(dense, a->maxSensitivity * (1.0 - 1e-3));
  }
  // S + T = 1 at every frequency of the grid.
  for (std::size_t i = 0; i < caseII->sensitivity.size(); i += 37) {
    const std::complex<double> l = caseII->loop.values[i];
    EXPECT_NEAR(std::abs(1.0 / (1.0 + l) + l / (1.0 + l) - 1.0), 0.0, 1e-12);
  }
}

TEST_F(SeedDesigns, UnstableRegulatorRejectsArmStepBetter) {
  // Figure 8.3: the unstable regulator of case (ii) has the smaller arm deviation.
  EXPECT_LT(caseII->steps.peakArmDeviation, 0.8 * caseI->steps.peakArmDeviation);
  // Figure 8.9: acceleration feedback reduces it further.
  EXPECT_LT(acc->steps.peakArmDeviation, caseII->steps.peakArmDeviation);
  for (const LqgAnalysis* a : {caseI, caseII, acc}) {
    // Integral action: the motor angle returns to zero, the torque cancels w + v = 2.
    EXPECT_NEAR(a->steps.motorAngle.back(), 0.0, 1e-4);
    EXPECT_NEAR(a->steps.torque.back(), -2.0, 1e-3);
    EXPECT_EQ(a->steps.time.size(), 3001u);
    EXPECT_EQ(a->steps.armAngle[0], 0.0);
  }
}

TEST_F(SeedDesigns, DescribingFunctionMeetsLoopButNotG0) {
  // Section 8.5: -1/Y_f meets F_y G of the unstable design slightly left of -1 ...
  ASSERT_FALSE(caseII->loopCrossings.empty());
  double nearest = -1e300;
  for (const auto& x : caseII->loopCrossings) nearest = std::max(nearest, x.realPart);
  EXPECT_LT(nearest, -1.0);
  EXPECT_GT(nearest, -2.0);
  // ... the stable design's curve also crosses the negative real axis (left of -1) ...
  EXPECT_FALSE(caseI->loopCrossings.empty());
  // ... and G_0 (8.35), which does not depend on the estimator, never meets it (Figure 8.7).
  EXPECT_TRUE(caseII->g0Crossings.empty());
  EXPECT_EQ(caseII->g0.encirclements, 0);
}

TEST(LqgSaturation, AntiWindupKeepsTheUnstableRegulatorInCheck) {
  DisturbanceStepOptions o;
  o.horizon = 6.0;
  o.saturationLimit = 2.5;  // below the linear loop's peak torque of about 2.7 N m
  const LqgDesign unstable = designLqg(LqgOptions::seedCaseII());
  const DisturbanceResponse linear = disturbanceSteps(unstable, DisturbanceStepOptions{});
  double peakTorque = 0.0;
  for (double u : linear.torque) peakTorque = std::max(peakTorque, std::abs(u));
  ASSERT_GT(peakTorque, o.saturationLimit);
  // The computed u_bar fed to the estimator: the loop runs away.
  const DisturbanceResponse plain = disturbanceSteps(unstable, o);
  EXPECT_TRUE(plain.diverged || plain.peakArmDeviation > 1.0);
  // (8.31)-(8.32): the estimator sees the applied torque; the loop settles.
  o.antiWindup = true;
  const DisturbanceResponse aw = disturbanceSteps(unstable, o);
  EXPECT_FALSE(aw.diverged);
  EXPECT_LT(aw.peakArmDeviation, 2.0 * linear.peakArmDeviation);
  EXPECT_NEAR(aw.motorAngle.back(), 0.0, 1e-4);
  for (double u : aw.torque) EXPECT_LE(std::abs(u), o.saturationLimit + 1e-12);
}

TEST(LqgSaturation, WideLimitReproducesTheLinearLoop) {
  const LqgDesign d = designLqg(LqgOptions::seedCaseI());
  const DisturbanceResponse linear = disturbanceSteps(d);
  DisturbanceStepOptions o;
  o.saturationLimit = 1e9;
  o.subSteps = 20;
  const DisturbanceResponse sampled = disturbanceSteps(d, o);
  ASSERT_EQ(sampled.time.size(), linear.time.size());
  double diff = 0.0;
  for (std::size_t i = 0; i < linear.time.size(); ++i)
    diff = std::max(diff, std::abs(sampled.armAngle[i] - linear.armAngle[i]));
  // Holding u over 50 us changes the response by O(h) only.
  EXPECT_LT(diff, 1e-3 * linear.peakArmDeviation);
}

TEST(BandwidthCriterion, FiftyRadPerSecondNeedsAnUnstableRegulator) {
  // Section 8.4, Figure 8.5: T_a of third order with bandwidth about 50 rad/s makes
  // T_a G_a^-1 encircle +1 (clockwise), so 1 - T_m has RHP zeros and F_y (8.27) is unstable.
  const BandwidthCriterion fast = bandwidthCriterion({}, 50.0);
  EXPECT_TRUE(fast.unstableRegulatorNeeded());
  EXPECT_EQ(fast.curve.encirclements, -fast.rhpZeros);
  // Below the arm resonance (23.8 rad/s) a stable regulator suffices.
  const BandwidthCriterion slow = bandwidthCriterion({}, 10.0);
  EXPECT_FALSE(slow.unstableRegulatorNeeded());
  EXPECT_EQ(slow.curve.encirclements, 0);
  // The bandwidth definition: |T_a(i w_b)| = 1/sqrt(2).
  const std::complex<double> q(1.0, 50.0 / fast.omega0);
  EXPECT_NEAR(1.0 / std::abs(q * q * q), 1.0 / std::sqrt(2.0), 1e-12);
  EXPECT_THROW(bandwidthCriterion({}, 0.0), std::invalid_argument);
}

TEST(LqgAnalysisOptions, BadOptionsAreRejected) {
  LqgAnalysisOptions o;
  o.steps.sampleTime = 0.0;
  std::string why;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("sampleTime"), std::string::npos);
  EXPECT_THROW(analyzeLqg(LqgOptions{}, o), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
