// The fit pipeline's data preparation (Sections 5.1-5.2): channels, the motor velocity from
// the angle, decimation, ranges in seconds and the estimation means, against the same steps
// done one by one with the preprocessing functions.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ident/fit_data.h"
#include "core/signal/preprocess.h"

namespace flexarm {
namespace {

// 2 kHz, 4 s: torque, measured angle, reference with non-zero means.
IdData makeLog() {
  IdData d;
  d.sampleTime = 0.0005;
  d.startTime = 1.0;
  const std::size_t n = 8000;
  std::vector<double> u(n), a(n), r(n), extra(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = d.startTime + static_cast<double>(i) * d.sampleTime;
    u[i] = 0.3 + std::sin(7.0 * t) + 0.2 * std::sin(90.0 * t * t);
    a[i] = 2.0 + 0.1 * std::cos(3.0 * t) + 0.01 * std::sin(40.0 * t);
    r[i] = 2.0 + 0.1 * std::cos(3.0 * t);
    extra[i] = static_cast<double>(i);
  }
  d.setChannel({columns::kMotorAngle, "rad", ChannelRole::Output, a});
  d.setChannel({columns::kTorqueRef, "N m", ChannelRole::Input, u});
  d.setChannel({columns::kAngleRef, "rad", ChannelRole::Reference, r});
  d.setChannel({"counter", "", ChannelRole::None, extra});
  return d;
}

Eigen::VectorXd vec(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

TEST(FitData, VelocityDecimationRangesAndMeansMatchTheStepsDoneOneByOne) {
  const IdData log = makeLog();
  FitDataOptions o;
  o.velocityOutput = true;
  o.decimation = 10;
  o.estimation = SecondsRange{1.5, 3.0};
  o.validation = SecondsRange{3.0, 4.5};
  const PreparedData p = prepareFitData(log, o);
  ASSERT_TRUE(p.ok()) << p.message;

  DecimateOptions dec;
  dec.factor = 10;
  const IdData ref = decimate(addDerivative(log), dec);
  EXPECT_DOUBLE_EQ(p.sampleTime, 0.005);
  EXPECT_DOUBLE_EQ(p.startTime, 1.0);
  EXPECT_EQ(p.outputName, columns::kMotorVelocity);
  EXPECT_TRUE(p.differentiated);
  EXPECT_TRUE(p.closedLoop);
  // 1.5 s to 3.0 s at 200 Hz from t0 = 1 s: samples 100..400.
  EXPECT_EQ(p.estimation.begin, 100u);
  EXPECT_EQ(p.estimation.end, 401u);
  EXPECT_EQ(p.validation.begin, 400u);
  EXPECT_EQ(p.validation.end, 701u);
  const Eigen::VectorXd u = vec(ref.input()->values), y = vec(ref.output()->values);
  const Eigen::VectorXd r = vec(ref.withRole(ChannelRole::Reference)->values);
  const Eigen::VectorXd a = vec(ref.channel(columns::kMotorAngle)->values);
  ASSERT_EQ(p.u.size(), u.size());
  const double uMean = u.segment(100, 301).mean(), yMean = y.segment(100, 301).mean();
  const double rMean = r.segment(100, 301).mean();
  EXPECT_NEAR(p.inputMean, uMean, 1e-14);
  EXPECT_NEAR(p.outputMean, yMean, 1e-14);
  EXPECT_NEAR(p.referenceMean, rMean, 1e-14);
  EXPECT_LT((p.u - (u.array() - uMean).matrix()).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((p.y - (y.array() - yMean).matrix()).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((p.r - (r.array() - rMean).matrix()).cwiseAbs().maxCoeff(), 1e-13);
  // The angle keeps its mean: the controller sees it as logged.
  EXPECT_LT((p.angle - a).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(p.estimationInput().mean(), 0.0, 1e-12);
  EXPECT_EQ(p.estimationOutput().size(), 301);
  EXPECT_EQ(p.steps.size(), 3u) << p.note();
}

// Decimated, a held input is the mean over each new sample period (what a zero-order hold of
// that period must hold), while the output stays the FIR's.
TEST(FitData, HeldMeanInputIsTheMeanOverEachHeldPeriod) {
  const IdData log = makeLog();
  FitDataOptions o;
  o.decimation = 10;
  o.removeMeans = false;
  const PreparedData filtered = prepareFitData(log, o);
  o.decimatedInput = FitDataOptions::DecimatedInput::HeldMean;
  const PreparedData held = prepareFitData(log, o);
  ASSERT_TRUE(held.ok()) << held.message;
  ASSERT_EQ(held.u.size(), 800);
  const auto& u = log.input()->values;
  for (Eigen::Index k : {0, 1, 399, 799}) {
    double sum = 0.0;
    for (int j = 0; j < 10; ++j) sum += u[static_cast<std::size_t>(10 * k + j)];
    EXPECT_NEAR(held.u[k], sum / 10.0, 1e-14) << k;
  }
  EXPECT_GT((held.u - filtered.u).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(held.y, filtered.y);
  EXPECT_NE(held.note().find("mean over each held period"), std::string::npos) << held.note();
}

TEST(FitData, UnsetRangesMeanEverythingAndNoValidationAndMeansCanStay) {
  IdData log = makeLog();
  // A range the log stores is not used unless it is passed.
  log.estimationRange = SampleRange{1000, 5000};
  log.validationRange = SampleRange{5000, 8000};
  FitDataOptions o;
  o.removeMeans = false;
  PreparedData p = prepareFitData(log, o);
  ASSERT_TRUE(p.ok()) << p.message;
  EXPECT_EQ(p.estimation, (SampleRange{0, 8000}));
  EXPECT_TRUE(p.validation.empty());
  EXPECT_EQ(p.outputName, columns::kMotorAngle);  // no velocity asked
  EXPECT_FALSE(p.differentiated);
  EXPECT_EQ(p.inputMean, 0.0);
  EXPECT_DOUBLE_EQ(p.u[17], log.input()->values[17]);
  // A stored range passed in seconds gives back its samples.
  o.estimation = secondsOf(log, *log.estimationRange);
  o.validation = secondsOf(log, *log.validationRange);
  p = prepareFitData(log, o);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p.estimation, (SampleRange{1000, 5000}));
  EXPECT_EQ(p.validation, (SampleRange{5000, 8000}));
  o.estimation = SecondsRange{2.0, 2.5};
  p = prepareFitData(log, o);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p.estimation, (SampleRange{2000, 3001}));
}

TEST(FitData, ChannelsByName) {
  const IdData log = makeLog();
  FitDataOptions o;
  o.input = columns::kAngleRef;
  o.output = "counter";
  const PreparedData p = prepareFitData(log, o);
  ASSERT_TRUE(p.ok()) << p.message;
  EXPECT_EQ(p.inputName, columns::kAngleRef);
  EXPECT_EQ(p.outputName, "counter");
  EXPECT_NEAR(p.y[1] - p.y[0], 1.0, 1e-12);
}

TEST(FitData, DataFailuresAreSentencesAndMisuseThrows) {
  const IdData log = makeLog();
  FitDataOptions o;
  o.estimation = SecondsRange{10.0, 12.0};
  PreparedData p = prepareFitData(log, o);
  EXPECT_FALSE(p.ok());
  EXPECT_NE(p.message.find("estimation range 10-12 s holds no samples of the log (1-4.9995 s)"),
            std::string::npos)
      << p.message;
  o.estimation = SecondsRange{1.0, 1.004};
  p = prepareFitData(log, o);
  EXPECT_FALSE(p.ok());
  EXPECT_NE(p.message.find("holds only 9 samples (20 needed)"), std::string::npos) << p.message;
  o = FitDataOptions{};
  o.output = "nonexistent";
  p = prepareFitData(log, o);
  EXPECT_FALSE(p.ok());
  EXPECT_NE(p.message.find("no channel 'nonexistent' for the output"), std::string::npos) << p.message;
  IdData noInput = makeLog();
  noInput.channel(columns::kTorqueRef)->role = ChannelRole::None;
  p = prepareFitData(noInput, FitDataOptions{});
  EXPECT_FALSE(p.ok());
  EXPECT_EQ(p.message, "the log has no input channel");

  o = FitDataOptions{};
  o.decimation = 0;
  EXPECT_THROW(prepareFitData(log, o), std::invalid_argument);
  o = FitDataOptions{};
  o.validation = SecondsRange{3.0, 2.0};
  std::string why;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("validation range"), std::string::npos);
  EXPECT_THROW(prepareFitData(log, o), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
