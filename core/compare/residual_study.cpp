#include "core/compare/residual_study.h"

#include <chrono>
#include <cstdio>
#include <stdexcept>

namespace flexarm {

const char* toString(ResidualsCode c) {
  switch (c) {
    case ResidualsCode::Ok: return "ok";
    case ResidualsCode::NoData: return "no_data";
    case ResidualsCode::NoRange: return "no_range";
    case ResidualsCode::RateMismatch: return "rate_mismatch";
    case ResidualsCode::NoResiduals: return "no_residuals";
    case ResidualsCode::TooShort: return "too_short";
    case ResidualsCode::Cancelled: return "cancelled";
  }
  return "no_data";
}

bool ResidualsRequest::isValid(std::string* why) const {
  auto fail = [why](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  if (!data.log) return fail("no data to analyse");
  std::string reason;
  if (!model.isValid(&reason)) return fail("model '" + model.name + "': " + reason);
  if (!options.isValid(&reason)) return fail(reason);
  if (options.maxLag > 100000) return fail("at most 100000 lags");
  return true;
}

namespace {
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}
}  // namespace

std::string ResidualsResult::summary() const {
  if (code != ResidualsCode::Ok) return modelName + ": " + message;
  return modelName + " on the " + rangeText + " of " + dataName + ", " + std::to_string(samples) + " samples (" +
         (predictionErrors ? "one-step prediction errors" : "output errors of the simulation") +
         "). Whiteness: " + (analysis.white ? "passed" : "failed") + " (statistic " +
         number(analysis.whitenessStatistic) + ", 99 % threshold " + number(analysis.whitenessThreshold) +
         "). Independence from the input: " + (analysis.independent ? "passed" : "failed") + " (statistic " +
         number(analysis.independenceStatistic) + ", threshold " + number(analysis.independenceThreshold) + ").\n" +
         analysis.verdict;
}

ResidualsResult runResiduals(const ResidualsRequest& request, const ProgressCallback& progress) {
  std::string why;
  if (!request.isValid(&why)) throw std::invalid_argument("runResiduals: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  ResidualsResult out;
  out.modelName = request.model.name;
  out.dataName = request.data.name;
  out.range = request.range;
  out.predictionErrors = request.model.polynomial != nullptr;
  auto finish = [&](Termination t, ResidualsCode code, std::string message) {
    out.termination = t;
    out.code = code;
    out.message = std::move(message);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  const IdData& log = *request.data.log;
  if (!log.input() || !log.output())
    return finish(Termination::Failed, ResidualsCode::NoData, "the log needs an input and an output channel");
  out.decimation = decimationFor(request.model, log.sampleTime);
  if (out.decimation == 0)
    return finish(Termination::Failed, ResidualsCode::RateMismatch, "its sample time is no multiple of the data's");
  if (reportProgress(progress, 0.0, "residuals"))
    return finish(Termination::Cancelled, ResidualsCode::Cancelled, "cancelled");
  const PreparedData d = prepareFitData(
      log, modelDataOptions(request.model, out.decimation, request.data.estimation, request.data.validation));
  if (!d.ok()) return finish(Termination::Failed, ResidualsCode::NoData, d.message);
  out.dataNote = d.note();
  const SampleRange r = request.range == DataRange::Validation ? d.validation : d.estimation;
  if (r.empty())
    return finish(Termination::Failed, ResidualsCode::NoRange, "no validation range set: select one in the Log panel (V)");
  out.rangeText = rangeLabel(request.range, d, r);
  out.samples = static_cast<int>(r.size());
  out.sampleTime = d.sampleTime;
  const ResidualOptions& o = request.options;
  if (out.samples < 2 * o.maxLag + 10)
    return finish(Termination::Failed, ResidualsCode::TooShort,
                  "the range holds " + std::to_string(out.samples) + " samples; " + std::to_string(o.maxLag) +
                      " lags need at least " + std::to_string(2 * o.maxLag + 10));
  ModelSignal eps;
  try {
    eps = residualsOf(request.model, d);
  } catch (const std::exception& e) {
    eps.message = e.what();
  }
  const auto b = static_cast<Eigen::Index>(r.begin), n = static_cast<Eigen::Index>(r.size());
  if (!eps.ok() || eps.y.size() < b + n || !eps.y.segment(b, n).allFinite())
    return finish(Termination::Failed,
                  eps.failure == SignalFailure::RateMismatch ? ResidualsCode::RateMismatch : ResidualsCode::NoResiduals,
                  "no residuals (" + (eps.message.empty() ? std::string("unstable") : eps.message) + ")");
  out.analysis = residualAnalysis(eps.y.segment(b, n), d.u.segment(b, n), o);
  reportProgress(progress, 1.0, "residuals");
  return finish(Termination::Converged, ResidualsCode::Ok, out.analysis.verdict);
}

}  // namespace flexarm
