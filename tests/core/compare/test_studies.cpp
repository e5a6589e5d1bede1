// The residual analysis and the sensitivity study as requests (core/compare): the truth's
// errors are white where a model too small for the data leaves correlated ones, the codes
// name what stops a study, and the study's fits find the estimate again from starts around it.
#include <gtest/gtest.h>

#include "core/compare/compare_json.h"
#include "core/compare/residual_study.h"
#include "core/compare/sensitivity_study.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

std::shared_ptr<const IdData> openLoopishLog(double seconds, std::uint64_t seed, double rateHz,
                                             const std::string& structure = "three-mass") {
  SimulationOptions o;
  o.durationS = seconds;
  o.seed = seed;
  o.logRateHz = rateHz;
  o.disturbance.loadTorqueStd = 0.0;  // the output errors of the truth are the encoder's alone
  o.excitation.kind = ExcitationKind::Multisine;
  const SimulationResult sim = simulateClosedLoop(*makeModel(structure), {}, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  return std::make_shared<const IdData>(sim.data);
}

EvaluatedModel physical(const std::string& structure) {
  EvaluatedModel m;
  m.name = structure;
  m.physical = std::shared_ptr<const PhysicalModel>(makeModel(structure));
  return m;
}

TEST(Residuals, TheTruthsErrorsAreIndependentOfTheInputWhereARigidModelsAreNot) {
  const auto log = openLoopishLog(6.0, 3, 500.0);
  ResidualsRequest r;
  r.data = {log, SecondsRange{0.0, 6.0}, std::nullopt, "sim.csv"};
  r.model = physical("three-mass");
  const ResidualsResult truth = runResiduals(r);
  ASSERT_TRUE(truth.ok()) << truth.message;
  EXPECT_EQ(truth.code, ResidualsCode::Ok);
  EXPECT_EQ(static_cast<int>(truth.analysis.lags.size()), r.options.maxLag + 1);
  EXPECT_FALSE(truth.predictionErrors);
  r.model = physical("rigid");
  const ResidualsResult rigid = runResiduals(r);
  ASSERT_TRUE(rigid.ok()) << rigid.message;
  EXPECT_FALSE(rigid.analysis.independent);
  EXPECT_GT(rigid.analysis.independenceStatistic, truth.analysis.independenceStatistic);
  const nlohmann::json j = residualsResultJson(rigid);
  EXPECT_EQ(j["code"], "ok");
  EXPECT_EQ(j["errors"], "output_error");
  EXPECT_EQ(j["independence"]["passed"], false);
}

TEST(Residuals, CodesNameWhatStopsTheAnalysis) {
  const auto log = openLoopishLog(1.0, 4, 200.0);
  ResidualsRequest r;
  r.data = {log, SecondsRange{0.0, 1.0}, std::nullopt, "sim.csv"};
  r.model = physical("two-mass");
  r.range = DataRange::Validation;
  EXPECT_EQ(runResiduals(r).code, ResidualsCode::NoRange);
  r.range = DataRange::Estimation;
  r.options.maxLag = 200;  // 200 samples cannot carry 200 lags
  const ResidualsResult shortRange = runResiduals(r);
  EXPECT_EQ(shortRange.code, ResidualsCode::TooShort);
  EXPECT_EQ(shortRange.termination, Termination::Failed);
  r.options.maxLag = 0;
  EXPECT_THROW(runResiduals(r), std::invalid_argument);
}

TEST(Sensitivity, TheStudyFindsTheEstimateFromStartsAroundIt) {
  const auto log = openLoopishLog(3.0, 8, 200.0, "two-mass");
  SensitivityRequest s;
  s.data = {log, SecondsRange{0.0, 3.0}, std::nullopt, "sim.csv"};
  auto model = makeModel("two-mass");
  for (const auto& p : model->parameters()) model->setFree(p.name, p.name == "J_m" || p.name == "J_a");
  s.model.name = "two-mass";
  s.model.physical = std::shared_ptr<const PhysicalModel>(std::move(model));
  // A narrow search (from a third to three times the estimate): the Monte-Carlo region, a
  // fifth of it, lies where every start comes back.
  s.attraction.maxFactor = 3.0;
  s.attraction.minFactor = 0.3;
  s.attraction.halvings = 3;
  s.attraction.threads = 2;
  s.monteCarlo.runs = 6;
  s.monteCarlo.threads = 2;
  const SensitivityResult r = runSensitivityStudy(s);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.attraction.parameters.size(), 2u);
  for (const auto& p : r.attraction.parameters) {
    EXPECT_LT(p.lowerFactor, 1.0) << p.name;
    EXPECT_GT(p.upperFactor, 1.0) << p.name;
  }
  ASSERT_TRUE(r.monteCarlo);
  EXPECT_EQ(r.monteCarlo->completed, 6);
  EXPECT_EQ(r.monteCarlo->successes, 6) << r.summary();
  const nlohmann::json j = sensitivityResultJson(r);
  EXPECT_EQ(j["monte_carlo"]["completed"], 6);
  EXPECT_EQ(j["attraction"]["parameters"].size(), 2u);
}

TEST(Sensitivity, CodesNameWhatStopsTheStudy) {
  const auto log = openLoopishLog(1.0, 8, 200.0);
  SensitivityRequest s;
  s.data = {log, std::nullopt, std::nullopt, "sim.csv"};
  s.model.name = "arx";
  s.model.polynomial = std::make_shared<PolynomialModel>();
  EXPECT_EQ(runSensitivityStudy(s).code, SensitivityCode::NotPhysical);
  auto fixed = makeModel("two-mass");
  for (const auto& p : fixed->parameters()) fixed->setFree(p.name, false);
  s.model.polynomial.reset();
  s.model.physical = std::shared_ptr<const PhysicalModel>(std::move(fixed));
  EXPECT_EQ(runSensitivityStudy(s).code, SensitivityCode::NoFreeParameters);
  s.monteCarlo.runs = -1;
  EXPECT_THROW(runSensitivityStudy(s), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
