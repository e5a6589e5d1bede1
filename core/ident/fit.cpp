#include "core/ident/fit.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/common/text.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit_internal.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

const char* toString(FitModelKind k) {
  switch (k) {
    case FitModelKind::Physical: return "physical";
    case FitModelKind::BlackBox: return "black-box";
    case FitModelKind::Spa: return "spa";
    case FitModelKind::Etfe: return "etfe";
  }
  return "black-box";
}

std::optional<FitModelKind> fitModelKindFromString(std::string_view s) {
  for (auto k : {FitModelKind::Physical, FitModelKind::BlackBox, FitModelKind::Spa, FitModelKind::Etfe})
    if (s == toString(k)) return k;
  return std::nullopt;
}

const char* toString(ClosedLoopChoice c) {
  switch (c) {
    case ClosedLoopChoice::Auto: return "auto";
    case ClosedLoopChoice::Direct: return "direct";
    case ClosedLoopChoice::TwoStage: return "two-stage";
    case ClosedLoopChoice::Indirect: return "indirect";
  }
  return "auto";
}

std::optional<ClosedLoopChoice> closedLoopChoiceFromString(std::string_view s) {
  for (auto c : {ClosedLoopChoice::Auto, ClosedLoopChoice::Direct, ClosedLoopChoice::TwoStage,
                 ClosedLoopChoice::Indirect})
    if (s == toString(c)) return c;
  return std::nullopt;
}

const char* describe(ClosedLoopChoice c) {
  switch (c) {
    case ClosedLoopChoice::Auto:
      return "the indirect fit when the log is undecimated and its controller explains the torque, else the "
             "two-stage fit on a log with a reference, the direct fit without one; it says which and why";
    case ClosedLoopChoice::Direct:
      return "output error to the logged input, which the noise fed back biases in closed loop (4.43)";
    case ClosedLoopChoice::TwoStage:
      return "output error to the part of the input the reference explains (an FIR of the reference), "
             "consistent in closed loop";
    case ClosedLoopChoice::Indirect:
      return "the log's controller closed around the model, the loop fitted from the reference to the measured "
             "motor angle at the log's own rate";
  }
  return "";
}

namespace {

FitCheck refuse(FitIssue issue, std::string message) { return {issue, std::move(message)}; }

// The rules of a model spec (FitModelSpec::isValid and FitOptions::check).
FitCheck checkSpec(const FitModelSpec& m) {
  using I = FitIssue;
  switch (m.kind) {
    case FitModelKind::Physical: {
      if (!m.start) return refuse(I::NoStartModel, "a physical fit needs its start model");
      bool anyFree = false;
      for (const auto& p : m.start->parameters()) anyFree = anyFree || p.free;
      std::vector<bool> seen(allEffectKinds().size(), false);
      for (const auto& f : m.effects) {
        std::string reason;
        if (!f.effect.isValid(&reason)) return refuse(I::InvalidEffect, reason);
        const std::string name = toString(f.effect.kind);
        const EffectDefinition& d = effectDefinition(f.effect);
        if (d.structural())
          return refuse(I::EffectChangesStructure, name + " changes the structure; fit the larger structure instead");
        if (seen[static_cast<std::size_t>(f.effect.kind)])
          return refuse(I::EffectTwice, "the effect " + name + " is given twice");
        seen[static_cast<std::size_t>(f.effect.kind)] = true;
        if (d.needsGearSpring() &&
            (m.start->topology().gearStiffness.empty() || m.start->structureName() == "two-mass-theta"))
          return refuse(I::EffectNeedsGearSpring, name + " needs a model with a gear spring (two-mass, three-mass "
                                                         "or four-mass), not " + m.start->structureName());
        for (std::size_t k = 0; k < f.effect.values.size(); ++k) anyFree = anyFree || f.isFree(k);
      }
      for (const auto& f : m.effects)
        if (effectDefinition(f.effect).needsArmEncoder() && !m.armOutput)
          return refuse(I::EncoderSkewNeedsArm, std::string(toString(f.effect.kind)) +
                                                    " changes what the arm encoder reads: it goes with the arm as an "
                                                    "output (--outputs motor,arm)");
      if (m.armOutput && m.start->options().output != ModelOutput::MotorVelocity)
        return refuse(I::ArmOutputNeedsVelocity, "the arm as a second output goes with the motor velocity as the first");
      if (!m.effects.empty() && m.start->options().armAcceleration)
        return refuse(I::EffectsTakeOneOutput, "a fit with effects takes one output (the motor velocity or angle), "
                                               "not the arm acceleration");
      if (!anyFree) return refuse(I::NoFreeParameter, "a physical fit needs at least one free parameter");
      return {};
    }
    case FitModelKind::BlackBox: {
      std::string reason;
      if (!m.orders.isValid(&reason)) return refuse(I::InvalidOrders, "orders: " + reason);
      break;
    }
    case FitModelKind::Spa:
    case FitModelKind::Etfe:
      if (m.windowWidth < 0) return refuse(I::InvalidWindow, "the window width cannot be negative");
      break;
  }
  if (!m.effects.empty() || m.armOutput)
    return refuse(I::PhysicalOnly, "effects and the arm as an output apply to physical models only");
  return {};
}

}  // namespace

bool FitModelSpec::isValid(std::string* why) const {
  const FitCheck c = checkSpec(*this);
  if (why) *why = c.message;
  return c.ok();
}

std::string FitModelSpec::name() const {
  switch (kind) {
    case FitModelKind::Physical: {
      std::string n = start ? start->structureName() : "physical";
      for (const auto& f : effects) n += std::string(" + ") + toString(f.effect.kind);
      if (armOutput) n += " (motor and arm)";
      return n;
    }
    case FitModelKind::BlackBox: return PolynomialModel::zero(structure, orders, 1.0).name();
    case FitModelKind::Spa: return "spa";
    case FitModelKind::Etfe: return "etfe";
  }
  return "";
}

bool FitModelSpec::wantsVelocity() const {
  return kind != FitModelKind::Physical || !start || start->options().output == ModelOutput::MotorVelocity;
}

FitCheck FitOptions::checkExceptData() const {
  using I = FitIssue;
  if (FitCheck c = checkSpec(model); !c.ok()) return c;
  const bool physical = model.kind == FitModelKind::Physical;
  if (estimation.empty()) return refuse(I::NoEstimationData, "the fit needs an estimation experiment");
  if (estimation.size() > 1) {
    if (model.kind == FitModelKind::Spa || model.kind == FitModelKind::Etfe)
      return refuse(I::OneExperimentOnly, std::string(toString(model.kind)) + " takes one estimation experiment");
    if (physical && (closedLoop == ClosedLoopChoice::TwoStage || closedLoop == ClosedLoopChoice::Indirect))
      return refuse(I::OneExperimentOnly, std::string("the ") + toString(closedLoop) +
                                              " closed-loop fit takes one estimation experiment; several take "
                                              "the direct fit");
  }
  for (const auto* list : {&estimation, &validation})
    for (const auto& e : *list)
      if (e.range && !(e.range->start < e.range->end)) return refuse(I::EmptyRange, "a range must have start < end");
  if (decimation < 1) return refuse(I::OutOfRange, "the decimation factor must be at least 1");
  if (maxIterations < 1) return refuse(I::OutOfRange, "at least one iteration is needed");
  if (randomStarts < 0) return refuse(I::OutOfRange, "the number of random starts cannot be negative");
  if (!(level > 0.0 && level < 1.0)) return refuse(I::OutOfRange, "the level must lie strictly between 0 and 1");
  if (responsePoints < 2) return refuse(I::OutOfRange, "the frequency response needs at least two points");
  if (!(notchDepthDb >= 0.0)) return refuse(I::OutOfRange, "the notch depth cannot be negative");
  if (method != FitMethod::PredictionError) {
    const std::string name = std::string("the ") + toString(method) + " method ";
    if (!physical)
      return refuse(I::MethodNeedsPhysical, name + "estimates a physical model's rigid part; give a physical model");
    if (!model.effects.empty())
      return refuse(I::MethodExcludesEffects, name + "has its own friction model; it takes no effects");
    if (decimation > 1)
      return refuse(I::MethodExcludesDecimation, name + "filters and decimates the data itself; it excludes decimation");
    if (estimation.size() > 1) return refuse(I::OneExperimentOnly, name + "takes one estimation experiment");
    if (std::string why; !idim.isValid(&why)) return refuse(I::InvalidMethodOptions, why);
  }
  if (!physical) {
    if (!startValues.empty() || !bounds.empty())
      return refuse(I::PhysicalOnly, "start values and bounds apply to physical models only");
    if (noiseModel != NoiseModel::OutputError || randomStarts > 0 || closedLoop != ClosedLoopChoice::Auto)
      return refuse(I::PhysicalOnly, "the innovations form, random starts and a closed-loop method apply to "
                                     "physical models only");
    return {};
  }
  if (noiseModel == NoiseModel::Innovations && closedLoop != ClosedLoopChoice::Auto &&
      closedLoop != ClosedLoopChoice::Direct)
    return refuse(I::ExcludesInnovations, std::string("the ") + toString(closedLoop) +
                                              " closed-loop fit is output error; it excludes the innovations form");
  if (closedLoop == ClosedLoopChoice::Indirect && decimation > 1)
    return refuse(I::IndirectExcludesDecimation,
                  "the indirect closed-loop fit runs at the controller's rate; it excludes decimation");
  if (model.nonlinear() && noiseModel != NoiseModel::OutputError)
    return refuse(I::ExcludesInnovations, "a fit with effects is output error (5.7); it excludes the innovations form");
  if (model.nonlinear() && closedLoop != ClosedLoopChoice::Auto && closedLoop != ClosedLoopChoice::Direct)
    return refuse(I::EffectsNeedDirect, std::string("a fit with effects simulates the plant from the measured torque "
                                                    "(the direct fit); it excludes the ") +
                                            toString(closedLoop) + " closed-loop fit");
  if (std::string why; controller && !controller->isValid(&why)) return refuse(I::InvalidController, why);
  if (std::string why; !controllerIdent.isValid(&why)) return refuse(I::InvalidController, why);
  // Start values and bounds name the start model's parameters (an effect's values are its own).
  auto unknown = [this](const std::string& name, const char* what) {
    std::string names;
    for (const auto& p : model.start->parameters()) names += (names.empty() ? "" : ", ") + p.name;
    return refuse(I::UnknownParameter, "the " + model.start->structureName() + " model has no parameter '" + name +
                                           "'" + what + " (its parameters: " + names + ")");
  };
  for (const auto& v : startValues)
    if (model.start->indexOf(v.name) < 0) return unknown(v.name, "");
  for (const auto& b : bounds)
    if (model.start->indexOf(b.name) < 0) return unknown(b.name, " to bound");
  try {
    FitOptions dataless = *this;  // the log's own gear ratio is the data's business (fitModel)
    dataless.estimation.clear();
    const auto start = fitStartModel(dataless);
    bool anyFree = false;
    for (const auto& p : start->parameters()) anyFree = anyFree || p.free;
    if (!anyFree) return refuse(I::NoFreeParameter, "a physical fit needs at least one free parameter");
  } catch (const std::invalid_argument& e) {
    return refuse(I::OutsideBounds, e.what());
  }
  return {};
}

FitCheck FitOptions::check() const {
  if (FitCheck c = checkExceptData(); !c.ok()) return c;
  for (const auto* list : {&estimation, &validation})
    for (const auto& e : *list)
      if (!e.data) return refuse(FitIssue::NoData, "an experiment has no data");
  return {};
}

bool FitOptions::isValidExceptData(std::string* why) const {
  const FitCheck c = checkExceptData();
  if (why) *why = c.message;
  return c.ok();
}

bool FitOptions::isValid(std::string* why) const {
  const FitCheck c = check();
  if (why) *why = c.message;
  return c.ok();
}

const char* toString(FitIssue i) {
  switch (i) {
    case FitIssue::None: return "none";
    case FitIssue::NoStartModel: return "no-start-model";
    case FitIssue::NoFreeParameter: return "no-free-parameter";
    case FitIssue::InvalidEffect: return "invalid-effect";
    case FitIssue::EffectTwice: return "effect-twice";
    case FitIssue::EffectChangesStructure: return "effect-changes-structure";
    case FitIssue::EffectNeedsGearSpring: return "effect-needs-gear-spring";
    case FitIssue::EncoderSkewNeedsArm: return "encoder-skew-needs-arm";
    case FitIssue::ArmOutputNeedsVelocity: return "arm-output-needs-velocity";
    case FitIssue::EffectsTakeOneOutput: return "effects-take-one-output";
    case FitIssue::InvalidOrders: return "invalid-orders";
    case FitIssue::InvalidWindow: return "invalid-window";
    case FitIssue::NoEstimationData: return "no-estimation-data";
    case FitIssue::NoData: return "no-data";
    case FitIssue::OneExperimentOnly: return "one-experiment-only";
    case FitIssue::EmptyRange: return "empty-range";
    case FitIssue::OutOfRange: return "out-of-range";
    case FitIssue::MethodNeedsPhysical: return "method-needs-physical";
    case FitIssue::MethodExcludesEffects: return "method-excludes-effects";
    case FitIssue::MethodExcludesDecimation: return "method-excludes-decimation";
    case FitIssue::InvalidMethodOptions: return "invalid-method-options";
    case FitIssue::ExcludesInnovations: return "excludes-innovations";
    case FitIssue::IndirectExcludesDecimation: return "indirect-excludes-decimation";
    case FitIssue::EffectsNeedDirect: return "effects-need-direct";
    case FitIssue::InvalidController: return "invalid-controller";
    case FitIssue::UnknownParameter: return "unknown-parameter";
    case FitIssue::OutsideBounds: return "outside-bounds";
    case FitIssue::PhysicalOnly: return "physical-only";
  }
  return "none";
}

const char* toString(FitStatus s) {
  switch (s) {
    case FitStatus::Ok: return "ok";
    case FitStatus::BadRequest: return "bad-request";
    case FitStatus::BadData: return "bad-data";
    case FitStatus::Failed: return "failed";
    case FitStatus::Cancelled: return "cancelled";
  }
  return "failed";
}

const char* toString(FitWarning w) {
  switch (w) {
    case FitWarning::Other: return "other";
    case FitWarning::MaxIterations: return "max-iterations";
    case FitWarning::OnBound: return "on-bound";
    case FitWarning::SkippedStarts: return "skipped-starts";
    case FitWarning::Unstable: return "unstable";
    case FitWarning::ClosedLoopBias: return "closed-loop-bias";
    case FitWarning::ZeroOrderHold: return "zero-order-hold";
    case FitWarning::SmoothingSpeed: return "smoothing-speed";
    case FitWarning::LinearPartResponse: return "linear-part-response";
    case FitWarning::RandomStartsUnused: return "random-starts-unused";
    case FitWarning::DeflectionDiverges: return "deflection-diverges";
    case FitWarning::RepeatedExperiment: return "repeated-experiment";
  }
  return "other";
}

void FitResult::warn(FitWarning code, std::string text) {
  warningCodes.resize(warnings.size(), FitWarning::Other);  // any added without a code
  warnings.push_back(std::move(text));
  warningCodes.push_back(code);
}

FitWarning FitResult::warningCode(std::size_t i) const {
  return i < warningCodes.size() ? warningCodes[i] : FitWarning::Other;
}

bool FitResult::warned(FitWarning code) const {
  for (std::size_t i = 0; i < warnings.size(); ++i)
    if (warningCode(i) == code) return true;
  return false;
}

std::optional<double> FitResult::fitValidation() const {
  if (validation.empty()) return std::nullopt;
  return validation.front().fitPercent;
}

std::optional<double> FitResult::fitValidationNrmse() const {
  if (validation.empty()) return std::nullopt;
  return validation.front().fitPercentNrmse;
}

std::string FitResult::modelName() const {
  if (physical)
    return model.name() + (K.size() ? std::string(" (innovations form)") : std::string(" (K = 0)"));
  if (polynomial) return polynomial->name();
  return model.name();
}

std::vector<double> fitFrequencyGrid(const PreparedData& data, int points) {
  const double T = data.sampleTime;
  const double n = static_cast<double>(std::max<std::size_t>(2, data.estimation.size()));
  return logGrid(2.0 * M_PI / (n * T), M_PI / T, points);
}

FrequencyResponse fitResponse(const FitResult& r, const std::vector<double>& omega, double level) {
  const PreparedData& d = r.data;
  switch (r.model.kind) {
    case FitModelKind::Spa: {
      SpaOptions so;
      so.windowWidth = r.model.windowWidth;
      so.omega = omega;
      so.level = level;
      return spa(d.estimationInput(), d.estimationOutput(), d.sampleTime, so).response;
    }
    case FitModelKind::Etfe: {
      EtfeOptions eo;
      eo.smoothingWidth = r.model.windowWidth;
      eo.omega = omega;
      return etfe(d.estimationInput(), d.estimationOutput(), d.sampleTime, eo).response;
    }
    case FitModelKind::Physical:
    case FitModelKind::BlackBox:
      // Physical bands from the physical parameters only (K does not change G).
      return estimateResponse(r.physical.get(), r.covariance, r.freeIndices, r.polynomial.get(), omega, level);
  }
  return {};
}

FrequencyResponse estimateResponse(const PhysicalModel* physical, const Eigen::MatrixXd& covariance,
                                   const std::vector<int>& freeIndices, const PolynomialModel* polynomial,
                                   const std::vector<double>& omega, double level) {
  if (physical) return frequencyResponse(*physical, omega, covariance, freeIndices, level);
  if (!polynomial) return {};
  std::vector<double> below;  // a discrete response stops short of the Nyquist frequency
  for (double w : omega)
    if (w < M_PI / polynomial->sampleTime) below.push_back(w);
  if (below.empty()) return {};
  return frequencyResponse(*polynomial, below, level);
}

namespace fit_detail {

JoinedEstimation joinedEstimation(const FitResult& r) {
  JoinedEstimation j;
  Eigen::Index total = 0;
  for (const auto& e : r.estimation) total += static_cast<Eigen::Index>(e.data.estimation.size());
  j.u.resize(total);
  j.y.resize(total);
  Eigen::Index at = 0;
  for (const auto& e : r.estimation) {
    const auto n = static_cast<Eigen::Index>(e.data.estimation.size());
    j.u.segment(at, n) = e.data.estimationInput();
    j.y.segment(at, n) = e.data.estimationOutput();
    j.lengths.push_back(n);
    at += n;
  }
  if (j.lengths.size() == 1) j.lengths.clear();  // one experiment: the estimators' default
  return j;
}

}  // namespace fit_detail

namespace {

// Black-box structures (4.8) by prediction error (4.6), over every estimation experiment.
bool fitBlackBox(const FitOptions& o, FitResult& r, const ProgressCallback& progress) {
  PolyEstimateOptions po;
  po.maxIterations = o.maxIterations;
  const fit_detail::JoinedEstimation j = fit_detail::joinedEstimation(r);
  po.experimentLengths = j.lengths;
  po.closedLoop = r.data.closedLoop;
  PolyEstimate e = estimatePolynomial(j.u, j.y, o.model.structure, o.model.orders, r.data.sampleTime, po, progress);
  r.summary = e.summary;
  r.subspace = e.subspace;
  const auto names = e.model.parameterNames();
  const Eigen::VectorXd th = e.model.parameterVector(), sd = e.model.standardDeviations();
  const double z = twoSidedNormalQuantile(o.level);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const double s = sd.size() > k ? sd[k] : 0.0;
    r.parameters.push_back({names[i], "", th[k], s, th[k] - z * s, th[k] + z * s, true, "", true, {}});
  }
  r.polynomial = std::make_shared<PolynomialModel>(std::move(e.model));
  return true;
}

// SPA (4.28) or ETFE (4.24) of the estimation data on the default grid.
bool fitNonparametric(const FitOptions& o, FitResult& r) {
  const auto grid = fitFrequencyGrid(r.data, o.responsePoints);
  if (o.model.kind == FitModelKind::Spa) {
    SpaOptions so;
    so.windowWidth = o.model.windowWidth;
    so.omega = grid;
    so.level = o.level;
    r.nonparametric = spa(r.data.estimationInput(), r.data.estimationOutput(), r.data.sampleTime, so);
  } else {
    EtfeOptions eo;
    eo.smoothingWidth = o.model.windowWidth;
    eo.omega = grid;
    r.nonparametric = etfe(r.data.estimationInput(), r.data.estimationOutput(), r.data.sampleTime, eo);
  }
  if (r.data.closedLoop) {
    r.nonparametric.closedLoopBias = true;
    r.nonparametric.warning = kClosedLoopBiasWarning;
  }
  r.summary.termination = r.nonparametric.termination;
  r.summary.message = r.nonparametric.message;
  r.summary.seconds = r.nonparametric.seconds;
  return true;
}

// Every estimation experiment prepared on its own (its own range and means); r.data is the
// first. False with termination and message set when one cannot be used.
bool prepareEstimation(const FitOptions& o, const FitDataOptions& base, FitResult& r) {
  for (std::size_t i = 0; i < o.estimation.size(); ++i) {
    FitDataOptions eo = base;
    eo.estimation = o.estimation[i].range;
    FitValidation e;
    e.data = prepareFitData(*o.estimation[i].data, eo);
    const std::string which =
        o.estimation.size() > 1 ? "estimation experiment " + std::to_string(i + 1) + ": " : "";
    if (!e.data.ok()) {
      r.termination = Termination::Failed;
      r.message = which + e.data.message;
      return false;
    }
    if (i > 0 && std::abs(e.data.sampleTime - r.data.sampleTime) > 1e-9 * r.data.sampleTime) {
      r.termination = Termination::Failed;
      r.message = which + "its sample time differs from the first estimation experiment's";
      return false;
    }
    if (i == 0) r.data = e.data;
    r.estimation.push_back(std::move(e));
  }
  return true;
}

// Validation experiments prepared as the estimation data, with the means of the estimation
// experiment on the same log, else of the first.
bool prepareValidation(const FitOptions& o, const FitDataOptions& base, FitResult& r) {
  for (std::size_t i = 0; i < o.validation.size(); ++i) {
    const FitExperiment& e = o.validation[i];
    FitDataOptions vo = base;
    vo.estimation = e.range;
    vo.validation.reset();
    vo.removeMeans = false;
    vo.minimumSamples = 2;
    FitValidation v;
    v.data = prepareFitData(*e.data, vo);
    const std::string which = o.validation.size() > 1 ? " " + std::to_string(i + 1) : "";
    if (!v.data.ok()) {
      r.termination = Termination::Failed;
      r.message = "validation data" + which + ": " + v.data.message;
      return false;
    }
    if (std::abs(v.data.sampleTime - r.data.sampleTime) > 1e-9 * r.data.sampleTime) {
      r.termination = Termination::Failed;
      r.message = "validation data" + which + ": its sample time differs from the estimation data's";
      return false;
    }
    v.data.validation = v.data.estimation;
    const PreparedData* means = &r.data;
    for (std::size_t k = 0; k < o.estimation.size(); ++k)
      if (o.estimation[k].data == e.data) {
        means = &r.estimation[k].data;
        break;
      }
    v.data.u.array() -= means->inputMean;
    v.data.y.array() -= means->outputMean;
    if (v.data.r.size()) v.data.r.array() -= means->referenceMean;
    v.data.inputMean = means->inputMean;
    v.data.outputMean = means->outputMean;
    v.data.referenceMean = means->referenceMean;
    if (means->inputMean != 0.0 || means->outputMean != 0.0)
      v.data.steps.push_back("the estimation data's means removed");
    r.validation.push_back(std::move(v));
  }
  return true;
}

// What to try when the estimator stopped at its iteration limit, from what the fit shows: a
// loss still falling (more iterations); one that has stopped falling, with parameters the
// data do not determine (hold them: the search only wanders along them) or without (another
// start).
std::string iterationLimitAdvice(const FitResult& r, int limit) {
  std::string s = "the estimator stopped at its limit of " + std::to_string(limit) +
                  " iterations before it converged, so the estimate may not be the loss's minimum and its "
                  "intervals may not hold; ";
  std::string undetermined;
  for (const auto& p : r.parameters)
    if (p.free && !p.determined) undetermined += (undetermined.empty() ? "" : ", ") + p.name;
  const auto& h = r.summary.lossHistory;
  const std::size_t back = std::min<std::size_t>(10, h.size() > 0 ? h.size() - 1 : 0);
  const double before = back > 0 ? h[h.size() - 1 - back] : 0.0;
  const double fell = back > 0 && before > 0.0 ? (before - h.back()) / before : 0.0;
  const std::string percent = shortNumber(100.0 * fell, 2) + " %";
  if (fell >= 1e-3)
    return s + "the loss still fell " + percent + " over the last " + std::to_string(back) +
           " iterations: raise the iteration limit (--max-iterations, the Fit panel's Max iterations)";
  const std::string flat = "the loss fell only " + percent + " over the last " + std::to_string(back) +
                           " iterations, so more of them will change little: ";
  if (!undetermined.empty())
    return s + flat + "the data do not determine " + undetermined +
           ", and the search only moves along them; hold them (--fix, or untick them in the Fit panel) or fit a "
           "smaller model";
  return s + flat + "start from other values (--start, --starts)";
}

}  // namespace

PreparedFit prepareFit(const FitOptions& given) {
  std::string why;
  if (!given.isValid(&why)) throw std::invalid_argument("prepareFit: " + why);
  PreparedFit out;
  FitResult& r = out.result;
  r.model = given.model;
  // Evidence counted once: an experiment that holds the samples of an earlier one of its list
  // (the same log given twice, two copies of one file) is dropped with a warning, so that the
  // intervals do not narrow for data that add nothing.
  FitOptions deduplicated = given;
  auto countOnce = [&](std::vector<FitExperiment>& list, const char* kind) {
    std::vector<FitExperiment> kept;
    std::vector<std::size_t> number;  // of each kept one in the list as given, from 1
    for (std::size_t i = 0; i < list.size(); ++i) {
      std::size_t same = kept.size();
      for (std::size_t k = 0; k < kept.size() && same == kept.size(); ++k)
        if (sameSamples(*kept[k].data, kept[k].range, *list[i].data, list[i].range)) same = k;
      if (same == kept.size()) {
        kept.push_back(list[i]);
        number.push_back(i + 1);
        continue;
      }
      r.warn(FitWarning::RepeatedExperiment,
             std::string(kind) + " experiment " + std::to_string(i + 1) + " holds the same samples as " + kind +
                 " experiment " + std::to_string(number[same]) + " and is counted once");
    }
    list = std::move(kept);
    return number;
  };
  const std::vector<std::size_t> estimationGiven = countOnce(deduplicated.estimation, "estimation");
  const std::vector<std::size_t> validationGiven = countOnce(deduplicated.validation, "validation");
  const FitOptions& options = deduplicated;
  auto fail = [&](std::string message) {
    r.termination = Termination::Failed;
    r.message = std::move(message);
    r.status = FitStatus::BadData;
    out.options = deduplicated;
    return std::move(out);
  };

  // 1. Data. A log's gear ratio, the one source of a physical model's r, must be a ratio.
  if (options.model.kind == FitModelKind::Physical)
    for (const auto& e : options.estimation) {
      std::string bad;
      if (!logGearRatio(*e.data, &bad) && !bad.empty()) {
        return fail(bad);
      }
    }
  FitDataOptions d;
  d.input = options.input;
  d.output = options.output;
  d.reference = options.reference;
  const bool inverse = options.method != FitMethod::PredictionError;
  // Inverse dynamics differentiates the position itself, behind its own filter.
  d.velocityOutput = options.model.wantsVelocity() && !inverse;
  d.decimation = options.decimation;
  // A physical model holds its input over each sample (5.3): decimated, the torque it holds
  // is the logged torque's mean over the sample period (fit_data.h).
  if (options.model.kind == FitModelKind::Physical)
    d.decimatedInput = FitDataOptions::DecimatedInput::HeldMean;
  // The effects act on the real torque, velocity and angle: their means stay.
  d.removeMeans = options.removeMeans && !options.model.nonlinear() && !inverse;
  if (!prepareEstimation(options, d, r) || !prepareValidation(options, d, r)) return fail(r.message);
  for (std::size_t i = 0; i < r.estimation.size(); ++i) r.estimation[i].given = estimationGiven[i] - 1;
  for (std::size_t i = 0; i < r.validation.size(); ++i) r.validation[i].given = validationGiven[i] - 1;
  out.ok = true;
  out.options = std::move(deduplicated);
  return out;
}

FitResult fitModel(const FitOptions& given, const ProgressCallback& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  PreparedFit prepared = prepareFit(given);
  FitResult r = std::move(prepared.result);
  const FitOptions& options = prepared.options;
  auto finish = [&](Termination t, std::string message) -> FitResult {
    r.termination = t;
    r.message = std::move(message);
    if (t == Termination::Cancelled) r.status = FitStatus::Cancelled;
    else if (r.ok()) r.status = FitStatus::Ok;
    else if (r.status != FitStatus::BadData && r.status != FitStatus::BadRequest) r.status = FitStatus::Failed;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::move(r);
  };
  if (!prepared.ok) return finish(r.termination, r.message);
  const bool inverse = options.method != FitMethod::PredictionError;
  const bool nonparametric = options.model.kind == FitModelKind::Spa || options.model.kind == FitModelKind::Etfe;
  bool constant = true;
  for (const auto& e : r.estimation) {
    const Eigen::VectorXd uEst = e.data.estimationInput();
    constant = constant && (uEst.array() - uEst.mean()).abs().maxCoeff() == 0.0;
  }
  if (!nonparametric && constant)
    return finish(Termination::Failed,
                  "the input is constant over the estimation range, so the data say nothing about the system");

  // 2-4. Method, starts, estimator.
  if (inverse) {
    try {
      if (!fit_detail::fitIdim(options, r)) return finish(r.termination, r.message);
      r.response = fitResponse(r, fitFrequencyGrid(r.data, options.responsePoints), options.level);
      fit_detail::plausibilityChecks(options, r);
      fit_detail::assessDeterminacy(options, r);
    } catch (const std::exception& e) {
      return finish(Termination::Failed, std::string("inverse dynamics failed: ") + e.what());
    }
    return finish(r.summary.termination, r.summary.message);
  }
  FitOptions started = options;  // with the start values inverse dynamics gives
  try {
    switch (options.model.kind) {
      case FitModelKind::Physical:
        fit_detail::idimStart(started, r);
        if (options.model.nonlinear()) {
          fit_detail::fitNonlinear(started, r, progress);
        } else if (!fit_detail::fitPhysical(started, r, progress)) {
          return finish(r.termination, r.message);
        }
        break;
      case FitModelKind::BlackBox: {
        std::string tooMuch;
        long long samples = 0;  // of every estimation experiment
        for (const auto& e : r.estimation) samples += static_cast<long long>(e.data.estimation.size());
        if (!options.model.orders.fitsData(options.model.structure, samples, &tooMuch)) {
          r.status = FitStatus::BadRequest;
          return finish(Termination::Failed, tooMuch);
        }
        fitBlackBox(options, r, progress);
        break;
      }
      case FitModelKind::Spa:
      case FitModelKind::Etfe: fitNonparametric(options, r); break;
    }
  } catch (const std::invalid_argument& e) {
    return finish(Termination::Failed, std::string("the fit was refused: ") + e.what());
  } catch (const std::exception& e) {  // numerical trouble is a failed fit, never a crash
    return finish(Termination::Failed, std::string("the estimator met numerical trouble: ") + e.what());
  }
  if (!r.summary.ok()) return finish(r.summary.termination, r.summary.message);

  // 5. Evaluation.
  try {
    fit_detail::evaluate(options, r);
    fit_detail::plausibilityChecks(options, r);
    fit_detail::assessDeterminacy(options, r);
  } catch (const std::exception& e) {
    return finish(Termination::Failed, std::string("the estimate could not be evaluated: ") + e.what());
  }
  if (r.summary.termination == Termination::MaxIterations)
    r.warn(FitWarning::MaxIterations, iterationLimitAdvice(r, options.maxIterations));
  return finish(r.summary.termination, r.summary.message);
}

}  // namespace flexarm
