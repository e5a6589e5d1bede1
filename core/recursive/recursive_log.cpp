#include "core/recursive/recursive_log.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/io/log_io.h"

namespace flexarm {

bool RecursiveDataOptions::isValid(std::string* why) const {
  if (decimation < 0) {
    if (why) *why = "the decimation factor must not be negative (0: the log's rate up to the highest rate)";
    return false;
  }
  if (!(maxRateHz > 0.0) || !std::isfinite(maxRateHz)) {
    if (why) *why = "the highest rate must be a positive number of Hz";
    return false;
  }
  if (range && !(range->start < range->end)) {
    if (why) *why = "the range must have start < end";
    return false;
  }
  return true;
}

int recursiveDecimation(int decimation, double sampleRateHz, double maxRateHz) {
  if (decimation > 0) return decimation;
  return std::max(1, static_cast<int>(std::ceil(sampleRateHz / maxRateHz - 1e-9)));
}

PreparedData prepareRecursiveData(const IdData& log, const RecursiveDataOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("recursive identification: " + why);
  // Only the input and the output go through the preparation (the reference and any other
  // channel would be decimated for nothing).
  IdData used;
  used.sampleTime = log.sampleTime;
  used.startTime = log.startTime;
  used.metadata = log.metadata;
  for (const Channel& c : log.channels) {
    const bool wanted = options.input.empty() ? c.role == ChannelRole::Input : c.name == options.input;
    const bool output = options.output.empty() ? c.role == ChannelRole::Output : c.name == options.output;
    if (wanted || output) used.channels.push_back(c);
  }
  FitDataOptions f;
  f.input = options.input;
  f.output = options.output;
  f.velocityOutput = true;
  f.decimation = recursiveDecimation(options.decimation, log.sampleRateHz(), options.maxRateHz);
  f.decimatedInput = FitDataOptions::DecimatedInput::HeldMean;
  f.estimation = options.range;
  f.removeMeans = true;
  return prepareFitData(used, f);
}

RecursiveLogResult recursiveIdentification(const IdData& log, const ParametricModel& nominal,
                                           const RecursiveDataOptions& data,
                                           const RecursiveOptions& options,
                                           const ProgressCallback& progress) {
  RecursiveLogResult out;
  const PreparedData prepared = prepareRecursiveData(log, data);
  out.preparation = prepared.note();
  out.sampleTime = prepared.sampleTime;
  out.decimation = prepared.decimation;
  if (!prepared.ok()) {
    out.result.termination = Termination::Failed;
    out.result.message = prepared.message;
    return out;
  }
  out.result = recursiveIdentification(nominal, prepared.estimationInput(),
                                       prepared.estimationOutput(), prepared.sampleTime, options,
                                       progress, prepared.timeAt(prepared.estimation.begin));
  return out;
}

bool writeTrajectoryCsv(const RecursiveResult& r, const std::string& path, std::string* why) {
  std::string text = "time_s";
  for (const auto& e : r.estimates) text += "," + e.parameter.name;
  for (const auto& e : r.estimates) text += ",sigma_" + e.parameter.name;
  text += ",y,yhat,epsilon\n";
  const auto& t = r.trajectory;
  char buf[64];
  for (std::size_t k = 0; k < t.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.9g", t.time[k]);
    text += buf;
    for (const auto* columns : {&t.theta, &t.sigma})
      for (const auto& c : *columns) {
        std::snprintf(buf, sizeof buf, ",%.17g", c[k]);
        text += buf;
      }
    for (const auto* v : {&t.y, &t.yhat, &t.epsilon}) {
      std::snprintf(buf, sizeof buf, ",%.17g", (*v)[k]);
      text += buf;
    }
    text += "\n";
  }
  return writeFileAtomically(path, text, why);
}

}  // namespace flexarm
