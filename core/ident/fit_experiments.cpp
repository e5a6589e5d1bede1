#include "core/ident/fit_experiments.h"

#include <filesystem>
#include <sstream>

#include "core/io/ranges.h"

namespace flexarm {

namespace {

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string rangeText(const SecondsRange& r) {
  std::ostringstream s;
  s.precision(12);
  s << r.start << ":" << r.end;
  return s.str();
}

}  // namespace

std::optional<ExperimentSource> experimentSourceFromText(const std::string& text, bool validation, std::string* why) {
  ExperimentSource s;
  s.validation = validation;
  s.path = text;
  const auto at = text.rfind('@');
  std::error_code ec;
  if (at != std::string::npos && !std::filesystem::exists(text, ec)) {
    s.path = text.substr(0, at);
    s.range = secondsRangeFromText(text.substr(at + 1), why);
    if (!s.range) return std::nullopt;
  }
  if (s.path.empty()) {
    if (why) *why = "an experiment needs a file name, '" + text + "' has none";
    return std::nullopt;
  }
  return s;
}

std::string experimentSourceText(const ExperimentSource& s) {
  return s.range ? s.path + "@" + rangeText(*s.range) : s.path;
}

std::optional<std::vector<ExperimentSource>> experimentListFromText(const std::string& text, std::string* why) {
  std::vector<ExperimentSource> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item)) {
    std::istringstream parts(item);
    std::string part;
    while (std::getline(parts, part, ',')) {
      std::string t = trimmed(part);
      if (t.empty()) continue;
      bool validation = false;
      if (t.rfind("val:", 0) == 0) {
        validation = true;
        t = trimmed(t.substr(4));
      }
      auto s = experimentSourceFromText(t, validation, why);
      if (!s) return std::nullopt;
      out.push_back(*s);
    }
  }
  return out;
}

std::string experimentListText(const std::vector<ExperimentSource>& list) {
  std::string out;
  for (const auto& s : list) {
    if (!out.empty()) out += ", ";
    out += (s.validation ? "val: " : "") + experimentSourceText(s);
  }
  return out;
}

ExperimentLoad loadExperiment(const ExperimentSource& source, const LogReadOptions& read, ExperimentLogs& logs) {
  ExperimentLoad out;
  std::shared_ptr<const IdData>& data = logs[source.path];
  if (!data) {
    LogReadResult r = readLog(source.path, read);
    if (!r.ok) {
      logs.erase(source.path);
      out.badInput = true;
      out.message = r.error.toString();
      return out;
    }
    std::string why;
    if (!applyStoredRanges(r.data, &why)) {
      logs.erase(source.path);
      out.badInput = true;
      out.message = source.path + ": " + why;
      return out;
    }
    if (!r.data.input() || !r.data.output()) {
      logs.erase(source.path);
      out.badInput = true;
      out.message = source.path + ": the log has no input or no output channel";
      return out;
    }
    data = std::make_shared<const IdData>(std::move(r.data));
  }
  FitExperiment e{data, source.range};
  const auto& stored = source.validation ? data->validationRange : data->estimationRange;
  if (source.range) {
    if (samplesIn(*data, *source.range).empty()) {
      out.message = "the range " + rangeText(*source.range) + " s holds no samples of the log";
      return out;
    }
  } else if (stored && !stored->empty()) {
    e.range = secondsOf(*data, *stored);
  }
  out.experiment = e;
  return out;
}

bool appendExperiments(FitOptions& options, const std::vector<ExperimentSource>& sources,
                       const LogReadOptions& read, ExperimentLogs& logs, std::string* why) {
  for (const auto& s : sources) {
    ExperimentLoad l = loadExperiment(s, read, logs);
    if (!l.experiment) {
      if (why) *why = l.badInput ? l.message : experimentSourceText(s) + ": " + l.message;
      return false;
    }
    (s.validation ? options.validation : options.estimation).push_back(*l.experiment);
  }
  return true;
}

}  // namespace flexarm
