#include "core/session/diagnosis_part.h"

#include <algorithm>
#include <cmath>

#include "core/diagnosis/diagnosis_json.h"
#include "core/session/json_fields.h"
#include "core/session/model_json.h"

namespace flexarm {

using nlohmann::json;

namespace {

json testList(const std::vector<DiagnosisTest>& tests) {
  json list = json::array();
  for (DiagnosisTest t : tests) list.push_back(toString(t));
  return list;
}

bool readTests(const json& j, const char* key, std::vector<DiagnosisTest>& out, std::string* why,
               const std::string& where) {
  if (!j.contains(key)) return true;
  if (!j[key].is_array()) {
    if (why) *why = where + key + " must be a list of tests";
    return false;
  }
  out.clear();
  for (const auto& t : j[key]) {
    const auto test = t.is_string() ? diagnosisTestFromString(t.get<std::string>()) : std::nullopt;
    if (!test) {
      if (why) *why = where + key + ": unknown test " + t.dump();
      return false;
    }
    out.push_back(*test);
  }
  return true;
}

bool readNumbers(const json& j, const char* key, std::vector<double>& out, std::string* why,
                 const std::string& where) {
  if (!j.contains(key)) return true;
  if (!j[key].is_array()) {
    if (why) *why = where + key + " must be a list of numbers";
    return false;
  }
  out.clear();
  for (const auto& v : j[key]) {
    if (!v.is_number()) {
      if (why) *why = where + key + " must be a list of numbers";
      return false;
    }
    out.push_back(v.get<double>());
  }
  return true;
}

bool readNames(const json& j, const char* key, std::vector<std::string>& out, std::string* why,
               const std::string& where) {
  if (!j.contains(key)) return true;
  if (!j[key].is_array()) {
    if (why) *why = where + key + " must be a list of names";
    return false;
  }
  out.clear();
  for (const auto& v : j[key]) {
    if (!v.is_string()) {
      if (why) *why = where + key + " must be a list of names";
      return false;
    }
    out.push_back(v.get<std::string>());
  }
  return true;
}

class DiagnosisPart : public SessionPart {
 public:
  std::string key() const override { return "diagnosis"; }

  bool validate(const json& section, std::string* why) const override {
    if (!section.is_object() || !section.contains("request")) {
      if (why) *why = "must be an object with a request";
      return false;
    }
    if (!diagnosisRequestFromJson(section["request"], why)) return false;
    if (section.contains("result") && !section["result"].is_null() && !section["result"].is_object()) {
      if (why) *why = "the result must be an object";
      return false;
    }
    return true;
  }

  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    std::string why;
    const auto stored = diagnosisRequestFromJson(section["request"], &why);
    if (!stored) return;  // validated on load
    const IdData* monitored = nullptr;
    auto fail = [&report](const std::string& text) {
      report.warnings.push_back("diagnosis: could not run: " + text);  // e.g. a log the session lacks
      ReportSection s;
      s.title = "Diagnosis";
      s.paragraphs.push_back("The diagnosis could not run: " + text + ".");
      s.values = {{"verdict", nullptr}, {"message", text}};
      report.sections.push_back(s);
    };
    auto request = resolveDiagnosisRequest(*stored, context, &monitored, &why);
    if (!request) return fail(why);
    DiagnosisRun run;
    try {
      run = runDiagnosisRequest(*request, *monitored, context.progress);
    } catch (const std::invalid_argument& e) {
      return fail(e.what());
    }
    if (run.termination == Termination::Failed || run.termination == Termination::Cancelled)
      return fail(run.message.empty() ? toString(run.termination) : run.message);
    ReportSection s = diagnosisReportSection(
        run, run.calibration ? calibrationJson(*run.calibration) : stored->calibration);
    s.paragraphs.insert(s.paragraphs.begin(),
                        "Monitored log: " + (stored->log.empty() ? std::string("the session's first") : stored->log) +
                            "; theta_0 from " +
                            (stored->referenceLog.empty()
                                 ? "the model " + (stored->model.empty() ? stored->structure + " (nominal)" : stored->model)
                                 : "the fault-free log " + stored->referenceLog) +
                            ".");
    if (section.contains("result") && section["result"].is_object()) {
      const std::string was = section["result"].value("verdict", std::string("none"));
      s.values["stored_verdict"] = was;
      if (was != run.result.verdictName()) {
        s.paragraphs.push_back("The session recorded the verdict " + was + "; this replay reaches " +
                               run.result.verdictName() + ".");
        report.warnings.push_back("diagnosis: the session recorded " + was + ", the replay reaches " +
                                  run.result.verdictName());
      }
    }
    report.sections.push_back(s);
  }
};

}  // namespace

bool DiagnosisSessionRequest::isValid(std::string* why) const {
  const auto& names = modelStructureNames();
  if (model.empty() && std::find(names.begin(), names.end(), structure) == names.end()) {
    if (why) *why = "the structure '" + structure + "' is not a model FlexArm knows";
    return false;
  }
  if (calibrate && !calibrationOptions.isValid(why)) return false;
  return options.isValid(why);
}

json diagnosisOptionsToJson(const DiagnosisOptions& o) {
  const RecursiveOptions& e = o.estimator;
  return {{"parameters", o.parameters},
          {"inverted", o.inverted},
          {"predictor", toString(o.predictor)},
          {"algorithm", toString(e.algorithm)},
          {"lambda", e.lambda},
          {"tests", testList(o.tests)},
          {"decision", testList(o.decision)},
          {"classical_k", o.classicalK},
          {"robust_k", o.robustK},
          {"robust_lambda", o.robustLambda},
          {"cusum_alpha1", o.cusumAlpha1},
          {"cusum_alpha2", o.cusumAlpha2},
          {"hypothesis_threshold", o.hypothesisThreshold},
          {"window", toString(o.window)},
          {"window_s", o.windowS},
          {"classical_factors", o.classicalScales},
          {"robust_factors", o.robustScales},
          {"cusum_factors", o.cusumScales},
          {"confirm_s", o.confirmS},
          {"settle_s", o.settleS},
          {"joint_k", o.jointK},
          {"joint_scale", o.jointScale},
          {"check_model", o.checkModel},
          {"mismatch_ratio", o.mismatchRatio},
          {"friction_alpha", o.friction ? json(o.friction->alpha) : json(nullptr)},
          {"friction_reference_c", o.friction ? json(o.friction->referenceC) : json(nullptr)},
          {"monitored_temperature_c", o.monitoredTemperatureC ? json(*o.monitoredTemperatureC) : json(nullptr)},
          {"reference_temperature_c", o.referenceTemperatureC ? json(*o.referenceTemperatureC) : json(nullptr)}};
}

std::optional<DiagnosisOptions> diagnosisOptionsFromJson(const json& j, std::string* why) {
  const std::string where = "the diagnosis options: ";
  if (!j.is_object()) {
    if (why) *why = where + "must be an object";
    return std::nullopt;
  }
  DiagnosisOptions o;
  std::string predictor = toString(o.predictor), window = toString(o.window),
              algorithm = toString(o.estimator.algorithm);
  if (!readNames(j, "parameters", o.parameters, why, where) ||
      !readNames(j, "inverted", o.inverted, why, where) ||
      !readText(j, "predictor", predictor, false, why, where) ||
      !readText(j, "algorithm", algorithm, false, why, where) ||
      !readNumber(j, "lambda", o.estimator.lambda, false, why, where) ||
      !readTests(j, "tests", o.tests, why, where) || !readTests(j, "decision", o.decision, why, where) ||
      !readNumber(j, "classical_k", o.classicalK, false, why, where) ||
      !readNumber(j, "robust_k", o.robustK, false, why, where) ||
      !readNumber(j, "robust_lambda", o.robustLambda, false, why, where) ||
      !readNumber(j, "cusum_alpha1", o.cusumAlpha1, false, why, where) ||
      !readNumber(j, "cusum_alpha2", o.cusumAlpha2, false, why, where) ||
      !readNumber(j, "hypothesis_threshold", o.hypothesisThreshold, false, why, where) ||
      !readText(j, "window", window, false, why, where) ||
      !readNumber(j, "window_s", o.windowS, false, why, where) ||
      !readNumbers(j, "classical_factors", o.classicalScales, why, where) ||
      !readNumbers(j, "robust_factors", o.robustScales, why, where) ||
      !readNumbers(j, "cusum_factors", o.cusumScales, why, where) ||
      !readNumber(j, "confirm_s", o.confirmS, false, why, where) ||
      !readNumber(j, "settle_s", o.settleS, false, why, where) ||
      !readNumber(j, "joint_k", o.jointK, false, why, where) ||
      !readNumber(j, "joint_scale", o.jointScale, false, why, where) ||
      !readFlag(j, "check_model", o.checkModel, why, where) ||
      !readNumber(j, "mismatch_ratio", o.mismatchRatio, false, why, where))
    return std::nullopt;
  // Optional numbers, null when not set.
  double alpha = NAN, referenceC = NAN, monitoredC = NAN, logReferenceC = NAN;
  if (!readNumber(j, "friction_alpha", alpha, false, why, where) ||
      !readNumber(j, "friction_reference_c", referenceC, false, why, where) ||
      !readNumber(j, "monitored_temperature_c", monitoredC, false, why, where) ||
      !readNumber(j, "reference_temperature_c", logReferenceC, false, why, where))
    return std::nullopt;
  if (std::isfinite(alpha)) {
    FrictionTemperatureModel f;
    f.alpha = alpha;
    if (std::isfinite(referenceC)) f.referenceC = referenceC;
    o.friction = f;
  }
  if (std::isfinite(monitoredC)) o.monitoredTemperatureC = monitoredC;
  if (std::isfinite(logReferenceC)) o.referenceTemperatureC = logReferenceC;
  const auto p = diagnosisPredictorFromString(predictor);
  const auto w = hypothesisWindowFromString(window);
  const auto a = recursiveAlgorithmFromString(algorithm);
  if (!p || !w || !a) {
    if (why) *why = where + "unknown predictor, window or algorithm";
    return std::nullopt;
  }
  o.predictor = *p;
  o.window = *w;
  o.estimator.algorithm = *a;
  std::string reason;
  if (!o.isValid(&reason)) {
    if (why) *why = where + reason;
    return std::nullopt;
  }
  return o;
}

json diagnosisRequestToJson(const DiagnosisSessionRequest& q) {
  json j = {{"log", q.log},
            {"reference_log", q.referenceLog},
            {"options", diagnosisOptionsToJson(q.options)},
            {"calibrate", q.calibrate},
            {"calibration_runs", q.calibrationOptions.healthyRuns},
            {"false_alarms_per_hour", q.calibrationOptions.targetFalseAlarmsPerHour},
            {"calibration", q.calibration}};
  if (q.model.empty()) j["structure"] = q.structure;
  else j["model"] = q.model;
  j["seed_fault"] = q.seedFault ? json{{"parameter", q.seedFault->first}, {"factor", q.seedFault->second}}
                                : json(nullptr);
  return j;
}

std::optional<DiagnosisSessionRequest> diagnosisRequestFromJson(const json& j, std::string* why) {
  const std::string where = "the diagnosis request: ";
  if (!j.is_object()) {
    if (why) *why = where + "must be an object";
    return std::nullopt;
  }
  DiagnosisSessionRequest q;
  int runs = q.calibrationOptions.healthyRuns;
  if (!readText(j, "log", q.log, false, why, where) ||
      !readText(j, "reference_log", q.referenceLog, false, why, where) ||
      !readText(j, "model", q.model, false, why, where) ||
      !readText(j, "structure", q.structure, false, why, where) ||
      !readFlag(j, "calibrate", q.calibrate, why, where) ||
      !readWhole(j, "calibration_runs", runs, why, where) ||
      !readNumber(j, "false_alarms_per_hour", q.calibrationOptions.targetFalseAlarmsPerHour, false, why, where))
    return std::nullopt;
  q.calibrationOptions.healthyRuns = runs;
  q.calibrationOptions.faultyRuns = std::max(1, runs / 5);
  if (j.contains("seed_fault") && !j["seed_fault"].is_null()) {
    const json& f = j["seed_fault"];
    std::string name;
    double factor = 0.0;
    if (!f.is_object() || !readText(f, "parameter", name, true, why, where + "seed_fault: ") ||
        !readNumber(f, "factor", factor, true, why, where + "seed_fault: "))
      return std::nullopt;
    q.seedFault = std::make_pair(name, factor);
  }
  if (j.contains("options")) {
    auto o = diagnosisOptionsFromJson(j["options"], why);
    if (!o) return std::nullopt;
    q.options = *o;
  }
  if (j.contains("calibration")) q.calibration = j["calibration"];
  std::string reason;
  if (!q.isValid(&reason)) {
    if (why) *why = where + reason;
    return std::nullopt;
  }
  return q;
}

std::optional<DiagnosisRequest> resolveDiagnosisRequest(const DiagnosisSessionRequest& q,
                                                        const ReplayContext& context,
                                                        const IdData** monitored, std::string* why) {
  // The diagnosis prepares its data itself (decimation to 200 Hz): the logs as read.
  *monitored = findLog(context, q.log, true, why);
  if (!*monitored) return std::nullopt;
  DiagnosisRequest r;
  r.options = q.options;
  r.seedFault = q.seedFault;
  r.calibrate = q.calibrate;
  r.calibration = q.calibrationOptions;
  if (!q.referenceLog.empty()) {
    const IdData* healthy = findLog(context, q.referenceLog, true, why);
    if (!healthy) return std::nullopt;
    r.referenceLog = std::make_shared<const IdData>(*healthy);
  }
  if (q.model.empty()) {
    r.model = makeModel(q.structure);
  } else {
    const auto spec = findListModel(context.session.parts.value("models", json::array()), q.model, why);
    if (!spec) return std::nullopt;
    r.model = spec->model;
  }
  if (!r.isValid(why)) return std::nullopt;
  return r;
}

std::shared_ptr<const SessionPart> makeDiagnosisPart() { return std::make_shared<DiagnosisPart>(); }

}  // namespace flexarm
