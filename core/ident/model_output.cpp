#include "core/ident/model_output.h"

#include <cmath>
#include <cstdio>

#include "core/ident/fit.h"
#include "core/ident/nonlinear_pem.h"
#include "core/ident/pem.h"
#include "core/models/nonlinear_plant.h"

namespace flexarm {

bool FitBasis::operator==(const FitBasis& o) const {
  return horizon == o.horizon && observerHz == o.observerHz && start == o.start && effects == o.effects &&
         meansRemoved == o.meansRemoved && rateHz == o.rateHz && data == o.data && range == o.range;
}

namespace {
std::string shortNumber(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}
}  // namespace

std::string fitKindText(const FitBasis& b) {
  if (b.observerHz > 0.0) return "one-step prediction through the " + shortNumber(b.observerHz) + " Hz load observer";
  if (b.horizon > 0) return std::to_string(b.horizon) + "-step prediction";
  return "simulation";
}

std::string fitBasisText(const FitBasis& b) {
  std::string s = fitKindText(b);
  if (b.isSimulation()) s += " (open loop from the input)";
  s += b.start == FitStart::LogStart ? " from the log's first sample" : " from the range's first sample";
  if (b.effects) s += ", with the model's effects";
  s += b.meansRemoved ? ", means removed" : ", means kept";
  if (b.rateHz > 0.0) s += ", at " + shortNumber(b.rateHz) + " Hz";
  if (!b.data.empty() || !b.range.empty()) {
    s += ", on";
    if (!b.data.empty()) s += " " + b.data;
    if (!b.range.empty()) s += " " + b.range;
  }
  return s;
}

std::string samplesLabel(const std::string& kind, const PreparedData& d, SampleRange range) {
  if (range.empty()) return kind;
  return kind + " " + shortNumber(d.timeAt(range.begin)) + "-" + shortNumber(d.timeAt(range.end - 1)) + " s";
}

bool EvaluatedModel::isValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!physical == !polynomial) return fail("a model is either physical or a black-box estimate");
  if (polynomial && !effects.empty()) return fail("a black-box estimate carries no effects");
  if (decimation < 1) return fail("the decimation must be at least 1");
  if (!(smoothingSpeed >= 0.0) || !std::isfinite(smoothingSpeed))
    return fail("the smoothing speed must be a finite number >= 0");
  return true;
}

int decimationFor(const EvaluatedModel& m, double dataSampleTime) {
  if (!(dataSampleTime > 0.0)) return 1;
  if (m.physical || !m.polynomial) return std::max(1, m.decimation);
  const double ratio = m.polynomial->sampleTime / dataSampleTime;
  const long k = std::lround(ratio);
  return k >= 1 && std::abs(ratio - static_cast<double>(k)) < 1e-6 * ratio ? static_cast<int>(k) : 0;
}

bool wantsVelocity(const EvaluatedModel& m) {
  return !m.physical || m.physical->options().output == ModelOutput::MotorVelocity;
}

FitDataOptions modelDataOptions(const EvaluatedModel& m, int decimation, const std::optional<SecondsRange>& estimation,
                                const std::optional<SecondsRange>& validation) {
  FitDataOptions o;
  o.decimation = std::max(1, decimation);
  o.velocityOutput = wantsVelocity(m);
  if (m.physical) o.decimatedInput = FitDataOptions::DecimatedInput::HeldMean;
  o.removeMeans = !m.nonlinear();
  o.estimation = estimation;
  o.validation = validation;
  o.minimumSamples = 2;
  return o;
}

double fitObserverHz(const EvaluatedModel& m, const PreparedData& d) {
  return m.nonlinear() && d.closedLoop && !m.armOutput ? kClosedLoopObserverHz : 0.0;
}

namespace {

bool angleOutput(const EvaluatedModel& m) { return m.physical && m.physical->options().output == ModelOutput::MotorAngle; }

// The first sample the model's output is formed from.
std::size_t firstSample(FitStart start, SampleRange range) { return start == FitStart::LogStart ? 0 : range.begin; }

ModelSignal failed(std::string message, SignalFailure failure = SignalFailure::Failed) {
  ModelSignal out;
  out.message = std::move(message);
  out.failure = failure;
  return out;
}

// How far a model's output may leave the scale of what it is compared with before it counts
// as diverged: an unstable G grows without bound (1e84 on a 10 s log), and a fit % of such a
// number says nothing.
constexpr double kDivergedScale = 1e6;

// The tail of y (formed from sample `from`) that covers range; diverged when it is not finite
// or, given the measured signal over the range, when it leaves its scale by kDivergedScale.
ModelSignal over(const Eigen::VectorXd& y, std::size_t from, SampleRange range, const Eigen::VectorXd* measured = nullptr) {
  const auto b = static_cast<Eigen::Index>(range.begin - from), n = static_cast<Eigen::Index>(range.size());
  if (y.size() < b + n) return failed("the simulation did not cover the range");
  ModelSignal out;
  out.y = y.segment(b, n);
  if (!out.y.allFinite()) return failed("the simulated output diverges (an unstable model)", SignalFailure::Diverged);
  if (measured && measured->size() > 0 && n > 0) {
    const double scale = measured->cwiseAbs().maxCoeff();
    if (scale > 0.0 && out.y.cwiseAbs().maxCoeff() > kDivergedScale * scale)
      return failed("the simulated output diverges (an unstable model: it grows to more than 1e6 times the "
                    "measured output)",
                    SignalFailure::Diverged);
  }
  return out;
}

// The nonlinear plant's output of a physical model with effects (nonlinear_pem.h): simulation
// from the torque alone, or the observer's prediction, which also starts every sample from
// the measured motor angle as the fit's predictor does.
ModelSignal nonlinearOutput(const EvaluatedModel& m, const PreparedData& d, SampleRange span, double observerHz) {
  NonlinearSeries s = nonlinearSeries(d, span, angleOutput(m));
  if (!(observerHz > 0.0) || m.armOutput) s.resetAngle = false;
  NonlinearPemOptions o;
  o.smoothingSpeed = m.smoothingSpeed;
  o.observerBandwidthHz = observerHz;
  // A velocity differentiated from the angle at the log's rate is compared with the predicted
  // angle through the same central differences; a logged one, or one decimated behind the
  // anti-alias filter, with the velocity state (as the nonlinear fit compares them).
  o.output = angleOutput(m) ? PredictedOutput::MotorAngle
             : d.differentiated && d.decimation == 1 && d.angle.size() == d.u.size()
                 ? PredictedOutput::DifferentiatedAngle
                 : PredictedOutput::MotorVelocity;
  ModelSignal out;
  try {
    out.y = simulateNonlinear(*m.physical, m.effects, s, o);
  } catch (const std::invalid_argument& e) {
    return failed(std::string("the simulation failed: ") + e.what());
  }
  if (out.y.size() == 0) return failed("the simulated output diverges", SignalFailure::Diverged);
  return out;
}

}  // namespace

ModelSignal modelOutput(const EvaluatedModel& m, const PreparedData& d, SampleRange range, const FitBasis& basis) {
  std::string why;
  if (!m.isValid(&why)) throw std::invalid_argument("modelOutput: " + why);
  if (range.empty() || range.end > static_cast<std::size_t>(d.u.size()))
    throw std::invalid_argument("modelOutput: the range lies outside the data");
  const std::size_t from = firstSample(basis.start, range);
  const SampleRange span{from, range.end};
  const auto b = static_cast<Eigen::Index>(span.begin), n = static_cast<Eigen::Index>(span.size());
  const Eigen::VectorXd measured = d.y.segment(static_cast<Eigen::Index>(range.begin), static_cast<Eigen::Index>(range.size()));
  if (m.polynomial) {
    const PolynomialModel& p = *m.polynomial;
    if (std::abs(p.sampleTime - d.sampleTime) > 1e-9 * d.sampleTime)
      return failed("estimated at " + std::to_string(p.sampleTime) + " s, the data are sampled every " +
                        std::to_string(d.sampleTime) + " s",
                    SignalFailure::RateMismatch);
    const Eigen::VectorXd u = d.u.segment(b, n);
    return over(basis.horizon > 0 ? predict(p, u, d.y.segment(b, n), basis.horizon) : simulate(p, u), from, range,
                &measured);
  }
  if (m.nonlinear()) {
    ModelSignal out = nonlinearOutput(m, d, span, basis.observerHz);
    return out.ok() ? over(out.y, from, range, &measured) : out;
  }
  // A linear physical model is an output-error model (K = 0): its k-step predictor is its
  // simulation.
  return over(simulate(*m.physical, d.u.segment(b, n), d.sampleTime), from, range, &measured);
}

ModelFit modelFit(const EvaluatedModel& m, const PreparedData& d, SampleRange range, FitBasis basis) {
  if (!m.nonlinear()) basis.observerHz = 0.0;
  basis.effects = m.nonlinear();
  basis.meansRemoved = d.inputMean != 0.0 || d.outputMean != 0.0;
  basis.rateHz = 1.0 / d.sampleTime;
  ModelFit f;
  f.output = modelOutput(m, d, range, basis);
  if (!f.output.ok() || range.size() < 2) return f;
  const auto b = static_cast<Eigen::Index>(range.begin), n = static_cast<Eigen::Index>(range.size());
  const Eigen::VectorXd y = d.y.segment(b, n);
  f.squaredErrors = (y - f.output.y).squaredNorm();
  f.squaredDeviations = (y.array() - y.mean()).square().sum();
  f.figure = FitFigure{fitPercentsFromSums(f.squaredErrors, f.squaredDeviations), basis};
  return f;
}

ModelSignal residualsOf(const EvaluatedModel& m, const PreparedData& d) {
  if (m.polynomial) {
    if (std::abs(m.polynomial->sampleTime - d.sampleTime) > 1e-9 * d.sampleTime)
      return failed("estimated at another sample time than the data's", SignalFailure::RateMismatch);
    ModelSignal out;
    out.y = predictionErrors(*m.polynomial, d.u, d.y);
    return out;
  }
  const SampleRange whole{0, static_cast<std::size_t>(d.u.size())};
  if (m.nonlinear()) {
    ModelSignal out = modelOutput(m, d, whole, FitBasis{});
    if (out.ok()) out.y = d.y - out.y;
    return out;
  }
  ModelSignal out;
  out.y = predictionErrors(*m.physical, Eigen::VectorXd(), d.u, d.y, d.sampleTime);
  if (!out.y.allFinite()) return failed("the simulated output diverges (an unstable model)", SignalFailure::Diverged);
  return out;
}

ModelSignal predictedDeflection(const EvaluatedModel& m, const PreparedData& d, SampleRange range, FitStart start) {
  if (!m.physical) return failed("a black-box estimate predicts no deflection");
  const std::size_t from = firstSample(start, range);
  const SampleRange span{from, range.end};
  auto linear = std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(m.physical->clone().release()));
  linear->setOptions(ModelOptions{});
  if (!m.nonlinear()) {
    const Eigen::VectorXd y = simulateDeflection(*linear, d.u.segment(static_cast<Eigen::Index>(span.begin),
                                                                      static_cast<Eigen::Index>(span.size())),
                                                 d.sampleTime);
    return over(y, from, range);
  }
  NonlinearPlant plant(*linear, m.effects);
  if (m.smoothingSpeed > 0.0) plant.setSmoothingSpeed(m.smoothingSpeed);
  NonlinearSeries s = nonlinearSeries(d, span, angleOutput(m));
  s.resetAngle = false;  // from the torque alone: no measured angle in the arm's gravity torque
  std::vector<double> yhat, arm;
  if (!predictOutput(plant, s, defaultSubsteps(s.Ts), {}, PredictedOutput::MotorVelocity, yhat, nullptr, &arm))
    return failed("the predicted deflection diverges", SignalFailure::Diverged);
  return over(Eigen::Map<const Eigen::VectorXd>(arm.data(), static_cast<Eigen::Index>(arm.size())), from, range);
}

std::optional<DeflectionFit> deflectionFit(const EvaluatedModel& m, const PreparedData& d, SampleRange range,
                                           FitStart start, double gearRatio, std::string* why) {
  auto fail = [why](std::string text) -> std::optional<DeflectionFit> {
    if (why) *why = std::move(text);
    return std::nullopt;
  };
  const Eigen::VectorXd measured = measuredDeflection(d, gearRatio);
  if (measured.size() == 0) return fail("the log has no motor and arm-side encoder pair");
  if (range.size() < 2) return fail("the range holds fewer than two samples");
  const ModelSignal p = predictedDeflection(m, d, range, start);
  if (!p.ok()) return fail(p.message);
  const auto b = static_cast<Eigen::Index>(range.begin), n = static_cast<Eigen::Index>(range.size());
  DeflectionFit f;
  f.gearRatio = gearRatio;
  f.measured = measured.segment(b, n).array() - measured.segment(b, n).mean();
  f.predicted = p.y.array() - p.y.mean();
  const Eigen::VectorXd e = f.measured - f.predicted;
  f.rmsError = std::sqrt(e.squaredNorm() / static_cast<double>(n));
  f.measuredRms = std::sqrt(f.measured.squaredNorm() / static_cast<double>(n));
  f.figure.percent = fitPercents(f.measured, f.predicted);
  f.figure.basis.start = start;
  f.figure.basis.effects = m.nonlinear();
  f.figure.basis.meansRemoved = true;  // each about its own mean over the range
  f.figure.basis.rateHz = 1.0 / d.sampleTime;
  return f;
}

}  // namespace flexarm
