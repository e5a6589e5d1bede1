// The session parts "compare", "residuals" and "sensitivity" (compare_part.h): their requests
// as JSON and their replay. The report sections are in compare_report.cpp.
#include "core/common/text.h"
#include "core/session/compare_part.h"

#include <filesystem>

#include "core/compare/compare_json.h"
#include "core/session/json_fields.h"
#include "core/session/session_models.h"

namespace flexarm {

using nlohmann::json;

EvaluationData evaluationDataOf(const ReplayContext& context) {
  const Session& s = context.session;
  const std::string name =
      s.logs.empty() ? std::string() : std::filesystem::path(s.logs.front().path).filename().string();
  return {std::make_shared<const IdData>(context.data), s.estimation, s.validation, name};
}

std::vector<EvaluatedModel> evaluatedModelsOf(const Session& session) {
  const ModelList list = modelListOf(session);
  std::vector<EvaluatedModel> out;
  for (const auto& e : list.entries()) out.push_back(e.evaluated());
  return out;
}

namespace {

const char* const kWhere = "";

bool readRange(const json& j, DataRange& out, std::string* why) {
  std::string text = toString(out);
  if (!readText(j, "range", text, false, why, kWhere)) return false;
  const auto r = dataRangeFromString(text);
  if (!r) {
    if (why) *why = "range must be \"estimation\" or \"validation\"";
    return false;
  }
  out = *r;
  return true;
}

bool mustBeObject(const json& j, std::string* why) {
  if (j.is_object()) return true;
  if (why) *why = "must be an object";
  return false;
}

// The model named `name` among models (empty: the last one that `accept` takes); nullptr with a
// sentence when there is none.
const EvaluatedModel* findModel(const std::vector<EvaluatedModel>& models, const std::string& name,
                                bool physicalOnly, std::string* why) {
  const EvaluatedModel* found = nullptr;
  for (const auto& m : models)
    if ((name.empty() || m.name == name) && (!physicalOnly || m.physical)) found = &m;
  if (!found && why)
    *why = name.empty() ? std::string(physicalOnly ? "the model list holds no physical model" : "the model list is empty")
                        : "the model list holds no model " + inQuotes(name);
  return found;
}

// Progress of a part's one run, cancelled as the replay asks.
ProgressCallback partProgress(const ReplayContext& context) { return context.progress; }

}  // namespace

bool CompareSessionRequest::isValid(std::string* why) const {
  if (horizon < 0 || horizon > kMaxCompareHorizon) {
    if (why) *why = "horizon must lie in 0.." + std::to_string(kMaxCompareHorizon);
    return false;
  }
  if (observerHz && !(*observerHz >= 0.0 && *observerHz <= 1e4)) {
    if (why) *why = "observer_hz must lie in 0..10000";
    return false;
  }
  if (models.size() > kMaxPartItems) {
    if (why) *why = "more than " + std::to_string(kMaxPartItems) + " models";
    return false;
  }
  return true;
}

json compareRequestToJson(const CompareSessionRequest& r) {
  json j = {{"models", r.models}, {"range", toString(r.range)}, {"horizon", r.horizon}};
  if (r.observerHz) j["observer_hz"] = *r.observerHz;
  return j;
}

std::optional<CompareSessionRequest> compareRequestFromJson(const json& j, std::string* why) {
  if (!mustBeObject(j, why)) return std::nullopt;
  CompareSessionRequest r;
  if (j.contains("models")) {
    if (!j["models"].is_array()) {
      if (why) *why = "models must be a list of names";
      return std::nullopt;
    }
    for (const auto& n : j["models"]) {
      if (!n.is_string()) {
        if (why) *why = "models must be a list of names";
        return std::nullopt;
      }
      r.models.push_back(n.get<std::string>());
    }
  }
  if (!readRange(j, r.range, why) || !readWhole(j, "horizon", r.horizon, why, kWhere)) return std::nullopt;
  if (j.contains("observer_hz")) {
    double hz = 0.0;
    if (!readNumber(j, "observer_hz", hz, true, why, kWhere)) return std::nullopt;
    r.observerHz = hz;
  }
  if (!r.isValid(why)) return std::nullopt;
  return r;
}

bool ResidualsSessionRequest::isValid(std::string* why) const {
  if (!options.isValid(why)) return false;
  if (options.maxLag > 100000) {
    if (why) *why = "at most 100000 lags";
    return false;
  }
  return true;
}

json residualsRequestToJson(const ResidualsSessionRequest& r) {
  return {{"model", r.model}, {"range", toString(r.range)}, {"lags", r.options.maxLag}, {"level", r.options.level}};
}

std::optional<ResidualsSessionRequest> residualsRequestFromJson(const json& j, std::string* why) {
  if (!mustBeObject(j, why)) return std::nullopt;
  ResidualsSessionRequest r;
  if (!readText(j, "model", r.model, false, why, kWhere) || !readRange(j, r.range, why) ||
      !readWhole(j, "lags", r.options.maxLag, why, kWhere) || !readNumber(j, "level", r.options.level, false, why, kWhere))
    return std::nullopt;
  if (!r.isValid(why)) return std::nullopt;
  return r;
}

bool SensitivitySessionRequest::isValid(std::string* why) const {
  if (runs < 0 || runs > kMaxSensitivityRuns) {
    if (why) *why = "runs must lie in 0.." + std::to_string(kMaxSensitivityRuns);
    return false;
  }
  return true;
}

json sensitivityRequestToJson(const SensitivitySessionRequest& r) {
  return {{"model", r.model}, {"runs", r.runs}, {"seed", r.seed}};
}

std::optional<SensitivitySessionRequest> sensitivityRequestFromJson(const json& j, std::string* why) {
  if (!mustBeObject(j, why)) return std::nullopt;
  SensitivitySessionRequest r;
  int seed = static_cast<int>(r.seed);
  if (!readText(j, "model", r.model, false, why, kWhere) || !readWhole(j, "runs", r.runs, why, kWhere) ||
      !readWhole(j, "seed", seed, why, kWhere))
    return std::nullopt;
  if (seed < 0) {
    if (why) *why = "seed must be a whole number >= 0";
    return std::nullopt;
  }
  r.seed = static_cast<unsigned>(seed);
  if (!r.isValid(why)) return std::nullopt;
  return r;
}

namespace {

ReportSection failedSection(const std::string& title, const std::string& why) {
  ReportSection s;
  s.title = title;
  s.paragraphs.push_back("Not run: " + why + ".");
  return s;
}

class ComparePart : public SessionPart {
 public:
  std::string key() const override { return "compare"; }
  bool validate(const json& section, std::string* why) const override {
    return compareRequestFromJson(section, why).has_value();
  }
  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    std::string why;
    const auto asked = compareRequestFromJson(section, &why);
    if (!asked) return;  // validated on load
    CompareRequest r;
    r.data = evaluationDataOf(context);
    r.range = asked->range;
    r.horizon = asked->horizon;
    r.observerHz = asked->observerHz;
    const std::vector<EvaluatedModel> all = evaluatedModelsOf(context.session);
    for (const auto& name : asked->models) {
      const EvaluatedModel* m = findModel(all, name, false, &why);
      if (!m) return report.sections.push_back(failedSection("Compare", why));
      r.models.push_back(*m);
    }
    if (asked->models.empty()) r.models = all;
    if (r.models.empty()) return report.sections.push_back(failedSection("Compare", "the model list is empty"));
    report.sections.push_back(compareReportSection(runCompare(r, partProgress(context))));
  }
};

class ResidualsPart : public SessionPart {
 public:
  std::string key() const override { return "residuals"; }
  bool validate(const json& section, std::string* why) const override {
    return residualsRequestFromJson(section, why).has_value();
  }
  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    std::string why;
    const auto asked = residualsRequestFromJson(section, &why);
    if (!asked) return;
    const std::vector<EvaluatedModel> all = evaluatedModelsOf(context.session);
    const EvaluatedModel* m = findModel(all, asked->model, false, &why);
    if (!m) return report.sections.push_back(failedSection("Residual analysis", why));
    ResidualsRequest r;
    r.data = evaluationDataOf(context);
    r.model = *m;
    r.range = asked->range;
    r.options = asked->options;
    report.sections.push_back(residualsReportSection(runResiduals(r, partProgress(context))));
  }
};

class SensitivityPart : public SessionPart {
 public:
  std::string key() const override { return "sensitivity"; }
  bool validate(const json& section, std::string* why) const override {
    return sensitivityRequestFromJson(section, why).has_value();
  }
  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    std::string why;
    const auto asked = sensitivityRequestFromJson(section, &why);
    if (!asked) return;
    const std::vector<EvaluatedModel> all = evaluatedModelsOf(context.session);
    const EvaluatedModel* m = findModel(all, asked->model, true, &why);
    if (!m) return report.sections.push_back(failedSection("Sensitivity study (Section 5.3.3)", why));
    SensitivityRequest r;
    r.data = evaluationDataOf(context);
    r.model = *m;
    r.monteCarlo.runs = asked->runs;
    r.monteCarlo.seed = asked->seed;
    report.sections.push_back(sensitivityReportSection(runSensitivityStudy(r, partProgress(context))));
  }
  void replayStored(const json& section, const std::string& mismatch, Report& report) const override {
    ReportSection s;
    s.title = "Sensitivity study (Section 5.3.3)";
    s.paragraphs.push_back("Computed on other data: " + mismatch + ". Shown as stored, not recomputed.");
    if (section.contains("result")) s.values = section["result"];
    report.sections.push_back(std::move(s));
  }
};

}  // namespace

std::shared_ptr<const SessionPart> makeComparePart() { return std::make_shared<ComparePart>(); }
std::shared_ptr<const SessionPart> makeResidualsPart() { return std::make_shared<ResidualsPart>(); }
std::shared_ptr<const SessionPart> makeSensitivityPart() { return std::make_shared<SensitivityPart>(); }

}  // namespace flexarm
