// The one fit pipeline (core/ident/fit.h) and the controller it identifies from a log
// (controller_ident.h), on closed-loop logs of the simulator (Figure 5.1) whose truth is known:
// the cascade's gains come back, Auto takes the indirect fit and says why, the two-mass truth
// lies inside the 99 % intervals, and every stage gives the numbers its estimator gives alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/ident/controller_ident.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit.h"
#include "core/sim/closed_loop.h"
#include "tests/core/ident/closed_loop_logs.h"

namespace flexarm {
namespace {

using testing::twoMassLog;

// The two-mass model with every parameter 10-30 % off the truth.
std::shared_ptr<const PhysicalModel> twoMassStart() {
  auto m = makeModel("two-mass");
  const std::pair<const char*, double> f[] = {{"J_m", 1.2}, {"J_a", 0.85}, {"f_m", 1.3}, {"k_a", 1.1}, {"d_a", 0.8}};
  for (const auto& [name, factor] : f) m->setParameter(name, m->value(name) * factor);
  return std::shared_ptr<const PhysicalModel>(std::move(m));
}

FitOptions physicalFit(std::shared_ptr<const IdData> log, std::optional<SecondsRange> range = std::nullopt) {
  FitOptions o;
  o.model.kind = FitModelKind::Physical;
  o.model.start = twoMassStart();
  o.estimation = {{std::move(log), range}};
  return o;
}

// Every free parameter's 99 % interval holds the truth of the nominal two-mass model.
void expectTruthInside(const FitResult& r) {
  const auto truth = makeModel("two-mass");
  int checked = 0;
  for (const auto& p : r.parameters) {
    if (!p.free) continue;
    const double t = truth->value(p.name);
    EXPECT_GE(t, p.lower) << p.name << " = " << p.value << " +- " << p.std;
    EXPECT_LE(t, p.upper) << p.name << " = " << p.value << " +- " << p.std;
    EXPECT_LT(p.std / t, 0.1) << p.name << ": interval too wide";
    ++checked;
  }
  EXPECT_EQ(checked, 5);
}

// Issue 13's log: closed loop, a reference, no controller in the metadata. Auto identifies the
// controller, takes the indirect fit, says why, and its intervals hold the truth.
TEST(Fit, AutoIdentifiesTheControllerAndTakesTheIndirectFit) {
  const FitResult r = fitModel(physicalFit(twoMassLog(8.0, 21)));
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_TRUE(r.method.has_value());
  EXPECT_EQ(*r.method, ClosedLoopMethod::Indirect);
  EXPECT_EQ(r.methodReason.rfind("auto: ", 0), 0u) << r.methodReason;
  EXPECT_NE(r.methodReason.find("unbiased"), std::string::npos) << r.methodReason;
  EXPECT_NE(r.controllerSource.find("identified from the log"), std::string::npos) << r.controllerSource;
  ASSERT_TRUE(r.controller.has_value());
  EXPECT_NEAR(r.controller->kp, 40.0, 1e-3);
  EXPECT_EQ(r.covarianceKind, CovarianceKind::Sandwich);
  expectTruthInside(r);
  // The estimate keeps the start's output (the motor velocity): fit % of the simulated output.
  ASSERT_TRUE(r.fitEstimation.has_value());
  EXPECT_GT(*r.fitEstimation, 90.0);
  EXPECT_EQ(r.physical->options().output, ModelOutput::MotorVelocity);
  EXPECT_EQ(r.data.outputName, columns::kMotorVelocity);
  EXPECT_EQ(r.notches.size(), 1u);
  EXPECT_EQ(r.peaks.size(), 1u);
  EXPECT_TRUE(r.residuals.has_value());
}

// An estimation range that starts after the log's first sample: the loop still starts at rest
// at the first sample, and the loss counts the range only.
TEST(Fit, IndirectOverALaterRangeCountsThatRangeOnly) {
  const auto log = twoMassLog(8.0, 22, true);
  FitOptions o = physicalFit(log, SecondsRange{2.0, 8.0});
  o.closedLoop = ClosedLoopChoice::Indirect;
  const FitResult later = fitModel(o);
  ASSERT_TRUE(later.ok()) << later.message;
  EXPECT_NE(later.controllerSource.find("metadata"), std::string::npos) << later.controllerSource;
  EXPECT_EQ(later.data.estimation.begin, 4000u);
  expectTruthInside(later);
  // The loss is the mean over the range's samples: the same estimate's errors over the whole
  // log would count the first 2 s as well.
  o.estimation.front().range.reset();
  const FitResult whole = fitModel(o);
  ASSERT_TRUE(whole.ok()) << whole.message;
  EXPECT_NE(later.summary.loss, whole.summary.loss);
  EXPECT_GT(std::abs(later.summary.aic - whole.summary.aic), 1.0);
}

TEST(Fit, AutoIsDirectWithoutReferenceAndTwoStageWhenDecimated) {
  auto log = twoMassLog(6.0, 23);
  FitOptions o = physicalFit(log);
  o.decimation = 10;
  FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(*r.method, ClosedLoopMethod::TwoStage);
  EXPECT_NE(r.methodReason.find("decimated"), std::string::npos) << r.methodReason;
  ASSERT_TRUE(r.referenceFitPercent.has_value());
  EXPECT_NE(r.methodDescription.find("the reference explains"), std::string::npos) << r.methodDescription;

  auto open = std::make_shared<IdData>(*log);
  open->channel(columns::kAngleRef)->role = ChannelRole::None;
  r = fitModel(physicalFit(open));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.method.has_value());  // not a closed-loop log: no method to choose
  EXPECT_TRUE(r.methodReason.empty());
  o = physicalFit(open);
  o.closedLoop = ClosedLoopChoice::TwoStage;
  r = fitModel(o);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_EQ(r.status, FitStatus::BadData) << r.message;
}

// The pipeline adds preparation and evaluation around the estimators, nothing else: a black-box
// fit and SPA give exactly what the estimators give on the prepared data.
TEST(Fit, BlackBoxAndSpaGiveWhatTheirEstimatorsGiveOnThePreparedData) {
  const auto log = twoMassLog(6.0, 24);
  FitOptions o;
  o.model.kind = FitModelKind::BlackBox;
  o.model.structure = PolyStructure::Oe;
  o.model.orders = PolyOrders{0, 4, 0, 0, 4, 1};
  o.decimation = 10;
  o.estimation = {{log, SecondsRange{0.5, 4.0}}};
  o.validation = {{log, SecondsRange{4.0, 6.0}}};
  const FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  FitDataOptions d;
  d.velocityOutput = true;  // black-box models give the motor velocity too (Section 5.2)
  d.decimation = 10;
  d.estimation = SecondsRange{0.5, 4.0};
  d.validation = SecondsRange{4.0, 6.0};
  const PreparedData p = prepareFitData(*log, d);
  ASSERT_TRUE(p.ok()) << p.message;
  const PolyEstimate e = estimatePolynomial(p.estimationInput(), p.estimationOutput(), PolyStructure::Oe,
                                            o.model.orders, p.sampleTime);
  EXPECT_EQ(r.polynomial->parameterVector(), e.model.parameterVector());
  EXPECT_EQ(r.summary.loss, e.summary.loss);
  EXPECT_EQ(r.fitValidation().value(),
            fitPercent(p.y, simulate(e.model, p.u), static_cast<Eigen::Index>(p.validation.begin),
                       static_cast<Eigen::Index>(p.validation.end)));
  ASSERT_EQ(r.parameters.size(), 8u);
  EXPECT_NEAR(r.parameters[0].upper - r.parameters[0].value, 2.5758 * r.parameters[0].std, 1e-3 * r.parameters[0].std);
  EXPECT_TRUE(r.warned(FitWarning::ClosedLoopBias)) << "an OE model of closed-loop data is biased";

  o.model.kind = FitModelKind::Spa;
  o.responsePoints = 100;
  const FitResult s = fitModel(o);
  ASSERT_TRUE(s.ok()) << s.message;
  SpaOptions so;
  so.omega = fitFrequencyGrid(p, 100);
  const NonparametricEstimate direct = spa(p.estimationInput(), p.estimationOutput(), p.sampleTime, so);
  EXPECT_EQ(s.response.magnitude, direct.response.magnitude);
  EXPECT_TRUE(s.nonparametric.closedLoopBias);
}

// Validation on another log: simulated from that log's first sample, with the estimation
// data's means removed (the model's operating point).
TEST(Fit, ValidationOnAnotherLogUsesTheEstimationMeans) {
  const auto est = twoMassLog(6.0, 25, true), val = twoMassLog(4.0, 26, true);
  FitOptions o = physicalFit(est);
  o.closedLoop = ClosedLoopChoice::Direct;
  o.validation = {{val, std::nullopt}, {est, SecondsRange{4.0, 6.0}}};
  const FitResult r = fitModel(o);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.validation.size(), 2u);
  const PreparedData& v = r.validation[0].data;
  EXPECT_EQ(v.validation, (SampleRange{0, val->samples()}));
  EXPECT_EQ(v.inputMean, r.data.inputMean);
  EXPECT_NEAR(v.u[10] + r.data.inputMean, val->input()->values[10], 1e-12);
  ASSERT_TRUE(r.validation[0].fitPercent.has_value());
  EXPECT_GT(*r.validation[0].fitPercent, 80.0);
  EXPECT_EQ(r.validation[1].data.validation.begin, 8000u);
  EXPECT_EQ(r.fitValidation(), r.validation[0].fitPercent);
}

TEST(Fit, DataFailuresAreSentencesAndMisuseThrows) {
  const auto log = twoMassLog(2.0, 27);
  auto flat = std::make_shared<IdData>(*log);
  std::fill(flat->channel(columns::kTorqueRef)->values.begin(), flat->channel(columns::kTorqueRef)->values.end(), 0.3);
  // Dead data are refused by the data preparation, as bad data naming the channel.
  FitResult r = fitModel(physicalFit(flat));
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_EQ(r.status, FitStatus::BadData);
  EXPECT_NE(r.message.find("the channel torque_ref_nm carries no signal: it is constant (every sample is 0.3)"),
            std::string::npos)
      << r.message;
  r = fitModel(physicalFit(log, SecondsRange{5.0, 9.0}));
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_EQ(r.status, FitStatus::BadData) << r.message;

  FitOptions o = physicalFit(log);
  o.decimation = 4;
  o.closedLoop = ClosedLoopChoice::Indirect;
  EXPECT_EQ(o.check().issue, FitIssue::IndirectExcludesDecimation) << o.check().message;
  EXPECT_THROW(fitModel(o), std::invalid_argument);
  o = physicalFit(log);
  o.estimation.push_back(o.estimation.front());  // several experiments take the direct fit only
  o.closedLoop = ClosedLoopChoice::Indirect;
  EXPECT_THROW(fitModel(o), std::invalid_argument);
  o = physicalFit(nullptr);
  EXPECT_EQ(o.check().issue, FitIssue::NoData);
  EXPECT_TRUE(o.checkExceptData().ok()) << o.checkExceptData().message;

  // Abort from the progress callback ends the fit as cancelled.
  const FitResult c = fitModel(physicalFit(log), [](double, const std::string&) { return ProgressAction::Abort; });
  EXPECT_EQ(c.termination, Termination::Cancelled) << c.message;
  EXPECT_EQ(c.status, FitStatus::Cancelled);
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

// Issue 14: SPA's default lag window is chosen from the data. On a 2 kHz two-mass log (20 s,
// the chirp of Section 5.1, PRBS) SITB's 30 lags span 15 ms and the estimate ripples every
// 2 pi / (30 T) = 419 rad/s with peaks far above the resonance; the default (1 s of lags, and
// frequencies where the input has almost no power left out) draws none above it, finds the
// notch of the truth, and says which window it used and why.
TEST(FitPipeline, SpaDefaultWindowDrawsNoSpuriousPeaksAt2kHz) {
  const NotchesPeaks truth = notchesAndPeaks(makeModel("two-mass")->stateSpace());
  ASSERT_EQ(truth.peaks.size(), 1u);
  ASSERT_EQ(truth.notches.size(), 1u);
  for (ExcitationKind kind : {ExcitationKind::Chirp, ExcitationKind::Prbs}) {
    SimulationOptions so;
    so.durationS = 20.0;
    so.seed = 3;
    so.excitation.kind = kind;
    const SimulationResult sim = simulateClosedLoop(*makeModel("two-mass"), {}, so);
    ASSERT_EQ(sim.termination, Termination::Converged) << sim.message;
    FitOptions o;
    o.model.kind = FitModelKind::Spa;
    o.estimation = {{std::make_shared<IdData>(sim.data), std::nullopt}};
    const FitResult r = fitModel(o);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.nonparametric.window, 2000);  // 1 s at 2 kHz, below N/10 = 4000
    EXPECT_NE(r.summary.message.find("chosen from the data: 1 s at 2000 Hz"), std::string::npos)
        << r.summary.message;
    for (double w : r.peaks)
      EXPECT_LT(w, 1.3 * truth.peaks[0]) << toString(kind) << ": a peak at " << w << " rad/s";
    ASSERT_FALSE(r.notches.empty()) << toString(kind);
    EXPECT_NEAR(r.notches.front() / truth.notches[0], 1.0, 0.05) << toString(kind);
    if (kind != ExcitationKind::Prbs) continue;
    // SITB's 30 lags on the PRBS log: a peak far above the resonance (406 rad/s), where the
    // estimate ripples every 419 rad/s.
    o.model.windowWidth = 30;
    const FitResult sitb = fitModel(o);
    ASSERT_TRUE(sitb.ok()) << sitb.message;
    EXPECT_TRUE(std::any_of(sitb.peaks.begin(), sitb.peaks.end(),
                            [&](double w) { return w > 1.3 * truth.peaks[0]; }));
  }
}

}  // namespace
}  // namespace flexarm
