#include "core/fleet/log_analysis.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/session/json_fields.h"
#include "core/diagnosis/diagnosis.h"
#include "core/io/log_io.h"
#include "core/session/model_json.h"
#include "core/session/sha256.h"

namespace flexarm {

namespace {

using nlohmann::json;

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

template <class T>
bool readArray(const json& j, const char* key, std::vector<T>& out, std::string* why) {
  if (!j.contains(key) || !j[key].is_array()) {
    if (why) *why = std::string("the reference lacks the list '") + key + "'";
    return false;
  }
  out.clear();
  for (const auto& v : j[key]) {
    if (!v.is_number()) {
      if (why) *why = std::string("'") + key + "' must hold numbers";
      return false;
    }
    out.push_back(v.get<T>());
  }
  return true;
}

}  // namespace

bool FleetAnalysisOptions::isValid(std::string* why) const {
  try {
    (void)makeModel(model);
  } catch (const std::invalid_argument& e) {
    if (why) *why = e.what();
    return false;
  }
  if (!(settledFraction > 0.0 && settledFraction <= 1.0)) {
    if (why) *why = "the settled fraction of a log must lie in (0, 1]";
    return false;
  }
  return diagnosis.isValid(why);
}

const FleetEstimate* FleetLogResult::estimate(const std::string& name) const {
  for (const auto& e : estimates)
    if (e.name == name) return &e;
  return nullptr;
}

namespace {

bool isSha256(const std::string& s) {
  return s.size() == 64 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

bool isValidFleetLogResult(const FleetLogResult& r, std::string* why) {
  auto fail = [&](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (!isSha256(r.sha256)) return fail("the log's checksum is not 64 hex digits");
  if (!isSha256(r.referenceSha256)) return fail("the reference's checksum is not 64 hex digits");
  // A verdict is none, detected (a change not isolated), model_mismatch, or one of the
  // monitored parameters.
  bool known = r.verdict == "none" || r.verdict == "detected" || r.verdict == "model_mismatch";
  for (const auto& e : r.estimates) known = known || (r.ok && e.name == r.verdict);
  if (!known)
    return fail("the verdict '" + r.verdict.substr(0, 40) +
                "' is not none, detected, model_mismatch or a monitored parameter");
  if (r.verdictTimeS && !(std::isfinite(*r.verdictTimeS) && *r.verdictTimeS >= 0.0))
    return fail("the verdict's time " + number(*r.verdictTimeS) + " s is not a time in the log");
  if (!(std::isfinite(r.seconds) && r.seconds >= 0.0)) return fail("the analysis time " + number(r.seconds) + " s is not a duration");
  if (!r.ok) return true;
  if (r.estimates.empty() || r.estimates.size() > 16) return fail("an analysed log needs 1 to 16 estimates");
  for (const auto& e : r.estimates) {
    if (e.name.empty() || e.name.size() > 32) return fail("an estimate has no name (or one longer than 32 characters)");
    if (!std::isfinite(e.value) || std::fabs(e.value) > 1e12)
      return fail("the estimate of " + e.name + " (" + number(e.value) + ") is not a finite value");
    if (!std::isfinite(e.reference) || std::fabs(e.reference) > 1e12)
      return fail("the reference value of " + e.name + " (" + number(e.reference) + ") is not a finite value");
    if (!(std::isfinite(e.std) && e.std > 0.0))
      return fail("the std of " + e.name + " (" + number(e.std) + ") is not a positive finite number");
  }
  return true;
}

DiagnosisReference fleetReference(const std::string& logPath, const FleetAnalysisOptions& options) {
  DiagnosisReference ref;
  const LogReadResult read = readLog(logPath);
  if (!read.ok) {
    ref.message = "the reference log cannot be read: " + read.error.toString();
    return ref;
  }
  ReferenceOptions ro;
  ro.fitPlant = false;
  const auto start = makeModel(options.model);
  return referenceFromLog(*start, read.data, options.diagnosis, ro);
}

json referenceToJson(const DiagnosisReference& r) {
  if (!r.nominal) throw std::invalid_argument("referenceToJson: the reference has no theta_0");
  return {{"nominal", modelToJson("theta_0", *r.nominal, {})},
          {"predictor", toString(r.predictor)},
          {"sigma0", r.sigma0},
          {"lambda0", r.noiseVariance},
          {"p0", r.p0},
          {"p0_single", r.p0Single},
          {"source", r.source}};
}

std::optional<DiagnosisReference> referenceFromJson(const json& j, std::string* why) {
  auto fail = [&](const std::string& s) -> std::optional<DiagnosisReference> {
    if (why) *why = s;
    return std::nullopt;
  };
  if (!j.is_object() || !j.contains("nominal")) return fail("a reference needs theta_0 ('nominal')");
  auto spec = modelFromJson(j["nominal"], why);
  if (!spec) return std::nullopt;
  DiagnosisReference r;
  r.nominal = spec->model;
  r.plant = spec->model;
  const auto p = j.contains("predictor") && j["predictor"].is_string()
                     ? diagnosisPredictorFromString(j["predictor"].get<std::string>())
                     : std::nullopt;
  if (!p || *p == DiagnosisPredictor::Auto) return fail("the reference's predictor must be loop or direct");
  r.predictor = *p;
  if (!readArray(j, "sigma0", r.sigma0, why) || !readArray(j, "p0", r.p0, why) ||
      !readArray(j, "p0_single", r.p0Single, why))
    return std::nullopt;
  if (!j.contains("lambda0") || !j["lambda0"].is_number()) return fail("the reference lacks lambda0");
  r.noiseVariance = j["lambda0"].get<double>();
  r.source = j.value("source", std::string());
  r.message = r.source;
  r.termination = Termination::Converged;
  return r;
}

FleetLogResult analyseFleetLog(const std::string& logPath, const DiagnosisReference& reference,
                               const FleetAnalysisOptions& options) {
  const auto begin = std::chrono::steady_clock::now();
  FleetLogResult out;
  auto finish = [&](std::string message) {
    out.message = std::move(message);
    out.seconds = secondsSince(begin);
    return out;
  };
  std::string why;
  const auto sha = sha256OfFile(logPath, &why);
  if (!sha) return finish(logPath + ": " + why);
  out.sha256 = *sha;
  const LogReadResult read = readLog(logPath);
  if (!read.ok) return finish(read.error.toString());
  if (!reference.ok()) return finish("the axis has no usable reference: " + reference.message);
  DiagnosisResult d;
  try {
    d = diagnose(reference, read.data, options.diagnosis);
  } catch (const std::invalid_argument& e) {
    return finish(logPath + ": " + e.what());
  }
  if (d.termination != Termination::Converged) return finish(logPath + ": " + d.message);
  const std::size_t n = d.time.size();
  const std::size_t from = std::min(n - 1, static_cast<std::size_t>(
                                               std::floor(static_cast<double>(n) * (1.0 - options.settledFraction))));
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    const auto& theta = d.estimates.theta[i];
    const auto& sigma = d.estimates.sigma[i];
    double mean = 0.0;
    for (std::size_t k = from; k < n; ++k) mean += theta[k];
    const double count = static_cast<double>(n - from);
    mean /= count;
    double spread = 0.0;
    for (std::size_t k = from; k < n; ++k) spread += (theta[k] - mean) * (theta[k] - mean);
    spread = std::sqrt(spread / std::max(1.0, count - 1.0));
    const auto& p = d.parameters[i];
    FleetEstimate e;
    e.name = p.modelName;
    e.value = p.toModel(mean);
    e.std = p.sigmaToModel(mean, std::max(sigma.back(), spread));
    e.reference = p.toModel(d.theta0[i]);
    if (!std::isfinite(e.value) || !std::isfinite(e.std))
      return finish(logPath + ": the estimate of " + e.name + " is not finite");
    if (!(e.std > 0.0))
      return finish(logPath + ": the log does not determine " + e.name + " (its std is 0)");
    out.estimates.push_back(e);
  }
  out.verdict = d.verdictName();
  out.verdictTimeS = d.verdictTime();
  out.ok = true;
  return finish(d.summary());
}

json fleetLogResultJson(const FleetLogResult& r) {
  json est = json::array();
  for (const auto& e : r.estimates)
    est.push_back({{"name", e.name}, {"value", e.value}, {"std", e.std}, {"reference", e.reference}});
  return {{"sha256", r.sha256},
          {"reference_sha256", r.referenceSha256},
          {"ok", r.ok},
          {"message", r.message},
          {"verdict", r.verdict},
          {"verdict_time_s", r.verdictTimeS ? json(*r.verdictTimeS) : json(nullptr)},
          {"estimates", est},
          {"seconds", r.seconds}};
}

std::optional<FleetLogResult> fleetLogResultFromJson(const json& j, std::string* why) {
  auto fail = [&](const std::string& s) -> std::optional<FleetLogResult> {
    if (why) *why = s;
    return std::nullopt;
  };
  try {
    FleetLogResult r;
    r.sha256 = j.at("sha256").get<std::string>();
    r.referenceSha256 = j.at("reference_sha256").get<std::string>();
    r.ok = j.at("ok").get<bool>();
    r.message = j.at("message").get<std::string>();
    r.verdict = j.at("verdict").get<std::string>();
    if (!j.at("verdict_time_s").is_null()) r.verdictTimeS = j.at("verdict_time_s").get<double>();
    for (const auto& e : j.at("estimates"))
      r.estimates.push_back({e.at("name").get<std::string>(), e.at("value").get<double>(),
                             e.at("std").get<double>(), e.at("reference").get<double>()});
    r.seconds = j.at("seconds").get<double>();
    return r;
  } catch (const json::exception& e) {
    return fail(std::string("a log result is malformed: ") + jsonErrorText(e));
  }
}

}  // namespace flexarm
