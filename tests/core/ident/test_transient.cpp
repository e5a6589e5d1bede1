// Step and impulse responses with their bands (core/ident/transient.h): the 99 % band of an
// estimated OE model holds the truth's step response at its level on a Monte-Carlo of
// simulated data, the impulse is the step's difference over T, and a physical model's step
// response is its sampled simulation.
#include <gtest/gtest.h>

#include "core/ident/blackbox.h"
#include "core/ident/pem.h"
#include "core/ident/transient.h"
#include "core/models/physical_models.h"
#include "tests/core/ident/sim_helpers.h"

namespace flexarm {
namespace {

TEST(Transient, StepBandOfAnOeEstimateHoldsTheTruthAtItsLevel) {
  const Poly one{1.0}, b{0.0, 1.0, 0.5}, f{1.0, -1.5, 0.7};
  PolynomialModel truth = PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 2, 1}, 1.0);
  truth.b = b;
  truth.f = f;
  const TransientResponse exact = transientResponse(nullptr, {}, {}, &truth, TransientKind::Step, 1.0, 0.99, 60);
  ASSERT_EQ(exact.value.size(), 60u);
  EXPECT_FALSE(exact.hasBand());
  EXPECT_NEAR(exact.value.back(), 1.5 / 0.2, 1e-3);  // the static gain B(1)/F(1)
  const int points[] = {1, 3, 6, 10, 20, 40, 59};
  int misses = 0, checks = 0;
  for (unsigned seed = 1; seed <= 150; ++seed) {
    const testing::SimData s = testing::simulateSystem(one, b, one, one, f, 800, 0.5, seed);
    const PolyEstimate e = oe(s.u, s.y, 2, 2, 1);
    ASSERT_TRUE(e.summary.ok()) << e.summary.message;
    const TransientResponse r = transientResponse(nullptr, {}, {}, &e.model, TransientKind::Step, 1.0, 0.99, 60);
    ASSERT_TRUE(r.hasBand());
    for (int k : points) {
      ++checks;
      misses += exact.value[k] < r.lower[k] || exact.value[k] > r.upper[k];
    }
  }
  ::testing::Test::RecordProperty("step_band_misses", misses);
  // 1 % of 1050 checks is 10.5: a band too narrow misses far more, one too wide almost never.
  EXPECT_LE(misses, 30) << "of " << checks;
  EXPECT_GE(misses, 1) << "of " << checks;
}

TEST(Transient, TheImpulseIsTheStepsDifferenceOverT) {
  PolynomialModel m = PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 2, 1}, 0.01);
  m.b = {0.0, 1.0, 0.5};
  m.f = {1.0, -1.5, 0.7};
  const auto step = transientResponse(nullptr, {}, {}, &m, TransientKind::Step, 1.0, 0.99, 80);
  const auto imp = transientResponse(nullptr, {}, {}, &m, TransientKind::Impulse, 1.0, 0.99, 80);
  ASSERT_EQ(imp.value.size(), 80u);
  EXPECT_DOUBLE_EQ(imp.time[10], 0.1);
  for (std::size_t k = 1; k < 80; ++k)
    EXPECT_NEAR(imp.value[k], (step.value[k] - step.value[k - 1]) / 0.01, 1e-9 * std::abs(imp.value[k]) + 1e-9);
  // Until it settles when no length is given.
  const auto settled = transientResponse(nullptr, {}, {}, &m, TransientKind::Step, 1.0);
  EXPECT_GT(settled.value.size(), 30u);
  EXPECT_NEAR(settled.value.back(), 7.5, 0.1);
}

TEST(Transient, APhysicalModelsStepIsItsSampledSimulationWithABand) {
  const auto model = makeModel("two-mass");
  const double T = 1e-3;
  const auto r = transientResponse(model.get(), {}, {}, nullptr, TransientKind::Step, T, 0.99, 400);
  const Eigen::VectorXd sim = simulate(*model, Eigen::VectorXd::Ones(400), T);
  ASSERT_EQ(r.value.size(), 400u);
  for (Eigen::Index k = 0; k < 400; k += 37) EXPECT_DOUBLE_EQ(r.value[static_cast<std::size_t>(k)], sim[k]);
  EXPECT_FALSE(r.hasBand());
  // A covariance of J_m alone: the band widens with the response's sensitivity to it.
  const int jm = model->indexOf("J_m");
  const double v = model->parameters()[static_cast<std::size_t>(jm)].value;
  Eigen::MatrixXd P(1, 1);
  P(0, 0) = (0.01 * v) * (0.01 * v);
  const auto b = transientResponse(model.get(), P, {jm}, nullptr, TransientKind::Step, T, 0.99, 400);
  ASSERT_TRUE(b.hasBand());
  EXPECT_LT(b.lower[300], b.value[300]);
  EXPECT_GT(b.upper[300], b.value[300]);
  EXPECT_THROW(transientResponse(nullptr, {}, {}, nullptr, TransientKind::Step, T), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
