// Compare (core/compare/compare.h) against the fit pipeline on simulated logs whose truth is
// known: the same model on the same range gives the fit's own fit % to the last digit (the
// rate, the start, the means and the effects are those of the fit), every figure says what it
// is, and the open-loop simulation, the load observer's prediction and the linear part alone
// are three different numbers for one model with effects.
#include <gtest/gtest.h>

#include <cmath>

#include "core/compare/compare.h"
#include "core/compare/compare_json.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

std::shared_ptr<const IdData> simulatedLog(const PhysicalModel& truth, const std::vector<Effect>& effects,
                                           double seconds, std::uint64_t seed, double rateHz = 2000.0,
                                           bool armAngle = false) {
  SimulationOptions o;
  o.durationS = seconds;
  o.seed = seed;
  o.logRateHz = rateHz;
  o.logArmAngle = armAngle;
  const SimulationResult sim = simulateClosedLoop(truth, effects, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  return std::make_shared<const IdData>(sim.data);
}

FitOptions physicalFit(std::shared_ptr<const IdData> log, const std::string& structure, SecondsRange est,
                       SecondsRange val, int decimation) {
  FitOptions o;
  o.model.kind = FitModelKind::Physical;
  auto start = makeModel(structure);
  for (const char* p : {"k_g", "d_g", "J_a", "k_a", "d_a"})
    if (start->indexOf(p) >= 0) start->setFree(p, true);
  o.model.start = std::shared_ptr<const PhysicalModel>(std::move(start));
  o.estimation = {{log, est}};
  o.validation = {{log, val}};
  o.decimation = decimation;
  return o;
}

EvaluatedModel estimateOf(const FitResult& r, int decimation) {
  EvaluatedModel m;
  m.name = "estimate";
  m.physical = r.physical;
  m.effects = r.effects;
  m.decimation = decimation;
  m.smoothingSpeed = r.smoothingSpeed;
  return m;
}

CompareRequest requestOn(std::shared_ptr<const IdData> log, SecondsRange est, SecondsRange val) {
  CompareRequest c;
  c.data = {std::move(log), est, val, "simulated.csv"};
  return c;
}

TEST(Compare, GivesTheFitsOwnFitPercentOnBothRanges) {
  // A decimated fit: the fit's numbers are of the data at its 200 Hz; Compare runs the
  // estimate at the rate it was fitted at, so the same model and range give the same number.
  const auto log = simulatedLog(*makeModel("two-mass"), {}, 8.0, 11);
  const SecondsRange est{0.5, 5.0}, val{5.0, 8.0};
  const FitResult fit = fitModel(physicalFit(log, "two-mass", est, val, 10));
  ASSERT_TRUE(fit.ok()) << fit.message;
  ASSERT_TRUE(fit.fitValidation() && fit.fitEstimation);
  CompareRequest c = requestOn(log, est, val);
  c.models = {estimateOf(fit, 10)};
  const CompareResult onValidation = runCompare(c);
  ASSERT_TRUE(onValidation.ok()) << onValidation.message;
  ASSERT_TRUE(onValidation.models.front().fit);
  EXPECT_DOUBLE_EQ(onValidation.models.front().fit->percent.seed52, *fit.fitValidation());
  EXPECT_DOUBLE_EQ(onValidation.models.front().fit->percent.nrmse, *fit.fitValidationNrmse());
  EXPECT_EQ(onValidation.models.front().fit->basis.start, FitStart::LogStart);
  EXPECT_DOUBLE_EQ(onValidation.models.front().fit->basis.rateHz, 200.0);
  // And it is the same thing: the fit's figure has the same basis (the fit names no file).
  FitBasis named = fit.validation.front().basis;
  named.data = "simulated.csv";
  EXPECT_EQ(named, onValidation.models.front().fit->basis) << fitBasisText(named) << " / "
                                                           << fitBasisText(onValidation.models.front().fit->basis);
  c.range = DataRange::Estimation;
  const CompareResult onEstimation = runCompare(c);
  ASSERT_TRUE(onEstimation.models.front().fit);
  EXPECT_DOUBLE_EQ(onEstimation.models.front().fit->percent.seed52, *fit.fitEstimation);
  EXPECT_EQ(onEstimation.models.front().fit->basis.start, FitStart::RangeStart);
  named = fit.estimation.front().basis;
  named.data = "simulated.csv";
  EXPECT_EQ(named, onEstimation.models.front().fit->basis);
  // The same estimate taken at the log's 2 kHz is another figure (a noisier velocity from the
  // angle), and says so.
  c.range = DataRange::Validation;
  c.models.front().decimation = 1;
  const CompareResult atLogRate = runCompare(c);
  ASSERT_TRUE(atLogRate.models.front().fit);
  EXPECT_DOUBLE_EQ(atLogRate.models.front().fit->basis.rateHz, 2000.0);
  EXPECT_NE(atLogRate.models.front().fit->percent.seed52, *fit.fitValidation());
  EXPECT_NE(atLogRate.models.front().fit->basis, onValidation.models.front().fit->basis);
}

TEST(Compare, AModelWithEffectsIsComparedThroughItsFitsObserverUnlessAsked) {
  // Coulomb friction on a closed-loop log at 1 kHz: the nonlinear fit predicts through the
  // 4 Hz load observer; Compare's default is that same figure, the open-loop simulation is a
  // lower one, and the linear part alone without its effect another still.
  std::vector<Effect> truthEffects{Effect{EffectKind::CoulombFriction, {0.05, 0.1}}};
  const auto log = simulatedLog(*makeModel("two-mass"), truthEffects, 7.0, 23, 1000.0);
  FitOptions o = physicalFit(log, "two-mass", {0.0, 4.5}, {4.5, 7.0}, 1);
  o.model.effects = {FitEffect::defaults(EffectKind::CoulombFriction)};
  const FitResult fit = fitModel(o);
  ASSERT_TRUE(fit.ok()) << fit.message;
  ASSERT_TRUE(fit.fitValidation());
  CompareRequest c = requestOn(log, {0.0, 4.5}, {4.5, 7.0});
  c.models = {estimateOf(fit, 1)};
  const CompareResult autoObserver = runCompare(c);
  ASSERT_TRUE(autoObserver.models.front().fit) << autoObserver.models.front().message;
  const FitFigure& predicted = *autoObserver.models.front().fit;
  EXPECT_DOUBLE_EQ(predicted.percent.seed52, *fit.fitValidation());
  EXPECT_DOUBLE_EQ(fit.validation.front().basis.observerHz, kClosedLoopObserverHz);
  EXPECT_DOUBLE_EQ(predicted.basis.observerHz, kClosedLoopObserverHz);
  EXPECT_TRUE(predicted.basis.effects);
  EXPECT_FALSE(predicted.basis.meansRemoved);  // friction acts on the real velocity
  EXPECT_NE(fitBasisText(predicted.basis).find("load observer"), std::string::npos);
  c.observerHz = 0.0;
  const CompareResult simulated = runCompare(c);
  ASSERT_TRUE(simulated.models.front().fit);
  EXPECT_TRUE(simulated.models.front().fit->basis.isSimulation());
  EXPECT_LT(simulated.models.front().fit->percent.seed52, predicted.percent.seed52);
  c.models.front().effects.clear();
  const CompareResult linear = runCompare(c);
  ASSERT_TRUE(linear.models.front().fit);
  EXPECT_FALSE(linear.models.front().fit->basis.effects);
  EXPECT_NE(linear.models.front().fit->percent.seed52, simulated.models.front().fit->percent.seed52);
}

TEST(Compare, KStepPredictionOfABlackBoxModelAndItsLimits) {
  // An ARX model fitted at the log's 500 Hz: its one-step prediction fits better than its
  // simulation, and a horizon far beyond its memory predicts what it simulates.
  const auto log = simulatedLog(*makeModel("two-mass"), {}, 6.0, 5, 500.0);
  FitOptions o;
  o.model.kind = FitModelKind::BlackBox;
  o.model.structure = PolyStructure::Arx;
  o.model.orders = PolyOrders{2, 2, 0, 0, 0, 1};
  o.estimation = {{log, SecondsRange{0.0, 4.0}}};
  o.validation = {{log, SecondsRange{4.0, 6.0}}};
  const FitResult fit = fitModel(o);
  ASSERT_TRUE(fit.ok()) << fit.message;
  EvaluatedModel m;
  m.name = "arx";
  m.polynomial = fit.polynomial;
  CompareRequest c = requestOn(log, {0.0, 4.0}, {4.0, 6.0});
  c.models = {m};
  const double simulation = runCompare(c).models.front().fit->percent.seed52;
  EXPECT_DOUBLE_EQ(simulation, *fit.fitValidation());
  c.horizon = 1;
  const CompareResult oneStep = runCompare(c);
  ASSERT_TRUE(oneStep.models.front().fit);
  EXPECT_EQ(oneStep.models.front().fit->basis.horizon, 1);
  EXPECT_GT(oneStep.models.front().fit->percent.seed52, simulation);
  EXPECT_EQ(fitKindText(oneStep.models.front().fit->basis), "1-step prediction");
  c.horizon = 5000;
  EXPECT_NEAR(runCompare(c).models.front().fit->percent.seed52, simulation, 1e-6);
  // Black-box models at a rate that is no multiple of the data's are listed, not compared.
  c.horizon = 0;
  auto odd = std::make_shared<PolynomialModel>(*fit.polynomial);
  odd->sampleTime = 1.5 / 500.0;
  c.models.front().polynomial = odd;
  const CompareResult mismatch = runCompare(c);
  EXPECT_EQ(mismatch.models.front().status, CompareStatus::RateMismatch);
  EXPECT_FALSE(mismatch.models.front().fit);
}

TEST(Compare, FallsBackToTheEstimationRangeAndSaysSo) {
  const auto log = simulatedLog(*makeModel("two-mass"), {}, 3.0, 2, 1000.0);
  CompareRequest c;
  c.data = {log, SecondsRange{0.5, 2.5}, std::nullopt, "simulated.csv"};
  EvaluatedModel truth;
  truth.name = "truth";
  truth.physical = std::shared_ptr<const PhysicalModel>(makeModel("two-mass"));
  c.models = {truth};
  const CompareResult r = runCompare(c);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.rangeFellBack);
  EXPECT_EQ(r.range, DataRange::Estimation);
  // The truth explains the chirp's motor velocity closely.
  EXPECT_GT(r.models.front().fit->percent.seed52, 90.0);
  const nlohmann::json j = compareResultJson(r);
  EXPECT_EQ(j["range"], "estimation");
  EXPECT_EQ(j["range_fell_back"], true);
  EXPECT_EQ(j["models"][0]["status"], "compared");
  EXPECT_DOUBLE_EQ(j["models"][0]["fit_percent"].get<double>(), r.models.front().fit->percent.seed52);
  EXPECT_EQ(j["models"][0]["basis"]["kind"], "simulation");
  EXPECT_EQ(j["models"][0]["basis"]["start"], "range");
  // An invalid request is misuse.
  c.horizon = -1;
  EXPECT_THROW(runCompare(c), std::invalid_argument);
}

TEST(Compare, TheDeflectionCheckIsTheFitsOn) {
  // A quiet arm with an arm-side encoder: Compare's deflection figure of the estimate on the
  // validation range is the one the fit reports.
  SimulationOptions quiet;
  quiet.disturbance.loadTorqueStd = 0.2;
  quiet.durationS = 5.0;
  quiet.seed = 9;
  quiet.logArmAngle = true;
  const SimulationResult sim = simulateClosedLoop(*makeModel("two-mass"), {}, quiet);
  ASSERT_EQ(sim.termination, Termination::Converged);
  const auto log = std::make_shared<const IdData>(sim.data);
  const FitResult fit = fitModel(physicalFit(log, "two-mass", {0.0, 3.5}, {3.5, 5.0}, 1));
  ASSERT_TRUE(fit.ok()) << fit.message;
  ASSERT_TRUE(fit.deflection && fit.deflection->fitPercentValidation);
  CompareRequest c = requestOn(log, {0.0, 3.5}, {3.5, 5.0});
  c.models = {estimateOf(fit, 1)};
  const CompareResult r = runCompare(c);
  ASSERT_TRUE(r.models.front().deflection);
  EXPECT_NEAR(r.models.front().deflection->figure.percent.seed52, *fit.deflection->fitPercentValidation, 1e-9);
  EXPECT_GT(r.measuredDeflection.size(), 0);
  c.range = DataRange::Estimation;
  EXPECT_NEAR(runCompare(c).models.front().deflection->figure.percent.seed52, *fit.deflection->fitPercent, 1e-9);
}

TEST(Compare, CancelStopsBetweenModels) {
  const auto log = simulatedLog(*makeModel("two-mass"), {}, 2.0, 4, 1000.0);
  CompareRequest c = requestOn(log, {0.0, 1.0}, {1.0, 2.0});
  EvaluatedModel m;
  m.name = "a";
  m.physical = std::shared_ptr<const PhysicalModel>(makeModel("two-mass"));
  c.models = {m, m, m};
  int calls = 0;
  const CompareResult r = runCompare(c, [&calls](double, const std::string&) {
    return ++calls >= 2 ? ProgressAction::Abort : ProgressAction::Continue;
  });
  EXPECT_EQ(r.termination, Termination::Cancelled);
  EXPECT_EQ(r.code, CompareCode::Cancelled);
  EXPECT_EQ(r.models.size(), 1u);
}

}  // namespace
}  // namespace flexarm
