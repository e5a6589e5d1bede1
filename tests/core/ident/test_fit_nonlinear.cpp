// Nonlinear grey-box fits in the one fit pipeline (core/ident/fit.h with FitModelSpec::effects,
// core/ident/nonlinear_pem.h): a three-mass arm (3.21, Table 5.7 p6) with a stiffening gear
// spring k delta (1 + beta delta^2) and Coulomb friction F_c tanh(phi_m'/v_s), simulated open
// loop from a known truth, is fitted by output error (5.7) with the effects' parameters free;
// the truth lies inside the 99 % intervals of the model's and the effects' parameters, on a
// validation experiment of another excitation the fit is far better than the linear fit's,
// and several estimation experiments are each simulated from their own start.
#include <gtest/gtest.h>

#include "tests/test_scale.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "core/ident/fit.h"
#include "core/models/physical_models.h"
#include "tests/core/ident/nonlinear_logs.h"

namespace flexarm {
namespace {

using testing::nonlinearTruthEffects;

std::shared_ptr<const IdData> nonlinearLog(std::size_t n, int kind, unsigned seed) {
  return std::make_shared<const IdData>(testing::nonlinearLog(n, kind, seed));
}

// The three-mass start with every free parameter 10-25 % off the truth.
std::shared_ptr<const PhysicalModel> perturbedStart() {
  auto m = makeModel("three-mass");
  const std::pair<const char*, double> f[] = {{"J_m", 1.15}, {"J_g", 0.85}, {"J_a", 1.1},  {"f_m", 1.2},
                                              {"k_g", 0.9},  {"k_a", 1.1},  {"d_g", 0.85}, {"d_a", 1.2}};
  for (const auto& [name, factor] : f) m->setParameter(name, m->value(name) * factor);
  return m;
}

FitOptions optionsFor(std::vector<std::shared_ptr<const IdData>> estimation, std::shared_ptr<const IdData> validation,
                      bool withEffects) {
  FitOptions o;
  o.model.kind = FitModelKind::Physical;
  o.model.start = perturbedStart();
  // The truth's gear damping is the seed's negative d_g (Table 5.7); open its default bound.
  o.bounds.push_back({"d_g", -INFINITY, INFINITY});
  if (withEffects) {
    FitEffect spring = FitEffect::defaults(EffectKind::NonlinearSpring);
    spring.effect.values[0] = 1e6;  // half the truth
    FitEffect coulomb = FitEffect::defaults(EffectKind::CoulombFriction);
    coulomb.effect.values[0] = 0.02;  // v_s fixed at the truth's 0.1 rad/s
    coulomb.scaleSmoothing = false;
    o.model.effects = {spring, coulomb};
  }
  for (auto& e : estimation) o.estimation.push_back({e, std::nullopt});
  o.validation.push_back({validation, std::nullopt});
  o.maxIterations = 40;
  return o;
}

// The truth of a parameter row: the model's, or the effect's.
double truthOf(const FitParameter& p) {
  if (p.effect.empty()) return makeModel("three-mass")->value(p.name);
  for (const Effect& e : nonlinearTruthEffects())
    if (p.effect == toString(e.kind)) {
      const auto& info = effectParameters(e.kind);
      for (std::size_t k = 0; k < info.size(); ++k)
        if (info[k].name == p.name) return e.values[k];
    }
  ADD_FAILURE() << "no truth for " << p.effect << " " << p.name;
  return NAN;
}

std::size_t samples() { return test::reducedSizes() ? 2000 : 4000; }

TEST(FitNonlinear, RecoversSpringAndFrictionInsideTheirIntervalsAndBeatsTheLinearFitOnValidation) {
  const auto est = nonlinearLog(samples(), 0, 1);
  const auto val = nonlinearLog(samples(), 1, 2);  // another excitation
  const FitResult r = fitModel(optionsFor({est}, val, true));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.modelName(), "three-mass + nonlinear_spring + coulomb_friction (K = 0)");
  ASSERT_EQ(r.effects.size(), 2u);
  int effectRows = 0;
  for (const auto& p : r.parameters) {
    if (!p.free) continue;
    const double truth = truthOf(p);
    ASSERT_GT(p.std, 0.0) << p.name;
    EXPECT_TRUE(truth >= p.lower && truth <= p.upper)
        << p.effect << " " << p.name << " = " << p.value << " +- " << p.std << ", truth " << truth << ", off by "
        << (p.value - truth) / p.std << " std";
    effectRows += !p.effect.empty();
  }
  EXPECT_EQ(effectRows, 2);  // beta and F_c (v_s fixed)
  ASSERT_EQ(r.fullCovariance.rows(), 10);
  // The linear fit of the same data (means removed as it does) cannot follow the spring and
  // the friction: the validation fit is far worse.
  const FitResult linear = fitModel(optionsFor({est}, val, false));
  ASSERT_TRUE(linear.ok()) << linear.message;
  ASSERT_TRUE(r.fitValidation() && linear.fitValidation());
  std::printf("validation fit %% (5.2): %.3f with effects, %.3f without; fit %.2f s\n", *r.fitValidation(),
              *linear.fitValidation(), r.seconds);
  EXPECT_GT(*r.fitValidation(), 99.5);  // noise of 1 % of the spread: 99.99 at best
  EXPECT_LT(*linear.fitValidation(), *r.fitValidation() - 2.0);
}

// Two estimation experiments (different excitations and lengths) fitted at once, each
// simulated from its own start: the truth inside the intervals, every experiment's fit % high
// (one simulation running across the seam would not start the second from its own state).
TEST(FitNonlinear, SeveralEstimationExperimentsEachFromTheirOwnStart) {
  const auto a = nonlinearLog(samples() / 2, 0, 3);
  const auto b = nonlinearLog(samples() / 2 + 300, 1, 4);
  const auto val = nonlinearLog(samples() / 2, 0, 5);
  const FitResult r = fitModel(optionsFor({a, b}, val, true));
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.estimation.size(), 2u);
  for (const auto& e : r.estimation) {
    ASSERT_TRUE(e.fitPercent);
    EXPECT_GT(*e.fitPercent, 99.5);
  }
  for (const auto& p : r.parameters)
    if (p.free) {
      const double truth = truthOf(p);
      EXPECT_TRUE(truth >= p.lower && truth <= p.upper)
          << p.effect << " " << p.name << " = " << p.value << " +- " << p.std << ", truth " << truth;
    }
}

// Fixed effect values stay where they were given, and the options refuse what a fit with
// effects cannot do.
TEST(FitNonlinear, FixedEffectValuesStayAndMisuseIsRefused) {
  const auto est = nonlinearLog(1200, 0, 6);
  FitOptions o = optionsFor({est}, est, true);
  o.validation.clear();
  o.model.effects[0].free = {false, false};  // beta fixed at the truth
  o.model.effects[0].effect.values[0] = 2e6;
  o.maxIterations = 3;
  const FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.effects[0].values[0], 2e6);
  for (const auto& p : r.parameters) {
    if (p.name == "beta") {
      EXPECT_FALSE(p.free);
    }
  }
  FitOptions bad = o;
  bad.noiseModel = NoiseModel::Innovations;
  EXPECT_EQ(bad.check().issue, FitIssue::ExcludesInnovations) << bad.check().message;
  bad = o;
  bad.model.effects.push_back(bad.model.effects[0]);
  EXPECT_EQ(bad.check().issue, FitIssue::EffectTwice) << bad.check().message;
  bad = o;
  bad.model.start = makeModel("rigid");
  EXPECT_EQ(bad.check().issue, FitIssue::EffectNeedsGearSpring) << bad.check().message;
  bad = o;
  bad.model.effects.push_back(FitEffect::defaults(EffectKind::ExtraMass));
  EXPECT_EQ(bad.check().issue, FitIssue::EffectChangesStructure) << bad.check().message;
}

}  // namespace
}  // namespace flexarm
