#include "core/compare/compare.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <tuple>

#include "core/ident/fit.h"

namespace flexarm {

const char* toString(DataRange r) { return r == DataRange::Estimation ? "estimation" : "validation"; }

std::optional<DataRange> dataRangeFromString(std::string_view s) {
  if (s == "estimation") return DataRange::Estimation;
  if (s == "validation") return DataRange::Validation;
  return std::nullopt;
}

const char* toString(CompareStatus s) {
  switch (s) {
    case CompareStatus::Compared: return "compared";
    case CompareStatus::RateMismatch: return "rate_mismatch";
    case CompareStatus::Diverged: return "diverged";
    case CompareStatus::Failed: return "failed";
  }
  return "failed";
}

const char* toString(CompareCode c) {
  switch (c) {
    case CompareCode::Ok: return "ok";
    case CompareCode::NoData: return "no_data";
    case CompareCode::Cancelled: return "cancelled";
  }
  return "no_data";
}

bool CompareRequest::isValid(std::string* why) const {
  auto fail = [why](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  if (!data.log) return fail("no data to compare on");
  if (observerHz && !(*observerHz >= 0.0 && *observerHz <= 1e4))
    return fail("the observer bandwidth must lie in 0..10000 Hz");
  if (observerHz && *observerHz > 0.0 && horizon > 0)
    return fail("give either a prediction horizon or the load observer");
  if (horizon < 0 || horizon > kMaxCompareHorizon)
    return fail("the prediction horizon must be 0 (simulation) or 1.." + std::to_string(kMaxCompareHorizon) +
                " samples");
  for (const auto* r : {&data.estimation, &data.validation})
    if (*r && !(r->value().end > r->value().start))
      return fail("a range must end after it starts");
  for (const auto& m : models) {
    std::string reason;
    if (!m.isValid(&reason)) return fail("model '" + m.name + "': " + reason);
  }
  return true;
}

namespace {

std::string shortNumber(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", t);
  return buf;
}

std::string percent(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

}  // namespace

std::string rangeLabel(DataRange kind, const PreparedData& d, SampleRange range) {
  return samplesLabel(toString(kind), d, range);
}

std::string CompareResult::rangeText() const {
  if (rangeFellBack) return "the estimation data (no validation range set)";
  return std::string("the ") + toString(range) + " data";
}

std::vector<std::string> CompareResult::lines() const {
  std::vector<std::string> out;
  if (!ok() && models.empty()) {
    out.push_back(message);
    return out;
  }
  const std::string how = horizon > 0 ? std::to_string(horizon) + "-step prediction" : "model output";
  out.push_back("Fit of the " + how + " on " + rangeText() + " of " + dataName + " (" + dataNote +
                "), as the seed's (5.2) 1 - sum e^2/sum (y - mean y)^2 and as MATLAB compare's NRMSE "
                "1 - |e|/|y - mean y|:");
  for (const auto& m : models) {
    if (!m.fit) {
      out.push_back(m.name + ": not compared (" + m.message + ")");
      continue;
    }
    std::string line = m.name + ": fit " + percent(m.fit->percent.seed52) + " % (5.2), " +
                       percent(m.fit->percent.nrmse) + " % NRMSE";
    if (m.decimation > 1) line += " (at " + shortNumber(1.0 / m.sampleTime) + " Hz)";
    line += "; " + fitKindText(m.fit->basis) + (m.fit->basis.start == FitStart::LogStart
                                                    ? " from the log's first sample"
                                                    : " from the range's first sample");
    if (m.fit->basis.effects) line += ", with its effects";
    if (!m.message.empty()) line += "; " + m.message;
    out.push_back(line);
  }
  bool deflection = false;
  for (const auto& m : models) deflection = deflection || m.deflection;
  if (deflection) {
    out.push_back("The deflection r phi_m - phi_a the arm-side encoder measures (r = " + shortNumber(gearRatio) +
                  "), predicted from the torque by each model (with its effects), each about its mean:");
    for (const auto& m : models)
      if (m.deflection)
        out.push_back(m.name + ": deflection " + percent(m.deflection->figure.percent.seed52) + " % (5.2), " +
                      percent(m.deflection->figure.percent.nrmse) + " % NRMSE");
  }
  if (code == CompareCode::Cancelled) out.push_back("Cancelled.");
  return out;
}

namespace {

// The data at one preparation, prepared once for every model that needs it.
using PreparationKey = std::tuple<int, bool, bool, bool>;  // decimation, velocity, means, held
PreparationKey keyOf(const FitDataOptions& o) {
  return {o.decimation, o.velocityOutput, o.removeMeans,
          o.decimatedInput == FitDataOptions::DecimatedInput::HeldMean};
}

SampleRange rangeOf(DataRange kind, const PreparedData& d) {
  return kind == DataRange::Validation && !d.validation.empty() ? d.validation : d.estimation;
}

}  // namespace

CompareResult runCompare(const CompareRequest& request, const ProgressCallback& progress) {
  std::string why;
  if (!request.isValid(&why)) throw std::invalid_argument("runCompare: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  CompareResult out;
  out.horizon = request.horizon;
  out.observerHz = request.observerHz;
  out.dataName = request.data.name;
  out.range = request.range;
  auto finish = [&](Termination t, CompareCode code, std::string message) {
    out.termination = t;
    out.code = code;
    out.message = std::move(message);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  const IdData& log = *request.data.log;
  if (!log.input() || !log.output())
    return finish(Termination::Failed, CompareCode::NoData, "the log needs an input and an output channel");

  // The measured output at the log's rate, in its own units (means kept): the curve every
  // model's output is drawn against.
  bool velocity = request.models.empty();
  for (const auto& m : request.models) velocity = velocity || wantsVelocity(m);
  FitDataOptions baseOptions;
  baseOptions.velocityOutput = velocity;
  baseOptions.removeMeans = false;
  baseOptions.minimumSamples = 2;
  baseOptions.estimation = request.data.estimation;
  baseOptions.validation = request.data.validation;
  const PreparedData base = prepareFitData(log, baseOptions);
  if (!base.ok()) return finish(Termination::Failed, CompareCode::NoData, base.message);
  out.velocity = base.differentiated || (velocity && log.output()->unit == "rad/s");
  out.outputName = base.outputName;
  out.outputUnit = log.output()->unit + (base.differentiated ? "/s" : "");
  out.dataNote = base.note();
  out.rangeFellBack = request.range == DataRange::Validation && base.validation.empty();
  out.range = out.rangeFellBack ? DataRange::Estimation : request.range;
  const SampleRange shown = rangeOf(out.range, base);
  out.sampleTime = base.sampleTime;
  out.startTime = base.timeAt(shown.begin);
  out.measured = base.y.segment(static_cast<Eigen::Index>(shown.begin), static_cast<Eigen::Index>(shown.size()));

  // The estimation range's first sample for the estimation figure, the log's for validation.
  FitBasis basis;
  basis.horizon = request.horizon;
  basis.start = out.range == DataRange::Estimation ? FitStart::RangeStart : FitStart::LogStart;
  basis.data = request.data.name;

  // The measured deflection, through the log's gear ratio, else the first physical model's.
  double ratio = std::nan("");
  if (const auto stated = logGearRatio(log)) ratio = *stated;
  for (const auto& m : request.models)
    if (std::isnan(ratio) && m.physical) ratio = m.physical->value("r");
  if (request.deflection && std::isfinite(ratio)) {
    const Eigen::VectorXd d = measuredDeflection(base, ratio);
    if (d.size() == base.u.size()) {
      out.gearRatio = ratio;
      const Eigen::VectorXd seg = d.segment(static_cast<Eigen::Index>(shown.begin), static_cast<Eigen::Index>(shown.size()));
      out.measuredDeflection = seg.array() - seg.mean();
    }
  }

  std::map<PreparationKey, PreparedData> prepared;
  const std::size_t n = request.models.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (reportProgress(progress, static_cast<double>(i) / static_cast<double>(std::max<std::size_t>(1, n)),
                       "comparing " + request.models[i].name))
      return finish(Termination::Cancelled, CompareCode::Cancelled, "cancelled after " + std::to_string(i) + " models");
    const EvaluatedModel& model = request.models[i];
    ComparedModel c;
    c.name = model.name;
    c.decimation = decimationFor(model, log.sampleTime);
    if (c.decimation == 0) {
      c.status = CompareStatus::RateMismatch;
      c.message = "its sample time is no multiple of the data's";
      out.models.push_back(std::move(c));
      continue;
    }
    const FitDataOptions o = modelDataOptions(model, c.decimation, request.data.estimation, request.data.validation);
    auto it = prepared.find(keyOf(o));
    if (it == prepared.end()) it = prepared.emplace(keyOf(o), prepareFitData(log, o)).first;
    const PreparedData& d = it->second;
    if (!d.ok()) {
      c.message = d.message;
      out.models.push_back(std::move(c));
      continue;
    }
    const SampleRange r = rangeOf(out.range, d);
    c.sampleTime = d.sampleTime;
    c.startTime = d.timeAt(r.begin);
    FitBasis b = basis;
    b.range = rangeLabel(out.range, d, r);
    // A prediction horizon asks every model to predict: no observer then.
    b.observerHz = request.horizon > 0 ? 0.0 : request.observerHz.value_or(fitObserverHz(model, d));
    ModelFit f;
    try {
      f = modelFit(model, d, r, b);
    } catch (const std::exception& e) {
      f.output.message = e.what();
    }
    if (!f.figure || !std::isfinite(f.figure->percent.seed52)) {
      c.status = f.output.failure == SignalFailure::Diverged       ? CompareStatus::Diverged
                 : f.output.failure == SignalFailure::RateMismatch ? CompareStatus::RateMismatch
                                                                   : CompareStatus::Failed;
      c.message = f.output.message.empty() ? "the measured output does not vary over the range" : f.output.message;
      out.models.push_back(std::move(c));
      continue;
    }
    c.status = CompareStatus::Compared;
    c.fit = f.figure;
    c.output = f.output.y.array() + d.outputMean;  // in the log's units, as the measured curve
    if (request.horizon > 0 && model.physical)
      c.message = "an output-error model predicts what it simulates";
    if (request.deflection && model.physical) {
      std::string reason;
      if (auto df = deflectionFit(model, d, r, b.start, model.physical->value("r"), &reason)) {
        df->figure.basis.data = b.data;
        df->figure.basis.range = b.range;
        c.deflection = std::move(df);
      }
    }
    out.models.push_back(std::move(c));
  }
  reportProgress(progress, 1.0, "compared");
  return finish(Termination::Converged, CompareCode::Ok,
                "compared " + std::to_string(n) + (n == 1 ? " model" : " models") + " on " + out.rangeText());
}

}  // namespace flexarm
