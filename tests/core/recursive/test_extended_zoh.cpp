// The sampled sensitivity system (6.27): one step of ExtendedZoh against the matrices
// sampleZoh forms from the exact derivative of the matrix exponential.
#include <gtest/gtest.h>

#include <random>

#include "core/ident/pem.h"
#include "core/recursive/extended_zoh.h"
#include "recursive_helpers.h"

namespace flexarm {
namespace {

double relativeError(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / b.lpNorm<Eigen::Infinity>();
}

// One step from a random state of realistic magnitudes (the balancing's scales: micro-radian
// twists next to motor speeds), compared block by block with Ad x + Bd u and
// Ad X_j + dAd_j x + dBd_j u.
void expectStepMatchesSampleZoh(const ParametricModel& model, const std::vector<std::string>& names,
                                double T, unsigned seed) {
  std::vector<int> free;
  for (const auto& n : names) free.push_back(model.indexOf(n));
  const SampledModel s = sampleZoh(model, T, free, true);
  const StateSpace ss = model.stateSpace();
  const Eigen::Index n = ss.states();
  const auto p = static_cast<Eigen::Index>(free.size());
  std::vector<Eigen::MatrixXd> dA;
  std::vector<Eigen::VectorXd> dB;
  for (int idx : free) {
    const auto d = model.derivative(idx);
    dA.push_back(d.dA);
    dB.push_back(d.dB.col(0));
  }
  std::mt19937 rng(seed);
  // Magnitudes of a response of the arm: the free response of the model from a unit motor
  // speed, so every state carries its own scale.
  Eigen::VectorXd scale = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  z[0] = 1.0;
  for (int k = 0; k < 200; ++k) {
    z = s.Ad * z + s.Bd * 1.0;
    scale = scale.cwiseMax(z.cwiseAbs());
  }
  Eigen::VectorXd x = testing::gaussian(n, 1.0, rng).cwiseProduct(scale);
  Eigen::MatrixXd X(n, p);
  for (Eigen::Index j = 0; j < p; ++j) X.col(j) = testing::gaussian(n, 1.0, rng).cwiseProduct(scale) * 10.0;
  const double u = 0.7;
  Eigen::VectorXd x1 = x;
  Eigen::MatrixXd X1 = X;
  ExtendedZoh zoh;
  zoh.advance(ss.A, ss.B.col(0), dA, dB, T, u, x1, X1);
  EXPECT_LT(relativeError(x1, s.Ad * x + s.Bd * u), 1e-12) << model.structureName();
  for (Eigen::Index j = 0; j < p; ++j) {
    const auto sj = static_cast<std::size_t>(j);
    const Eigen::VectorXd expected = s.Ad * X.col(j) + s.dAd[sj] * x + s.dBd[sj] * u;
    EXPECT_LT(relativeError(X1.col(j), expected), 1e-11)
        << model.structureName() << " d/d" << names[sj] << " T = " << T;
  }
}

TEST(ExtendedZoh, ThreeMassStepEqualsSampleZohForTheSeedsParameters) {
  expectStepMatchesSampleZoh(*testing::threeMassP6(), {"k_T", "J_a", "f_m"}, 0.005, 1);
}

TEST(ExtendedZoh, EveryParameterOfTheThreeMassModel) {
  const auto m = testing::threeMassP6();
  std::vector<std::string> names;
  for (const auto& p : m->parameters()) names.push_back(p.name);
  expectStepMatchesSampleZoh(*m, names, 0.005, 2);
}

TEST(ExtendedZoh, LongSampleTimesNeedSubStepsAndStayExact) {
  // T = 50 ms puts |A T| far beyond one sub-step's norm.
  expectStepMatchesSampleZoh(*testing::threeMassP6(), {"J_a", "k_a", "d_a"}, 0.05, 3);
}

TEST(ExtendedZoh, OtherStructuresAndTheMotorAngleOutput) {
  expectStepMatchesSampleZoh(*makeModel("two-mass"), {"J_a", "k_a", "f_m"}, 0.001, 4);
  expectStepMatchesSampleZoh(*makeModel("four-mass"), {"J_p", "k_p", "k_T"}, 0.005, 5);
  ModelOptions angle;
  angle.output = ModelOutput::MotorAngle;  // an integrator: A is singular
  expectStepMatchesSampleZoh(*makeModel("three-mass", angle), {"J_m", "f_m"}, 0.005, 6);
  expectStepMatchesSampleZoh(testing::FirstOrderModel(20.0, 2.0), {"a", "theta"}, 0.005, 7);
}

TEST(ExtendedZoh, WithoutParametersItIsTheZeroOrderHoldOfTheModel) {
  const auto m = testing::threeMassP6();
  const SampledModel s = sampleZoh(*m, 0.005, {}, false);
  const StateSpace ss = m->stateSpace();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(5), expected = x;
  Eigen::MatrixXd none(5, 0);
  ExtendedZoh zoh;
  for (int k = 0; k < 400; ++k) {
    const double u = std::sin(0.05 * k) + (k % 7 == 0 ? 0.5 : 0.0);
    zoh.advance(ss.A, ss.B.col(0), {}, {}, 0.005, u, x, none);
    expected = s.Ad * expected + s.Bd * u;
  }
  EXPECT_LT(relativeError(x, expected), 1e-11);
}

TEST(ExtendedZoh, ASampleFarLongerThanTheModelsTimeScaleIsRefusedNotIntegrated) {
  // A log with a time step of 1e6 s: at 4 sub-steps a unit of the weighted norm of h A, one
  // sample needed billions of sub-steps (and overflowed their int count).
  const auto m = testing::threeMassP6();
  const StateSpace ss = m->stateSpace();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(5);
  Eigen::MatrixXd none(5, 0);
  ExtendedZoh zoh;
  zoh.advance(ss.A, ss.B.col(0), {}, {}, 1e6, 1.0, x, none);
  EXPECT_GT(zoh.tooLongSubsteps(), ExtendedZoh::kMaxSubsteps);
  EXPECT_FALSE(x.allFinite());
  // The log's own rate stays well inside the budget.
  x.setZero();
  zoh.advance(ss.A, ss.B.col(0), {}, {}, 0.005, 1.0, x, none);
  EXPECT_EQ(zoh.tooLongSubsteps(), 0.0);
  EXPECT_TRUE(x.allFinite());
}

}  // namespace
}  // namespace flexarm
