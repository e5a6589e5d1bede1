// Subspace identification (core/ident/subspace.h): a simulated flexible arm's resonance and
// true order recovered from its singular values and MDL, in open loop by every weighting and
// in closed loop by the predictor route; the innovations model equals its ARMAX polynomials;
// the ss fit on the DaISy robot arm.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "core/ident/blackbox.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit_spec.h"
#include "core/ident/pem.h"
#include "core/ident/subspace.h"
#include "tests/core/ident/daisy_data.h"
#include "tests/core/ident/subspace_logs.h"

namespace flexarm {
namespace {

using testing::armLog;
using testing::ArmLog;
using testing::resonances;

TEST(Subspace, OpenLoopWeightingsRecoverTheOrderAndTheResonances) {
  for (int masses : {2, 3}) {
    const ArmLog log = armLog(masses, false, 11u + static_cast<unsigned>(masses));
    for (SubspaceMethod m : {SubspaceMethod::N4sid, SubspaceMethod::Moesp, SubspaceMethod::Cva, SubspaceMethod::Pbsid}) {
      SubspaceOptions o;
      o.method = m;
      const SubspaceEstimate e = subspaceEstimate(log.u, log.y, 0.005, o);
      ASSERT_TRUE(e.ok) << toString(m) << ": " << e.message;
      EXPECT_EQ(e.method, m);
      EXPECT_EQ(e.chosenOrder, log.order) << toString(m) << " " << masses << " masses: " << e.orderReason;
      EXPECT_GE(e.singularValues.size(), static_cast<std::size_t>(log.order + 1));
      const auto w = resonances(e.model.A, 0.005, true);
      ASSERT_EQ(w.size(), log.truth.size()) << toString(m);
      for (std::size_t i = 0; i < w.size(); ++i)
        EXPECT_NEAR(w[i] / log.truth[i], 1.0, 0.02) << toString(m) << " resonance " << i << " of " << masses;
    }
  }
}

TEST(Subspace, ClosedLoopTakesThePredictorRouteAndRecoversTheArm) {
  const ArmLog log = armLog(2, true, 5u, 8000);
  SubspaceOptions o;
  o.closedLoop = true;
  const SubspaceEstimate e = subspaceEstimate(log.u, log.y, 0.005, o);
  ASSERT_TRUE(e.ok) << e.message;
  EXPECT_EQ(e.method, SubspaceMethod::Pbsid);
  EXPECT_EQ(e.chosenOrder, 3) << e.orderReason;
  const auto w = resonances(e.model.A, 0.005, true);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NEAR(w[0] / log.truth[0], 1.0, 0.02);
  // Refined by prediction error as the ss fit does, the resonance stays.
  PolyEstimateOptions po;
  po.closedLoop = true;
  const PolyEstimate f = estimatePolynomial(log.u, log.y, PolyStructure::Ss, PolyOrders::stateSpace(0), 0.005, po);
  ASSERT_TRUE(f.summary.ok()) << f.summary.message;
  ASSERT_TRUE(f.subspace);
  EXPECT_EQ(f.model.orders.na, 3);
  EXPECT_EQ(f.model.name(), "ss[3]");
  EXPECT_GT(f.model.covariance.size(), 0);
  std::vector<double> wz;
  for (const auto& z : polyRoots(f.model.a))
    if (z.imag() > 1e-9) wz.push_back(std::abs(std::log(z) / 0.005));
  ASSERT_EQ(wz.size(), 1u);
  EXPECT_NEAR(wz[0] / log.truth[0], 1.0, 0.02);
}

TEST(Subspace, TheInnovationsModelIsItsArmaxPolynomials) {
  const ArmLog log = armLog(3, false, 3u, 3000);
  SubspaceOptions o;
  o.order = 5;
  const SubspaceEstimate e = subspaceEstimate(log.u, log.y, 0.005, o);
  ASSERT_TRUE(e.ok) << e.message;
  ASSERT_EQ(e.orders.size(), 1u);
  const PolynomialModel p = e.model.polynomial();
  EXPECT_EQ(p.structure, PolyStructure::Ss);
  EXPECT_EQ(p.orders.na, 5);
  EXPECT_EQ(p.orders.nb, 5);
  EXPECT_EQ(p.orders.nc, 5);
  EXPECT_EQ(p.orders.nk, 1);
  const Eigen::VectorXd a = innovationErrors(e.model, log.u, log.y), b = predictionErrors(p, log.u, log.y);
  // Both from zero initial conditions: the same errors wherever the predictor is defined.
  const Eigen::Index from = 10;
  EXPECT_LT((a - b).tail(a.size() - from).cwiseAbs().maxCoeff(), 1e-6 * a.cwiseAbs().maxCoeff());
  // And its simulation is the model's: B(q)/A(q) u.
  const Eigen::VectorXd sim = simulate(p, log.u);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(5), direct(log.u.size());
  for (Eigen::Index t = 0; t < log.u.size(); ++t) {
    direct[t] = e.model.C.dot(x);
    x = e.model.A * x + e.model.B * log.u[t];
  }
  EXPECT_LT((sim - direct).cwiseAbs().maxCoeff(), 1e-6 * direct.cwiseAbs().maxCoeff());
}

TEST(Subspace, SpecsNameTheOrderOrLetTheDataChoose) {
  std::string why;
  auto s = fitModelSpecFromText("ss", false, &why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->structure, PolyStructure::Ss);
  EXPECT_EQ(s->orders.na, 0);
  EXPECT_EQ(fitModelSpecText(*s), "ss");
  s = fitModelSpecFromText("ss:4", false, &why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->orders.na, 4);
  EXPECT_EQ(s->orders.nc, 4);
  EXPECT_EQ(s->orders.nk, 1);
  EXPECT_EQ(fitModelSpecText(*s), "ss:4");
  EXPECT_EQ(s->name(), "ss[4]");
  ASSERT_TRUE(fitModelSpecFromText("ss[4]", false, &why)) << why;
  EXPECT_FALSE(fitModelSpecFromText("ss:0", false, &why));
  EXPECT_NE(why.find("from 1 to"), std::string::npos) << why;
  EXPECT_FALSE(fitModelSpecFromText("ss:3,3", false, &why));
}

TEST(Subspace, RefusesWhatTheDataCannotCarry) {
  const ArmLog log = armLog(2, false, 1u, 200);
  SubspaceOptions o;
  o.maxOrder = 12;
  const SubspaceEstimate e = subspaceEstimate(log.u, log.y, 0.005, o);
  EXPECT_FALSE(e.ok);
  EXPECT_NE(e.message.find("too few samples"), std::string::npos) << e.message;
  Eigen::VectorXd bad = log.y;
  bad[3] = std::nan("");
  EXPECT_FALSE(subspaceEstimate(log.u, bad, 0.005, {}).ok);
  o.horizon = 4;
  o.order = 6;
  std::string why;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_THROW(subspaceEstimate(log.u, log.y, 0.005, o), std::invalid_argument);
}

// The DaISy flexible robot arm (96-009, T = 1): the order the data choose, and a validation
// fit as good as the ARX and OE models of test_daisy.
TEST(Subspace, DaisyRobotArm) {
  Eigen::VectorXd u, y;
  ASSERT_TRUE(testing::daisyRobotArm(u, y));
  const Eigen::Index ne = 700;
  const PolyEstimate f = estimatePolynomial(u.head(ne), y.head(ne), PolyStructure::Ss, PolyOrders::stateSpace(0));
  ASSERT_TRUE(f.summary.ok()) << f.summary.message;
  ASSERT_TRUE(f.subspace);
  const int n = f.model.orders.na;
  ::testing::Test::RecordProperty("daisy_ss_order", n);
  EXPECT_GE(n, 4);  // at least two resonances: the arm's first two modes
  EXPECT_LE(n, 10);
  const Eigen::VectorXd sim = simulate(f.model, u);
  const double fitVal = fitPercent(y, sim, ne, y.size());
  ::testing::Test::RecordProperty("daisy_ss_fit_val_x10", static_cast<int>(fitVal * 10));
  EXPECT_GT(fitVal, 90.0) << "order " << n << ": " << f.subspace->orderReason;
}

}  // namespace
}  // namespace flexarm
