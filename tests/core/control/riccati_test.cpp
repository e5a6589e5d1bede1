// Riccati equations: analytic cases, a failing case, and the Sylvester solver.
#include "core/control/riccati.h"

#include <gtest/gtest.h>

#include <cmath>

namespace flexarm {
namespace {

TEST(Care, ScalarEquationMatchesClosedForm) {
  // 2 a x - x^2 b^2 / r + q = 0 has the stabilizing root x = r (a + sqrt(a^2 + b^2 q / r)) / b^2.
  const double a = 0.7, b = 2.0, q = 3.0, r = 0.5;
  const CareResult res =
      solveCare(Eigen::MatrixXd::Constant(1, 1, a), Eigen::MatrixXd::Constant(1, 1, b),
                Eigen::MatrixXd::Constant(1, 1, q), Eigen::MatrixXd::Constant(1, 1, r));
  ASSERT_TRUE(res.ok()) << res.message;
  EXPECT_NEAR(res.X(0, 0), r * (a + std::sqrt(a * a + b * b * q / r)) / (b * b), 1e-12);
}

TEST(Care, DoubleIntegratorMatchesClosedForm) {
  // A = [0 1; 0 0], B = [0; 1], Q = I, R = 1: X = [sqrt(3) 1; 1 sqrt(3)].
  Eigen::MatrixXd A(2, 2), B(2, 1);
  A << 0, 1, 0, 0;
  B << 0, 1;
  const CareResult res =
      solveCare(A, B, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(1, 1));
  ASSERT_TRUE(res.ok()) << res.message;
  Eigen::MatrixXd expected(2, 2);
  expected << std::sqrt(3.0), 1, 1, std::sqrt(3.0);
  EXPECT_LT((res.X - expected).norm(), 1e-12);
  EXPECT_LT(res.residual, 1e-14);
  EXPECT_LT(
      careResidual(A, B, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(1, 1), res.X),
      1e-14);
}

TEST(Care, UnstabilizableSystemIsReportedNotThrown) {
  // An unstable mode that the input cannot reach: no stabilizing solution exists.
  Eigen::MatrixXd A(2, 2), B(2, 1);
  A << 1, 0, 0, -1;
  B << 0, 1;
  const CareResult res =
      solveCare(A, B, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(1, 1));
  EXPECT_EQ(res.termination, Termination::Failed);
  EXPECT_NE(res.message.find("not stabilizable"), std::string::npos) << res.message;
}

TEST(Care, MisuseThrows) {
  const Eigen::MatrixXd one = Eigen::MatrixXd::Identity(1, 1);
  EXPECT_THROW(solveCare(one, one, one, -one), std::invalid_argument);
  EXPECT_THROW(solveCare(Eigen::MatrixXd::Identity(2, 2), one, one, one), std::invalid_argument);
  Eigen::MatrixXd Q(2, 2);
  Q << 1, 2, 0, 1;
  EXPECT_THROW(solveCare(Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Ones(2, 1), Q, one),
               std::invalid_argument);
}

TEST(Sylvester, SolvesRandomEquation) {
  std::srand(7);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(4, 4) + 5.0 * Eigen::MatrixXd::Identity(4, 4);
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(3, 3) + 5.0 * Eigen::MatrixXd::Identity(3, 3);
  const Eigen::MatrixXd C = Eigen::MatrixXd::Random(4, 3);
  const Eigen::MatrixXd X = solveSylvester(A, B, C);
  EXPECT_LT((A * X + X * B - C).norm(), 1e-12);
}

}  // namespace
}  // namespace flexarm
