#include "core/session/provenance.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>

#include "core/session/json_fields.h"
#include "core/session/report.h"

namespace flexarm {

using nlohmann::json;

namespace {

std::string rangeText(const SecondsRange& r) {
  return formatSignificant(r.start) + "-" + formatSignificant(r.end) + " s";
}

// The first 16 hex digits: enough to tell logs apart in a sentence that fits a line.
std::string shortSum(const std::string& sum) {
  if (sum.empty()) return "unknown";
  return sum.size() > 16 ? sum.substr(0, 16) + "..." : sum;
}

}  // namespace

bool Provenance::operator==(const Provenance& o) const {
  return log == o.log && sha256 == o.sha256 && reading == o.reading && preprocessing == o.preprocessing &&
         estimation == o.estimation && validation == o.validation && when == o.when;
}

std::string utcNow() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

Provenance sessionDataProvenance(const Session& session, const std::string& path, const std::string& sum) {
  Provenance p;
  p.log = std::filesystem::path(path).filename().string();
  p.sha256 = sum;
  if (!session.logs.empty()) p.reading = describeMapping(session.logs.front().read.mapping);
  if (session.preprocessed) p.preprocessing = describePreprocessing(session.preprocess);
  p.estimation = session.estimation;
  p.validation = session.validation;
  p.when = utcNow();
  return p;
}

bool sameData(const Provenance& a, const Provenance& b) {
  return a.sha256 == b.sha256 && a.reading == b.reading && a.preprocessing == b.preprocessing;
}

std::string shortDescription(const Provenance& p) {
  return p.log + " " + (p.estimation ? rangeText(*p.estimation) : std::string("whole log"));
}

std::string longDescription(const Provenance& p) {
  std::string text = p.log + " (SHA-256 " + shortSum(p.sha256) + ", ";
  if (!p.reading.empty()) {
    text += "read with ";
    for (std::size_t i = 0; i < p.reading.size(); ++i) text += (i ? ", " : "") + p.reading[i];
    text += "; ";
  }
  if (p.preprocessing.empty()) {
    text += "as read";
  } else {
    text += "preprocessed: ";
    for (std::size_t i = 0; i < p.preprocessing.size(); ++i) text += (i ? ", " : "") + p.preprocessing[i];
  }
  if (p.estimation) text += "; estimation " + rangeText(*p.estimation);
  if (p.validation) text += ", validation " + rangeText(*p.validation);
  return text + ")";
}

std::string dataMismatch(const Provenance& result, const Provenance& open) {
  if (sameData(result, open)) return {};
  const bool sameLog = result.sha256 == open.sha256;
  return "computed on " + longDescription(result) + (result.when.empty() ? "" : " at " + result.when) +
         (sameLog ? "; the open data are the same log read or preprocessed differently: "
                  : "; the open log is ") +
         longDescription(open);
}

json provenanceToJson(const Provenance& p) {
  json j = {{"log", p.log},
            {"sha256", p.sha256},
            {"preprocessing", p.preprocessing},
            {"estimation_s", secondsRangeToJson(p.estimation)},
            {"validation_s", secondsRangeToJson(p.validation)},
            {"when", p.when}};
  if (!p.reading.empty()) j["reading"] = p.reading;
  return j;
}

std::optional<Provenance> provenanceFromJson(const json& j, std::string* why) {
  const std::string where = "provenance: ";
  if (!j.is_object()) {
    if (why) *why = where + "must be an object";
    return std::nullopt;
  }
  Provenance p;
  if (!readText(j, "log", p.log, true, why, where) || !readText(j, "sha256", p.sha256, true, why, where) ||
      !readText(j, "when", p.when, false, why, where))
    return std::nullopt;
  for (const auto& [key, list] : {std::pair<const char*, std::vector<std::string>*>{"preprocessing", &p.preprocessing},
                                   {"reading", &p.reading}}) {
    if (!j.contains(key)) continue;
    const json& steps = j[key];
    if (!steps.is_array() || !std::all_of(steps.begin(), steps.end(), [](const json& s) { return s.is_string(); })) {
      if (why) *why = where + key + " must be a list of steps";
      return std::nullopt;
    }
    for (const auto& s : steps) list->push_back(s.get<std::string>());
  }
  std::string rangeWhy;
  if (!readSecondsRange(j, "estimation_s", p.estimation, &rangeWhy) ||
      !readSecondsRange(j, "validation_s", p.validation, &rangeWhy)) {
    if (why) *why = where + rangeWhy;
    return std::nullopt;
  }
  return p;
}

std::optional<Provenance> provenanceIn(const json& j) {
  if (!j.is_object() || !j.contains("provenance")) return std::nullopt;
  std::string why;
  return provenanceFromJson(j["provenance"], &why);
}

std::string uniqueResultName(const std::string& base, const Provenance& p, const std::vector<std::string>& taken) {
  // The number counts results of this base: any earlier "BASE k (" or "BASE k" holds k.
  auto used = [&](const std::string& stem) {
    return std::any_of(taken.begin(), taken.end(), [&](const std::string& t) {
      return t == stem || t.rfind(stem + " (", 0) == 0;
    });
  };
  int k = 1;
  while (used(k == 1 ? base : base + " " + std::to_string(k))) ++k;
  return (k == 1 ? base : base + " " + std::to_string(k)) + " (" + shortDescription(p) + ")";
}

}  // namespace flexarm
