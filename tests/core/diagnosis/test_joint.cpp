// The joint test of the change vector (parameter_tests.h): the chi-square of theta_bar - theta_0
// with the correlations of the full P, isolated by the change's direction.
#include <gtest/gtest.h>

#include <cmath>

#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/scenarios.h"
#include "core/diagnosis/simulate_like.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

// Two parameters whose estimates are correlated (rho = 0.6 in P) with noise along that
// correlation: a change of either alone is detected and isolated to it (the other's direction
// explains only rho^2 of it), and no change stays quiet.
TEST(JointTest, TheDirectionOfTheChangeIsolatesTheParameter) {
  Eigen::MatrixXd P(2, 2);
  P << 1.0, 0.6, 0.6, 1.0;
  const Eigen::VectorXd sigma = Eigen::VectorXd::Constant(2, 0.01);
  auto run = [&](double d1, double d2, JointTest& t) {
    std::vector<TestSample> out;
    for (int k = 0; k < 200; ++k) {
      const double n = 0.01 * std::sin(0.7 * k), e = 0.003 * std::cos(1.3 * k);
      Eigen::VectorXd theta(2);
      theta << 1.0 + n + e, 1.0 + 0.6 * n - e;
      if (k >= 100) theta += Eigen::Vector2d(d1, d2);
      out = t.update(theta, sigma, P);
    }
    return out;
  };
  const DecisionStructure d = DecisionStructure::hypothesis({"a", "b"});
  auto statement = [&](const std::vector<TestSample>& t) {
    return d.diagnose({t[0].ratio > 1.0, t[1].ratio > 1.0, t[2].ratio > 1.0});
  };
  JointTest quiet({1.0, 1.0}, {0.0, 0.0}, 3.0, 0.5), first({1.0, 1.0}, {0.0, 0.0}, 3.0, 0.5),
      second({1.0, 1.0}, {0.0, 0.0}, 3.0, 0.5);
  const auto q = run(0.0, 0.0, quiet);
  EXPECT_LT(q[0].ratio, 1.0) << "no change: chi2 " << quiet.chiSquare();
  EXPECT_TRUE(statement(q) & 1u);  // NF stays possible
  const auto a = run(0.05, 0.0, first);
  EXPECT_GT(a[0].ratio, 1.0) << "chi2 " << first.chiSquare();
  EXPECT_EQ(isolatedFault(statement(a)), 0u);
  EXPECT_GT(first.alignment()[0], 0.9);
  const auto b = run(0.0, -0.05, second);
  EXPECT_EQ(isolatedFault(statement(b)), 1u);
  EXPECT_GT(second.alignment()[1], 0.9);
  // chi-square(3) at P(|z| < 3) is 14.16; Wilson-Hilferty's approximation 14.30.
  EXPECT_NEAR(jointQuantile(3, 3.0), 14.16, 0.2);
}

// A 20 % change of J_a on an arm of the Monte-Carlo study (bench/montecarlo_diagnosis, seed 1:
// the second arm, PRBS excitation): the classical per-parameter test (7.4), which reads each
// estimate against its own sigma, names k_T, whose estimate the J_a change drags along in
// closed loop; the joint test, which sees both moves as one direction, names J_a. In that
// study the classical test named the wrong parameter in 12 of 180 faulty runs (all of them J_a
// changes under PRBS), the joint test in none of those.
TEST(JointTest, IsolatesAJaChangeTheClassicalTestNamesKt) {
  ScenarioOptions so;
  so.arms = 2;
  so.seed = 1;
  DiagnosisOptions o;
  const auto runs = randomScenarios(*makeModel("three-mass"), o.parameters, so);
  ASSERT_EQ(runs.size(), 8u);
  const MonteCarloRun& m = runs[6];
  ASSERT_EQ(m.fault, 1);  // J_a
  const auto healthy = simulateClosedLoop(*m.plant, {}, runOptions(m.conditions, m.noiseScale, m.referenceSeed, {}, m.durationS));
  ASSERT_EQ(healthy.termination, Termination::Converged) << healthy.message;
  ReferenceOptions ro;
  ro.fitPlant = false;
  const DiagnosisReference ref = referenceFromLog(*m.plant, healthy.data, o, ro);
  ASSERT_TRUE(ref.ok()) << ref.message;
  const double ja = m.plant->value("J_a");
  const auto faulty = simulateClosedLoop(
      *m.plant, {}, runOptions(m.conditions, m.noiseScale, m.seed, {{"J_a", ja / (1.0 + m.faultSize), m.faultTimeS}}, m.durationS));
  ASSERT_EQ(faulty.termination, Termination::Converged) << faulty.message;
  const DiagnosisResult r = diagnose(ref, faulty.data, o);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const TestOutcome* classical = r.outcome(DiagnosisTest::Classical);
  const TestOutcome* joint = r.outcome(DiagnosisTest::Joint);
  ASSERT_TRUE(classical && joint);
  ASSERT_TRUE(classical->verdict);
  EXPECT_EQ(r.faults[*classical->verdict], "k_T");
  ASSERT_TRUE(joint->verdict);
  EXPECT_EQ(r.faults[*joint->verdict], "J_a");
  EXPECT_GT(*joint->verdictTime, m.faultTimeS);
  EXPECT_EQ(r.verdictName(), "J_a");  // the decision of the default tests agrees
}

}  // namespace
}  // namespace flexarm
