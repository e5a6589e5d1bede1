// Reduction of the chapter-3 models to the chapter-8 two-mass form (Section 8.1: gear ratio 1
// by scaling the arm side), checked against the frequency responses of the original models.
#include "core/models/two_mass_lqg_reduction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "core/models/analysis.h"

namespace flexarm {
namespace {

// Motor velocity per torque of the chapter-8 form: s C (sI - A)^-1 B with C = phi_m (8.6).
std::complex<double> chapter8Velocity(const TwoMassLqgParameters& p, double w) {
  const TwoMassLqgPlant g = twoMassLqgPlant(p, LqgMeasurement::MotorAngle);
  const std::complex<double> s(0.0, w);
  const Eigen::MatrixXcd M = s * Eigen::MatrixXcd::Identity(4, 4) - g.A.cast<std::complex<double>>();
  const Eigen::VectorXcd x = M.partialPivLu().solve(g.B.cast<std::complex<double>>());
  return s * x(0);
}

TEST(TwoMassReduction, TwoMassScaledByGearRatioKeepsTheMotorResponse) {
  const auto m = makeModel("two-mass");  // Table 5.2, r = 1/118
  const auto red = reduceToTwoMass(*m);
  ASSERT_TRUE(red.ok()) << red.message;
  const double r2 = 1.0 / (118.0 * 118.0);
  EXPECT_NEAR(red.parameters.Ja, 12.0 * r2, 1e-15);
  EXPECT_NEAR(red.parameters.k, 1.5e5 * r2, 1e-9);
  EXPECT_NEAR(red.parameters.d, 70.0 * r2, 1e-12);
  EXPECT_EQ(red.parameters.Jm, 9e-4);
  EXPECT_EQ(red.parameters.fa, 0.0);
  // (3.14) of the physical model equals the scaled chapter-8 model at every frequency.
  const std::vector<double> w = {1.0, 30.0, 100.0, 140.0, 200.0, 1000.0};
  const auto g = frequencyResponse(m->stateSpace(), w);
  for (std::size_t i = 0; i < w.size(); ++i) {
    const auto h = chapter8Velocity(red.parameters, w[i]);
    EXPECT_LT(std::abs(h - g[i]) / std::abs(g[i]), 1e-9) << w[i];
  }
  // The (5.5) form gives the same parameters.
  const auto theta = reduceToTwoMass(*makeModel("two-mass-theta"));
  ASSERT_TRUE(theta.ok()) << theta.message;
  EXPECT_NEAR(theta.parameters.k / red.parameters.k, 1.0, 1e-9);
  EXPECT_NEAR(theta.parameters.Ja / red.parameters.Ja, 1.0, 1e-9);
}

TEST(TwoMassReduction, ThreeMassMatchedAtFirstModeKeepsFrequenciesAndInertia) {
  const auto m = makeModel("three-mass");  // Table 5.7 p6
  const auto red = reduceToTwoMass(*m, {TwoMassReduction::MatchFirstMode});
  ASSERT_TRUE(red.ok()) << red.message;
  const auto notch = notchFrequencies(m->stateSpace()).front();
  const auto peak = peakFrequencies(m->stateSpace()).front();
  const TwoMassLqgParameters& p = red.parameters;
  // Antiresonance sqrt(k/J_a) and resonance sqrt(k (J_m + J_a) / (J_m J_a)) of the two-mass form.
  EXPECT_NEAR(std::sqrt(p.k / p.Ja), notch.naturalFrequency, 1e-9 * notch.naturalFrequency);
  EXPECT_NEAR(std::sqrt(p.k * (p.Jm + p.Ja) / (p.Jm * p.Ja)), peak.naturalFrequency,
              1e-9 * peak.naturalFrequency);
  const double r2 = std::pow(m->value("r"), 2);
  EXPECT_NEAR(p.Jm + p.Ja, m->value("J_m") + r2 * (m->value("J_g") + m->value("J_a")), 1e-15);
  // Table 5.7 p6 has d_g < 0: its first antiresonance is undamped or worse, and says so.
  if (notch.damping < 0.0) {
    EXPECT_EQ(p.d, 0.0);
    EXPECT_NE(red.message.find("negative damping"), std::string::npos) << red.message;
  } else {
    EXPECT_NEAR(p.d, 2.0 * notch.damping * std::sqrt(p.k * p.Ja), 1e-12);
  }
  // The reduced model's own peak (from its poles) is the three-mass first peak.
  StateSpace sys;
  const TwoMassLqgPlant g = twoMassLqgPlant(p, LqgMeasurement::MotorAngle);
  sys.A = g.A;
  sys.B = g.B;
  sys.C = g.C;
  sys.D = Eigen::MatrixXd::Zero(1, 1);
  EXPECT_NEAR(peakFrequencies(sys).front().frequency, peak.frequency, 0.02 * peak.frequency);
}

TEST(TwoMassReduction, ThreeMassMergedKeepsInertiaAndSeriesStiffness) {
  const auto m = makeModel("three-mass");
  const auto red = reduceToTwoMass(*m, {TwoMassReduction::MergeMasses});
  ASSERT_TRUE(red.ok()) << red.message;
  const double r2 = std::pow(m->value("r"), 2);
  const double kg = m->value("k_g"), ka = m->value("k_a");
  EXPECT_NEAR(red.parameters.k, r2 * kg * ka / (kg + ka), 1e-12);
  EXPECT_NEAR(red.parameters.Ja, r2 * (m->value("J_g") + m->value("J_a")), 1e-15);
  EXPECT_GE(red.parameters.d, 0.0);
  // At low frequency both behave as one rigid inertia: |G(iw)| ~ 1/(J_tot w).
  const auto g = frequencyResponse(m->stateSpace(), {5.0});
  EXPECT_NEAR(std::abs(chapter8Velocity(red.parameters, 5.0)) / std::abs(g[0]), 1.0, 0.01);
  // The four-mass model merges its parallel mass as well.
  const auto four = makeModel("four-mass");
  const auto red4 = reduceToTwoMass(*four, {TwoMassReduction::MergeMasses});
  ASSERT_TRUE(red4.ok()) << red4.message;
  EXPECT_NEAR(red4.parameters.Ja - red.parameters.Ja, r2 * four->value("J_p"), 1e-15);
}

TEST(TwoMassReduction, RigidModelIsRefusedWithASentence) {
  const auto red = reduceToTwoMass(*makeModel("rigid"));
  EXPECT_FALSE(red.ok());
  EXPECT_NE(red.message.find("no spring"), std::string::npos) << red.message;
}

TEST(TwoMassReduction, MethodNamesRoundTrip) {
  for (auto r : {TwoMassReduction::MergeMasses, TwoMassReduction::MatchFirstMode})
    EXPECT_EQ(twoMassReductionFromString(toString(r)), r);
  EXPECT_FALSE(twoMassReductionFromString("lump").has_value());
}

}  // namespace
}  // namespace flexarm
