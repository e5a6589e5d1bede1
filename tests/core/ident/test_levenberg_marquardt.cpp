// The search of (4.17)-(4.21) where a bound holds a parameter: a parameter pushed against its
// bound is held there and the others are solved for alone, so the search ends at the bounded
// minimum in a few iterations instead of crawling along the bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/ident/levenberg_marquardt.h"

namespace flexarm {
namespace {

// eps = b - A x with strongly correlated columns, x_0 >= 0 while the unbounded minimum has
// x_0 < 0: the bounded minimum is x_0 = 0 and the others the least squares of the rest.
struct BoundedLinear {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;

  explicit BoundedLinear(unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    const int rows = 400;
    A.resize(rows, 3);
    b.resize(rows);
    for (int i = 0; i < rows; ++i) {
      const double common = n(rng);
      A(i, 0) = common + 0.05 * n(rng);
      A(i, 1) = common + 0.05 * n(rng);
      A(i, 2) = n(rng);
      b[i] = -1.0 * A(i, 0) + 2.0 * A(i, 1) + 0.5 * A(i, 2) + 0.01 * n(rng);
    }
  }

  LeastSquaresProblem problem() const {
    LeastSquaresProblem p;
    p.evaluate = [this](const Eigen::VectorXd& x, Eigen::VectorXd& eps, Eigen::MatrixXd* psi) {
      eps = b - A * x;
      if (psi) *psi = A;
      return true;
    };
    p.project = [](Eigen::VectorXd& x) { x[0] = std::max(x[0], 0.0); };
    return p;
  }

  Eigen::VectorXd boundedMinimum() const {
    const Eigen::MatrixXd rest = A.rightCols(2);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(3);
    x.tail(2) = rest.colPivHouseholderQr().solve(b);
    return x;
  }
};

TEST(LevenbergMarquardt, AParameterOnItsBoundIsHeldAndTheOthersSolvedFor) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const BoundedLinear lin(seed);
    const Eigen::VectorXd unbounded = lin.A.colPivHouseholderQr().solve(lin.b);
    ASSERT_LT(unbounded[0], -0.5);  // the bound is active
    const LeastSquaresSolution s =
        levenbergMarquardt(lin.problem(), Eigen::Vector3d(1.0, 1.0, 1.0), 100, 1e-10, 1e-3);
    EXPECT_EQ(s.summary.termination, Termination::Converged) << s.summary.message;
    EXPECT_LE(s.summary.iterations, 15) << s.summary.message;
    const Eigen::VectorXd want = lin.boundedMinimum();
    EXPECT_DOUBLE_EQ(s.phi[0], 0.0);
    EXPECT_NEAR(s.phi[1], want[1], 1e-6 * (1.0 + std::abs(want[1])));
    EXPECT_NEAR(s.phi[2], want[2], 1e-6 * (1.0 + std::abs(want[2])));
  }
}

// A parameter on its bound that the gradient pulls back inside is free to leave it.
TEST(LevenbergMarquardt, AParameterPulledInsideLeavesItsBound) {
  const BoundedLinear lin(4);
  LeastSquaresProblem p = lin.problem();
  p.project = [](Eigen::VectorXd& x) { x[0] = std::max(x[0], -5.0); };
  const LeastSquaresSolution s = levenbergMarquardt(p, Eigen::Vector3d(-5.0, 0.0, 0.0), 100, 1e-12, 1e-3);
  EXPECT_EQ(s.summary.termination, Termination::Converged) << s.summary.message;
  const Eigen::VectorXd unbounded = lin.A.colPivHouseholderQr().solve(lin.b);
  EXPECT_NEAR(s.phi[0], unbounded[0], 1e-5);
  EXPECT_NEAR(s.phi[1], unbounded[1], 1e-5);
}

}  // namespace
}  // namespace flexarm
