#include "core/compare/sensitivity_study.h"

#include <chrono>
#include <cstdio>
#include <stdexcept>

namespace flexarm {

const char* toString(SensitivityCode c) {
  switch (c) {
    case SensitivityCode::Ok: return "ok";
    case SensitivityCode::NoData: return "no_data";
    case SensitivityCode::NotPhysical: return "not_physical";
    case SensitivityCode::NoFreeParameters: return "no_free_parameters";
    case SensitivityCode::ReferenceFailed: return "reference_failed";
    case SensitivityCode::Cancelled: return "cancelled";
  }
  return "no_data";
}

bool SensitivityRequest::isValid(std::string* why) const {
  auto fail = [why](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  if (!data.log) return fail("no data to run the fits on");
  std::string reason;
  if (!model.isValid(&reason)) return fail("model '" + model.name + "': " + reason);
  if (!attraction.isValid(&reason)) return fail("domain of attraction: " + reason);
  if (monteCarlo.runs < 0 || monteCarlo.runs > kMaxSensitivityRuns)
    return fail("the Monte-Carlo runs must lie in 0.." + std::to_string(kMaxSensitivityRuns));
  if (monteCarlo.runs > 0 && !monteCarlo.isValid(&reason)) return fail("Monte-Carlo: " + reason);
  return true;
}

std::string SensitivityResult::summary() const {
  if (code != SensitivityCode::Ok && code != SensitivityCode::Cancelled) return modelName + ": " + message;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f", attraction.seconds);
  std::string s = "Domain of attraction: " + std::to_string(attraction.fits) + " fits in " + buf + " s (" +
                  attraction.message + ").";
  if (monteCarlo) {
    std::snprintf(buf, sizeof buf, "%.1f", 100.0 * monteCarlo->successRate());
    std::string rate = buf;
    std::snprintf(buf, sizeof buf, "%.1f", monteCarlo->seconds);
    s += " Monte-Carlo: " + std::to_string(monteCarlo->successes) + " of " + std::to_string(monteCarlo->completed) +
         " runs succeeded (" + rate + " %) in " + buf + " s.";
  }
  if (effectsLeftOut) s += " The model's effects are left out: the study refits its linear part (5.7).";
  if (code == SensitivityCode::Cancelled) s += " Cancelled.";
  return s;
}

SensitivityResult runSensitivityStudy(const SensitivityRequest& request, const ProgressCallback& progress) {
  std::string why;
  if (!request.isValid(&why)) throw std::invalid_argument("runSensitivityStudy: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  SensitivityResult out;
  out.modelName = request.model.name;
  out.dataName = request.data.name;
  auto finish = [&](Termination t, SensitivityCode code, std::string message) {
    out.termination = t;
    out.code = code;
    out.message = std::move(message);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  if (!request.model.physical)
    return finish(Termination::Failed, SensitivityCode::NotPhysical,
                  "the study refits a physical model; a black-box estimate has no physical starts");
  bool anyFree = false;
  for (const auto& p : request.model.physical->parameters()) anyFree = anyFree || p.free;
  if (!anyFree)
    return finish(Termination::Failed, SensitivityCode::NoFreeParameters, "the model has no free parameter to vary");
  const IdData& log = *request.data.log;
  if (!log.input() || !log.output())
    return finish(Termination::Failed, SensitivityCode::NoData, "the log needs an input and an output channel");
  // The linear part on the data its fit ran on (means removed, as the refits (5.7) need).
  EvaluatedModel linear = request.model;
  out.effectsLeftOut = !linear.effects.empty();
  linear.effects.clear();
  const PreparedData d = prepareFitData(log, modelDataOptions(linear, decimationFor(linear, log.sampleTime),
                                                              request.data.estimation, std::nullopt));
  if (!d.ok()) return finish(Termination::Failed, SensitivityCode::NoData, d.message);
  out.dataNote = d.note();
  out.rangeText = rangeLabel(DataRange::Estimation, d, d.estimation);
  out.samples = static_cast<int>(d.estimation.size());
  out.sampleTime = d.sampleTime;
  const Eigen::VectorXd u = d.estimationInput(), y = d.estimationOutput();
  const bool monteCarlo = request.monteCarlo.runs > 0;
  const double share = monteCarlo ? 0.5 : 1.0;
  auto part = [&progress, share](double offset) -> ProgressCallback {
    if (!progress) return {};
    return [&progress, offset, share](double f, const std::string& stage) { return progress(offset + share * f, stage); };
  };
  out.attraction = domainOfAttraction(*request.model.physical, u, y, d.sampleTime, request.attraction, part(0.0));
  if (out.attraction.termination == Termination::Cancelled)
    return finish(Termination::Cancelled, SensitivityCode::Cancelled, "cancelled during the domain of attraction");
  if (out.attraction.termination != Termination::Converged)
    return finish(Termination::Failed, SensitivityCode::ReferenceFailed, out.attraction.message);
  if (monteCarlo) {
    out.monteCarlo = monteCarloStarts(*request.model.physical, u, y, d.sampleTime, out.attraction, request.monteCarlo,
                                      part(0.5));
    if (out.monteCarlo->termination == Termination::Cancelled)
      return finish(Termination::Cancelled, SensitivityCode::Cancelled, "cancelled during the Monte-Carlo runs");
    if (out.monteCarlo->termination != Termination::Converged)
      return finish(Termination::Failed, SensitivityCode::ReferenceFailed, out.monteCarlo->message);
  }
  return finish(Termination::Converged, SensitivityCode::Ok, "studied " + std::to_string(out.attraction.parameters.size()) +
                                                                 " free parameters");
}

}  // namespace flexarm
