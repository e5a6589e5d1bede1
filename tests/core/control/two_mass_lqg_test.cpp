// The chapter-8 two-mass form: (8.4)-(8.6), (8.42) and the x5 extension of Section 8.3.
#include "core/models/two_mass_lqg.h"

#include <gtest/gtest.h>

#include <cmath>

namespace flexarm {
namespace {

TEST(TwoMassLqg, MatricesFollowEquations84To86WithTable81) {
  const TwoMassLqgPlant g = twoMassLqgPlant({}, LqgMeasurement::MotorAngle);
  // (8.4) with Table 8.1: -k/J_m = -43/0.0043 = -10000, k/J_a = 43/0.0762.
  EXPECT_NEAR(g.A(1, 0), -10000.0, 1e-9);
  EXPECT_NEAR(g.A(1, 1), -(0.05 + 0.02) / 0.0043, 1e-12);
  EXPECT_NEAR(g.A(3, 2), -43.0 / 0.0762, 1e-12);
  EXPECT_NEAR(g.A(3, 3), -(0.05 + 0.005) / 0.0762, 1e-12);
  EXPECT_NEAR(g.B(1, 0), 1.0 / 0.0043, 1e-9);
  EXPECT_NEAR(g.Bv(3, 0), 1.0 / 0.0762, 1e-12);
  EXPECT_EQ(g.C.cols(), 4);
  EXPECT_EQ(g.C(0, 0), 1.0);
  // A rigid-body mode: no spring to ground, so A is singular with (1,0,1,0) in its kernel.
  Eigen::Vector4d rigid(1, 0, 1, 0);
  EXPECT_LT((g.A * rigid).norm(), 1e-12);
}

TEST(TwoMassLqg, AccelerationRowIsTheArmEquation) {
  TwoMassLqgParameters p;
  const TwoMassLqgPlant g = twoMassLqgPlant(p, LqgMeasurement::MotorAngleAndArmAcceleration);
  ASSERT_EQ(g.C.rows(), 2);
  // (8.42): (k/J_a, d/J_a, -k/J_a, -(d+f_a)/J_a); the measured acceleration equals x4'.
  EXPECT_NEAR(g.C(1, 0), p.k / p.Ja, 1e-12);
  EXPECT_NEAR(g.C(1, 1), p.d / p.Ja, 1e-12);
  EXPECT_NEAR(g.C(1, 2), -p.k / p.Ja, 1e-12);
  EXPECT_NEAR(g.C(1, 3), -(p.d + p.fa) / p.Ja, 1e-12);
  Eigen::Vector4d x(0.3, -1.0, 0.1, 2.0);
  const double v = 0.7;
  const double x4dot = (g.A * x + g.Bv * v)(3);
  EXPECT_NEAR((g.C * x + g.Dv * v)(1), x4dot, 1e-12);
}

TEST(TwoMassLqg, ExtensionMakesX5ALoadOnTheArm) {
  const TwoMassLqgPlant g = twoMassLqgPlant({}, LqgMeasurement::MotorAngle);
  const TwoMassLqgPlant e = withArmLoadDisturbanceState(g);
  ASSERT_EQ(e.states(), 5);
  Eigen::VectorXd z(5);
  z << 0.1, 0.2, 0.3, 0.4, 1.5;
  // x5 acts exactly like v: A_bar z = A x + Bv x5, and x5 stays constant.
  const Eigen::VectorXd dz = e.A * z;
  EXPECT_LT((dz.head(4) - (g.A * z.head(4) + g.Bv * 1.5)).norm(), 1e-12);
  EXPECT_EQ(dz(4), 0.0);
  EXPECT_EQ(e.B(4, 0), 0.0);
  // Uncontrollable from u: the controllability matrix of (A_bar, B_bar) has rank 4.
  Eigen::MatrixXd ctrb(5, 5);
  Eigen::MatrixXd col = e.B;
  for (int i = 0; i < 5; ++i, col = e.A * col) ctrb.col(i) = col;
  EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(ctrb).rank(), 4);
  // Observable from phi_m: the observability matrix has rank 5.
  Eigen::MatrixXd obs(5, 5);
  Eigen::MatrixXd row = e.C;
  for (int i = 0; i < 5; ++i, row = row * e.A) obs.row(i) = row;
  EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(obs).rank(), 5);
}

TEST(TwoMassLqg, ArmFromMotorHasUnitStaticGainAndResonance) {
  TwoMassLqgParameters p;
  EXPECT_NEAR(std::abs(armFromMotorResponse(p, {0.0, 0.0})), 1.0, 1e-15);
  // Figure 8.4: the resonance near sqrt(k/J_a) = 23.8 rad/s shows a gain well above one.
  const double wr = std::sqrt(p.k / p.Ja);
  EXPECT_GT(std::abs(armFromMotorResponse(p, {0.0, wr})), 10.0);
}

TEST(TwoMassLqg, ParametersByNameAndValidation) {
  TwoMassLqgParameters p;
  p.set("k", 50.0);
  EXPECT_EQ(p.get("k"), 50.0);
  EXPECT_THROW(p.set("stiffness", 1.0), std::invalid_argument);
  EXPECT_EQ(TwoMassLqgParameters::unit("J_a"), "kg m^2");
  p.set("J_m", -1.0);
  std::string why;
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("J_m"), std::string::npos);
  EXPECT_THROW(twoMassLqgPlant(p, LqgMeasurement::MotorAngle), std::invalid_argument);
  EXPECT_EQ(lqgMeasurementFromString(toString(LqgMeasurement::MotorAngleAndArmAcceleration)),
            LqgMeasurement::MotorAngleAndArmAcceleration);
  EXPECT_FALSE(lqgMeasurementFromString("gyro").has_value());
}

}  // namespace
}  // namespace flexarm
