// The arm side in the fit pipeline (core/ident/fit.h) on simulated logs whose truth is known:
// the deflection r phi_m - phi_a a fit predicts against an arm-side encoder, a skew between the
// two encoders found as such, the log's gear ratio as the one source of r, the plausibility
// sentences, and Auto's choice when the log's controller cannot be identified.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/ident/fit.h"
#include "core/io/log_io.h"
#include "core/sim/closed_loop.h"
#include "tests/test_scale.h"

namespace flexarm {
namespace {

// A closed-loop log of structure at 2 kHz with an arm-side encoder.
std::shared_ptr<IdData> armLog(const PhysicalModel& model, double seconds, std::uint64_t seed,
                               const SimulationOptions& base = {}) {
  SimulationOptions o = base;
  o.durationS = seconds;
  o.seed = seed;
  o.logArmAngle = true;
  const SimulationResult sim = simulateClosedLoop(model, {}, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  return std::make_shared<IdData>(sim.data);
}

FitOptions fitOf(std::shared_ptr<const IdData> log, const std::string& structure) {
  FitOptions o;
  o.model.kind = FitModelKind::Physical;
  o.model.start = std::shared_ptr<const PhysicalModel>(makeModel(structure));
  o.estimation = {{std::move(log), std::nullopt}};
  return o;
}

TEST(FitArmSide, TheTruthPredictsTheMeasuredDeflection) {
  // A quiet arm: the load disturbance (which deflects the gear without any motor torque) at a
  // tenth of the simulator's default.
  SimulationOptions quiet;
  quiet.disturbance.loadTorqueStd = 0.2;
  const auto log = armLog(*makeModel("two-mass"), 6.0, 41, quiet);
  ASSERT_NE(log->channel(columns::kArmAngle), nullptr);
  FitOptions o = fitOf(log, "two-mass");
  o.validation = {{log, SecondsRange{4.0, 6.0}}};
  o.estimation.front().range = SecondsRange{0.0, 4.0};
  const FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_TRUE(r.deflection.has_value());
  const DeflectionCheck& c = *r.deflection;
  // The estimate is the truth within its intervals, so it predicts the deflection the arm
  // encoder sees from the torque alone, on both ranges.
  ASSERT_TRUE(c.fitPercent && c.fitPercentValidation);
  EXPECT_GT(*c.fitPercent, 95.0);
  EXPECT_GT(*c.fitPercentValidation, 95.0);
  EXPECT_LT(*c.fitPercentNrmse, *c.fitPercent);
  EXPECT_GT(c.measuredRms, 1e-5);
  EXPECT_LT(c.rmsEstimation, 0.25 * c.measuredRms);
  EXPECT_NEAR(c.gearRatio, 1.0 / 118.0, 1e-12);
  // No skew between the encoders: a few microseconds at most (its std assumes white errors,
  // which the deflection's are not).
  EXPECT_LT(std::abs(c.skewSeconds), 2e-5) << c.skewSeconds << " +- " << c.skewStd;
  EXPECT_EQ(c.measured.size(), static_cast<Eigen::Index>(r.data.u.size()));
  EXPECT_EQ(c.predicted.size(), c.measured.size());
}

TEST(FitArmSide, ASkewBetweenTheEncodersIsFoundAsSuch) {
  // The arm encoder read 3 ms (6 samples) late, as on the KUKA KR300 logs.
  auto log = armLog(*makeModel("two-mass"), 6.0, 42);
  std::vector<double>& arm = log->channel(columns::kArmAngle)->values;
  std::vector<double> late(arm.size());
  for (std::size_t k = 0; k < arm.size(); ++k) late[k] = arm[k >= 6 ? k - 6 : 0];
  arm = late;
  const FitResult r = fitModel(fitOf(log, "two-mass"));
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_TRUE(r.deflection.has_value());
  const DeflectionCheck& c = *r.deflection;
  EXPECT_NEAR(c.skewSeconds, 3e-3, 0.3e-3);
  ASSERT_TRUE(c.fitPercent && c.fitPercentWithoutSkew);
  EXPECT_GT(*c.fitPercentWithoutSkew, *c.fitPercent + 5.0);
  EXPECT_GT(*c.fitPercentWithoutSkew, 90.0);
}

TEST(FitArmSide, NoArmEncoderNoDeflection) {
  SimulationOptions so;
  so.durationS = 3.0;
  const SimulationResult sim = simulateClosedLoop(*makeModel("two-mass"), {}, so);
  const FitResult r = fitModel(fitOf(std::make_shared<IdData>(sim.data), "two-mass"));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.deflection.has_value());
}

TEST(FitArmSide, TheLogsGearRatioIsTheModelsR) {
  auto model = makeModel("two-mass");
  model->setParameter("r", 0.01);
  auto log = armLog(*model, 4.0, 43);
  EXPECT_EQ(log->meta("gear_ratio"), "0.01");
  FitResult r = fitModel(fitOf(log, "two-mass"));  // the default start has r = 1/118
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_DOUBLE_EQ(r.physical->value("r"), 0.01);
  for (const auto& s : r.plausibility) EXPECT_EQ(s.find("gear ratio"), std::string::npos) << s;
  // Written as a ratio, as 1/256.86 is.
  log->setMeta("gear_ratio", "1/100");
  r = fitModel(fitOf(log, "two-mass"));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_DOUBLE_EQ(r.physical->value("r"), 0.01);
  // Motor turns per arm turn is refused with the way to write it.
  log->setMeta("gear_ratio", "100");
  r = fitModel(fitOf(log, "two-mass"));
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.message.find("1/100"), std::string::npos) << r.message;
  // No gear ratio stated: the fit says r was never set.
  log->metadata.erase(std::remove_if(log->metadata.begin(), log->metadata.end(),
                                     [](const auto& kv) { return kv.first == "gear_ratio"; }),
                      log->metadata.end());
  r = fitModel(fitOf(log, "two-mass"));
  ASSERT_TRUE(r.ok()) << r.message;
  const bool said = std::any_of(r.plausibility.begin(), r.plausibility.end(),
                                [](const std::string& s) { return s.find("states no gear ratio") != std::string::npos; });
  EXPECT_TRUE(said);
}

TEST(FitArmSide, AnUndeterminedSpringIsCalledSo) {
  // A rigid axis fitted as two-mass: nothing in the data determines the spring.
  auto rigid = makeModel("rigid");
  const auto log = armLog(*rigid, 4.0, 44);
  const FitResult r = fitModel(fitOf(log, "two-mass"));
  ASSERT_FALSE(r.plausibility.empty()) << r.message;
  const bool named = std::any_of(r.plausibility.begin(), r.plausibility.end(), [](const std::string& s) {
    return s.find("k_a") != std::string::npos || s.find("resonates") != std::string::npos;
  });
  EXPECT_TRUE(named) << r.plausibility.front();
  // The truth's own fit says nothing of the kind.
  const FitResult t = fitModel(fitOf(armLog(*makeModel("two-mass"), 4.0, 45), "two-mass"));
  ASSERT_TRUE(t.ok()) << t.message;
  EXPECT_TRUE(t.plausibility.empty()) << t.plausibility.front();
}

TEST(FitArmSide, InverseDynamicsStartsAFitOfAHeavierAxis) {
  // An axis five times heavier and stiffer than the default (the same resonances): the default
  // start is off by a factor of five, inverse dynamics scales it, and the fit reaches the truth.
  auto heavy = makeModel("two-mass");
  for (const char* p : {"J_m", "J_a", "f_m", "k_a", "d_a"}) heavy->setParameter(p, 5.0 * heavy->value(p));
  SimulationOptions wide;  // a multisine: the rigid body moves below the first notch too
  wide.excitation.kind = ExcitationKind::Multisine;
  wide.excitation.amplitude = 0.2;
  const auto log = armLog(*heavy, 8.0, 46, wide);
  const FitResult r = fitModel(fitOf(log, "two-mass"));
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_TRUE(r.idim.has_value());
  EXPECT_NE(r.idimNote.find("scaled"), std::string::npos) << r.idimNote;
  EXPECT_EQ(r.summary.termination, Termination::Converged);
  for (const char* p : {"J_m", "J_a", "k_a"})
    EXPECT_NEAR(r.physical->value(p), heavy->value(p), 0.02 * heavy->value(p)) << p;
  // The default axis's own log keeps the start.
  const FitResult same = fitModel(fitOf(armLog(*makeModel("two-mass"), 8.0, 47, wide), "two-mass"));
  ASSERT_TRUE(same.ok()) << same.message;
  EXPECT_NE(same.idimNote.find("kept"), std::string::npos) << same.idimNote;
}

TEST(FitArmSide, AutoWithAnUnknownControllerTakesDirectWhenHausmanSeesNoBias) {
  // A low-noise log of a controller that is not Figure 5.1's: velocity feed-forward and a
  // velocity filter. It cannot be identified, so Auto tests direct against two-stage.
  SimulationOptions so;
  so.velocityFeedForward = 1.0;
  so.velocityFilterHz = 150.0;
  so.disturbance.torqueNoiseStd = 0.002;
  so.disturbance.loadTorqueStd = 0.2;
  const auto truth = makeModel("two-mass");
  const auto log = armLog(*truth, 12.0, 48, so);
  FitOptions o = fitOf(log, "two-mass");
  const FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_TRUE(r.method.has_value());
  EXPECT_EQ(*r.method, ClosedLoopMethod::Direct) << r.methodReason;
  EXPECT_NE(r.methodReason.find("Durbin-Wu-Hausman"), std::string::npos) << r.methodReason;
  EXPECT_NE(r.methodReason.find("velocity feed-forward"), std::string::npos) << r.methodReason;
  EXPECT_NE(r.methodReason.find("agree within their uncertainty"), std::string::npos) << r.methodReason;
  for (const auto& p : r.parameters)
    if (p.free) {
      EXPECT_NEAR(p.value, truth->value(p.name), 0.01 * truth->value(p.name)) << p.name;
    }
  // At the simulator's default noise (ten times the load disturbance) the feedback biases the
  // direct fit beyond the two-stage fit's uncertainty: the test says so and takes two-stage.
  so.disturbance.torqueNoiseStd = 0.02;
  so.disturbance.loadTorqueStd = 2.0;
  const FitResult loud = fitModel(fitOf(armLog(*truth, 12.0, 48, so), "two-mass"));
  ASSERT_TRUE(loud.ok()) << loud.message;
  EXPECT_EQ(*loud.method, ClosedLoopMethod::TwoStage) << loud.methodReason;
  EXPECT_NE(loud.methodReason.find("differ beyond their uncertainty"), std::string::npos) << loud.methodReason;
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

// The sample chirp log's default three-mass fit starts inside its bounds (the start's
// d_g = -62 of Table 5.7 keeps the model's own bound) and converges well inside the default
// iteration limit to the log's truth (Table 5.7 p6), with nothing called absurd.
TEST(FitArmSide, TheDefaultThreeMassFitConverges) {
  const LogReadResult read = readLog(std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv");
  ASSERT_TRUE(read.ok) << read.error.toString();
  FitOptions o;
  o.model.kind = FitModelKind::Physical;
  o.model.start = std::shared_ptr<const PhysicalModel>(makeModel("three-mass"));
  o.estimation = {{std::make_shared<IdData>(read.data), std::nullopt}};
  const FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.summary.termination, Termination::Converged) << r.summary.message;
  EXPECT_LT(r.summary.iterations, 20);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  EXPECT_TRUE(r.plausibility.empty()) << r.plausibility.front();
  const auto truth = makeModel("three-mass");
  for (const auto& p : r.parameters)
    if (p.free) {
      EXPECT_NEAR(p.value, truth->value(p.name), 0.05 * std::abs(truth->value(p.name))) << p.name;
    }
}

}  // namespace
}  // namespace flexarm
