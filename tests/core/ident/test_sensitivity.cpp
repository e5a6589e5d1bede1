// The sensitivity study of Section 5.3.3 on the test-local two-mass model: domain of attraction
// by interval halving (Table 5.8) and Monte-Carlo success rate, in parallel, with cancel.
#include <gtest/gtest.h>

#include <random>

#include "core/ident/sensitivity.h"
#include "sim_helpers.h"
#include "two_mass_test_model.h"

namespace flexarm {
namespace {

using testing::TwoMassTestModel;
constexpr double kTs = 0.005;

struct Fixture {
  Eigen::VectorXd u, y;
  std::unique_ptr<ParametricModel> estimate;
};

Fixture makeFixture() {
  std::mt19937 rng(77);
  Fixture f;
  f.u = testing::whiteNoise(800, 1.0, rng);
  const Eigen::VectorXd clean = testing::rk4Simulate(TwoMassTestModel().stateSpace(), f.u, kTs);
  f.y = clean + testing::whiteNoise(800, 0.05 * std::sqrt(clean.squaredNorm() / 800), rng);
  TwoMassTestModel m;
  m.setParameter("d", 0.0);
  m.setFree("d", false);
  m.setFree("f_m", false);  // J_m, J_a, k free: a small, quick study
  auto r = pem(m, f.u, f.y, kTs);
  f.estimate = std::move(r.model);
  return f;
}

TEST(Sensitivity, DomainOfAttractionBracketsTheEstimateAndMonteCarloCountsSuccesses) {
  const auto f = makeFixture();
  AttractionOptions ao;
  ao.maxFactor = 20.0;
  ao.minFactor = 0.05;
  ao.halvings = 3;
  ao.threads = 2;
  const auto dom = domainOfAttraction(*f.estimate, f.u, f.y, kTs, ao);
  ASSERT_EQ(dom.termination, Termination::Converged) << dom.message;
  ASSERT_EQ(dom.parameters.size(), 3u);
  for (const auto& p : dom.parameters) {
    EXPECT_GE(p.upperFactor, 1.0) << p.name;
    EXPECT_LE(p.lowerFactor, 1.0) << p.name;
    EXPECT_GT(p.lowerFactor, 0.0) << p.name;  // positive parameters searched geometrically
    EXPECT_EQ(p.fits, p.upperOpen && p.lowerOpen ? 2 : (p.upperOpen || p.lowerOpen ? 5 : 8));
  }
  // A start far outside the domain must really fail where the halving said so: refit from
  // just beyond the upper limit of the first bounded parameter.
  for (const auto& p : dom.parameters) {
    if (p.upperOpen) continue;
    auto m = f.estimate->clone();
    const int idx = m->indexOf(p.name);
    const double beyond = p.upperFactor * std::pow(ao.maxFactor / 1.0, 1.0 / (1 << ao.halvings));
    m->setParameter(p.name, m->parameters()[idx].value * std::min(beyond, ao.maxFactor));
    const auto r = pem(*m, f.u, f.y, kTs);
    EXPECT_FALSE(r.summary.ok() && r.summary.loss < 1.05 * dom.referenceLoss) << p.name;
    break;
  }
  MonteCarloOptions mo;
  mo.runs = 24;
  mo.threads = 2;
  const auto mc = monteCarloStarts(*f.estimate, f.u, f.y, kTs, dom, mo);
  ASSERT_EQ(mc.termination, Termination::Converged);
  EXPECT_EQ(mc.completed, 24);
  int counted = 0;
  for (int i = 0; i < mc.runs; ++i) {
    counted += mc.success[i];
    EXPECT_EQ(mc.success[i], mc.losses[i] < 1.05 * mc.referenceLoss);
  }
  EXPECT_EQ(counted, mc.successes);
  ::testing::Test::RecordProperty("mc_successes", mc.successes);
  EXPECT_GT(mc.successes, 0);
  // Starts within 1 % of the estimate's domain always come back to it.
  MonteCarloOptions near = mo;
  near.regionFraction = 0.01;
  near.runs = 8;
  EXPECT_EQ(monteCarloStarts(*f.estimate, f.u, f.y, kTs, dom, near).successes, 8);
  // Same seed, one thread: the same outcome (starts are drawn before the parallel runs).
  mo.threads = 1;
  const auto mc1 = monteCarloStarts(*f.estimate, f.u, f.y, kTs, dom, mo);
  EXPECT_EQ(mc1.successes, mc.successes);
}

TEST(Sensitivity, MonteCarloCanBeCancelled) {
  const auto f = makeFixture();
  AttractionResult region;
  region.referenceLoss = 1.0;
  region.parameters = {{"k", 0.5, 2.0, false, false, 0}};
  MonteCarloOptions mo;
  mo.runs = 200;
  mo.threads = 2;
  const auto mc = monteCarloStarts(*f.estimate, f.u, f.y, kTs, region, mo,
                                   [](double fr, const std::string&) {
                                     return fr > 0.02 ? ProgressAction::Abort
                                                      : ProgressAction::Continue;
                                   });
  EXPECT_EQ(mc.termination, Termination::Cancelled);
  EXPECT_LT(mc.completed, 200);
}

}  // namespace
}  // namespace flexarm
