#include "core/session/discovery_part.h"

#include "core/common/text.h"
#include "core/discovery/discovery_json.h"

#include <cmath>

#include "core/session/fit_request.h"
#include "core/session/json_fields.h"
#include "core/session/model_json.h"

namespace flexarm {

using nlohmann::json;

namespace {

const char* kStructures[] = {"two-mass", "three-mass", "four-mass"};


// The effect names listed under key, if the key is there (else out is left as it is); false
// with a sentence when the value is not a list or names an unknown effect.
bool readEffectList(const json& j, const char* key, const char* notList, const char* unknown,
                    std::vector<EffectKind>& out, std::string* why, const std::string& where) {
  if (!j.contains(key)) return true;
  if (!j[key].is_array()) {
    if (why) *why = where + notList;
    return false;
  }
  out.clear();
  for (const auto& e : j[key]) {
    auto k = e.is_string() ? effectKindFromString(e.get<std::string>()) : std::nullopt;
    if (!k) {
      if (why) *why = where + unknown + e.dump();
      return false;
    }
    out.push_back(*k);
  }
  return true;
}

// Effects written as `flexarm fit --effect` takes them ("backlash:0.0002"), if the key is there.
bool readEffects(const json& j, const char* key, std::vector<Effect>& out, std::string* why, const std::string& where) {
  if (!j.contains(key)) return true;
  if (!j[key].is_array()) {
    if (why) *why = where + key + " must be a list of effects";
    return false;
  }
  out.clear();
  for (const auto& e : j[key]) {
    std::string reason;
    auto effect = e.is_string() ? parseEffect(e.get<std::string>(), &reason) : std::nullopt;
    if (!effect) {
      if (why) *why = where + key + ": " + (e.is_string() ? reason : "each effect must be text, not " + e.dump());
      return false;
    }
    out.push_back(*effect);
  }
  return true;
}

json dataRefToJson(const DiscoveryDataRef& d) {
  return {{"log", d.log}, {"range_s", secondsRangeToJson(d.range)}};
}

bool dataRefFromJson(const json& j, DiscoveryDataRef& d, std::string* why, const std::string& where) {
  if (!j.is_object()) {
    if (why) *why = where + "must be an object with log and range_s";
    return false;
  }
  std::string reason;
  if (!readText(j, "log", d.log, false, why, where)) return false;
  if (!readSecondsRange(j, "range_s", d.range, &reason)) {
    if (why) *why = where + reason;
    return false;
  }
  return true;
}

bool scoreFromJson(const json& j, DiscoveryScore& s, std::string* why, const std::string& where) {
  if (!j.is_object()) {
    if (why) *why = where + "must be an object";
    return false;
  }
  return readNumber(j, "fit_percent", s.fitPercent, true, why, where) &&
         readNumber(j, "fit_percent_validation", s.fitPercentValidation, true, why, where) &&
         readNumber(j, "fit_percent_nrmse", s.fitPercentNrmse, false, why, where) &&
         readNumber(j, "fit_percent_validation_nrmse", s.fitPercentValidationNrmse, false, why, where) &&
         readNumber(j, "rms_estimation", s.rmsEstimation, true, why, where) &&
         readNumber(j, "rms_validation", s.rmsValidation, true, why, where);
}

bool parametersFromJson(const json& j, std::vector<EffectParameterEstimate>& ps, std::string* why,
                        const std::string& where) {
  if (!j.is_array()) {
    if (why) *why = where + "parameters must be a list";
    return false;
  }
  for (const auto& p : j) {
    EffectParameterEstimate e;
    if (!p.is_object() || !readText(p, "name", e.name, true, why, where + "parameter ") ||
        !readText(p, "unit", e.unit, false, why, where) ||
        !readNumber(p, "value", e.value, true, why, where) ||
        !readNumber(p, "std", e.std, true, why, where) ||
        !readNumber(p, "lower", e.lower, true, why, where) ||
        !readNumber(p, "upper", e.upper, true, why, where) ||
        !readFlag(p, "estimated", e.estimated, why, where) || !readFlag(p, "derived", e.derived, why, where)) {
      if (why && !p.is_object()) *why = where + "each parameter must be an object";
      return false;
    }
    ps.push_back(e);
  }
  return true;
}

// One estimate under key (absent: left as it is).
bool readEstimate(const json& j, const char* key, EffectParameterEstimate& p, std::string* why, const std::string& where) {
  if (!j.contains(key) || j[key].is_null()) return true;
  std::vector<EffectParameterEstimate> one;
  if (!parametersFromJson(json::array({j[key]}), one, why, where + key + ": ")) return false;
  p = one.front();
  return true;
}

bool readSize(const json& j, EffectSize& s, std::string* why, const std::string& where) {
  if (!j.contains("size") || j["size"].is_null()) return true;
  const json& z = j["size"];
  if (!z.is_object()) {
    if (why) *why = where + "size must be an object";
    return false;
  }
  return readNumber(z, "torque_rms", s.torqueRms, false, why, where) &&
         readNumber(z, "friction_rms", s.frictionRms, false, why, where) &&
         readNumber(z, "spring_rms", s.springRms, false, why, where);
}

// A confirmation: an object (as discoveryResultJson writes it) or, in sessions stored before
// it, its text alone.
bool readConfirmation(const json& j, Confirmation& c, std::string* why, const std::string& where) {
  if (!j.contains("confirmation") || j["confirmation"].is_null()) return true;
  const json& x = j["confirmation"];
  if (x.is_string()) {
    c.text = x.get<std::string>();
    c.ran = !c.text.empty();
    return true;
  }
  if (!x.is_object()) {
    if (why) *why = where + "confirmation must be an object";
    return false;
  }
  const std::string cw = where + "confirmation: ";
  if (!readFlag(x, "ran", c.ran, why, cw) || !readFlag(x, "confirmed", c.confirmed, why, cw) ||
      !readText(x, "held_out_data", c.heldOutData, false, why, cw) ||
      !readNumber(x, "rms_before", c.rmsBefore, false, why, cw) ||
      !readNumber(x, "rms_after", c.rmsAfter, false, why, cw) ||
      !readNumber(x, "held_out_z", c.heldOutZ, false, why, cw) ||
      !readFlag(x, "held_out_passes", c.heldOutPasses, why, cw) || !readText(x, "test", c.test, false, why, cw) ||
      !readNumber(x, "value", c.value, false, why, cw) || !readNumber(x, "std", c.std, false, why, cw) ||
      !readNumber(x, "z", c.z, false, why, cw) || !readNumber(x, "fitted", c.fitted, false, why, cw) ||
      !readText(x, "unit", c.unit, false, why, cw) || !readFlag(x, "specific_passes", c.specificPasses, why, cw) ||
      !readText(x, "text", c.text, false, why, cw))
    return false;
  if (x.contains("rivals") && x["rivals"].is_array())
    for (const auto& r : x["rivals"])
      if (r.is_string()) c.rivals.push_back(r.get<std::string>());
  return true;
}

std::string describeData(const DiscoveryDataRef& d, const std::string& firstLog) {
  std::string text = "log '" + (d.log.empty() ? firstLog : d.log) + "'";
  if (d.range)
    text += ", " + formatSignificant(d.range->start, 6) + "-" + formatSignificant(d.range->end, 6) + " s";
  else
    text += ", whole log";
  return text;
}

// The chosen data set, or a sentence why there is none.
std::optional<IdData> pickData(const DiscoveryDataRef& ref, bool raw, const ReplayContext& context,
                               std::string* why) {
  const IdData* d = findLog(context, ref.log, raw, why);
  if (!d) return std::nullopt;
  if (!ref.range) return *d;
  const SampleRange r = d->rangeForTimes(ref.range->start, ref.range->end);
  if (r.size() < 10) {
    *why = "the range " + formatSignificant(ref.range->start) + "-" + formatSignificant(ref.range->end) +
           " s holds " + std::to_string(r.size()) + " samples of log " + inQuotes(ref.log);
    return std::nullopt;
  }
  return d->select(r);
}

std::unique_ptr<PhysicalModel> pickBase(const DiscoveryRequest& q, const Session& session,
                                        std::string* why) {
  if (q.baseModel.empty()) return makeModel(q.baseStructure);
  const auto spec = findListModel(session.parts.value("models", json::array()), q.baseModel, why);
  if (!spec) return nullptr;
  // Its effects, if any, are the request's start effects (stored with it).
  auto c = spec->model->clone();
  return std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(c.release()));
}

ReportSeries series(const std::string& name, const std::vector<double>& t, std::vector<double> y,
                    bool dashed, int color) {
  ReportSeries s{name, t, std::move(y), dashed, color};
  thinSeries(s.x, s.y, 3000);
  return s;
}

std::vector<double> difference(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> d(std::min(a.size(), b.size()));
  for (std::size_t k = 0; k < d.size(); ++k) d[k] = a[k] - b[k];
  return d;
}

class DiscoveryPart : public SessionPart {
 public:
  std::string key() const override { return "discovery"; }

  bool validate(const json& section, std::string* why) const override {
    if (!section.is_object() || !section.contains("request")) {
      if (why) *why = "must be an object with a request";
      return false;
    }
    if (!discoveryRequestFromJson(section["request"], why)) return false;
    if (section.contains("result") && !section["result"].is_null() &&
        !discoveryResultFromJson(section["result"], why))
      return false;
    return true;
  }

  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    std::string why;
    auto request = discoveryRequestFromJson(section["request"], &why);
    if (!request) return;  // validated on load
    ReportSection s;
    s.title = "Discovery: the missing effect";
    const std::string firstLog = context.session.logs.empty() ? "" : context.session.logs.front().name;
    const std::string baseName = request->baseModel.empty() ? request->baseStructure + " (nominal)"
                                                            : request->baseModel;
    std::string dataText = "Base model " + baseName + ". Estimation data: " +
                           describeData(request->estimation, firstLog);
    if (request->validation)
      dataText += "; validation data: " + describeData(*request->validation, firstLog);
    dataText += request->rawData ? " (as read)." : " (preprocessed as the session says).";
    s.paragraphs.push_back(dataText);
    std::string candidates;
    for (EffectKind k : request->options.candidates)
      candidates += (candidates.empty() ? "" : ", ") + std::string(toString(k));
    std::string start;
    for (const Effect& e : request->options.startEffects) start += (start.empty() ? "" : ", ") + toString(e);
    s.paragraphs.push_back("Candidates tested: " + candidates + (start.empty() ? "" : "; the base starts with " + start) +
                           (request->options.maxEffects > 1
                                ? "; the loop looks for up to " + std::to_string(request->options.maxEffects) +
                                      " effects, refitting the base and every effect found after each"
                                : std::string()) +
                           ". An effect is named only when the F-test of its parameters passes, the AIC falls, "
                           "its parameter's " + formatSignificant(100.0 * request->options.level, 3) +
                           " % interval excludes zero and the residual on held-out data falls significantly; "
                           "it is confirmed when a second test, specific to the effect, agrees on held-out data.");
    s.values = {{"base_model", baseName}};
    auto fail = [&](const std::string& text) {
      report.warnings.push_back("discovery: could not run: " + text);  // e.g. a log the session lacks
      s.paragraphs.push_back("Discovery could not run: " + text + ".");
      s.values["effect"] = nullptr;
      s.values["message"] = text;
      report.sections.push_back(s);
    };
    auto base = pickBase(*request, context.session, &why);
    if (!base) return fail(why);
    auto est = pickData(request->estimation, request->rawData, context, &why);
    if (!est) return fail("estimation data: " + why);
    std::optional<IdData> val;
    if (request->validation) {
      val = pickData(*request->validation, request->rawData, context, &why);
      if (!val) return fail("validation data: " + why);
    }
    DiscoveryResult r;
    try {
      r = discoverMissingEffect(*base, *est, val ? &*val : nullptr, request->options, context.progress);
    } catch (const std::invalid_argument& e) {
      return fail(e.what());
    }
    if (r.termination == Termination::Failed || r.termination == Termination::Cancelled)
      return fail(r.message.empty() ? toString(r.termination) : r.message);
    fillSection(r, s);
    if (section.contains("result") && section["result"].is_object()) {
      auto stored = discoveryResultFromJson(section["result"], &why);
      if (stored && stored->effect != r.effect) {
        const std::string was = stored->effect ? toString(*stored->effect) : "none";
        const std::string now = r.effect ? toString(*r.effect) : "none";
        s.paragraphs.push_back("The session recorded the effect " + was + "; this replay names " + now + ".");
        report.warnings.push_back("discovery: the session recorded " + was + ", the replay names " + now);
      }
      s.values["stored_effect"] = stored && stored->effect ? json(toString(*stored->effect)) : json("none");
    }
    report.sections.push_back(s);
  }

  // Discovery run on other data: the stored result, not a run on the open log.
  void replayStored(const json& section, const std::string& mismatch, Report& report) const override {
    ReportSection s;
    s.title = "Discovery: the missing effect";
    s.paragraphs.push_back("Not recomputed on the open data: this discovery was " + mismatch +
                           ". The verdict below is the one stored when it ran.");
    std::string why;
    std::optional<DiscoveryResult> stored;
    if (section.contains("result") && section["result"].is_object())
      stored = discoveryResultFromJson(section["result"], &why);
    if (stored) fillSection(*stored, s);
    else s.paragraphs.push_back("The session stored no result of this run.");
    s.values["recomputed"] = false;
    s.values["computed_on"] = section["provenance"];
    report.sections.push_back(s);
    report.warnings.push_back("discovery was " + mismatch);
  }

 private:
  static void fillSection(const DiscoveryResult& r, ReportSection& s) {
    const std::string effect = r.effect ? toString(*r.effect) : "none";
    std::string verdict = r.effect ? "Verdict: the missing effect is " + effect + "."
                                   : "Verdict: none of the candidates is significant; the missing effect is none.";
    if (!r.tied.empty()) {
      std::string t;
      for (EffectKind k : r.tied) t += (t.empty() ? "" : ", ") + std::string(toString(k));
      verdict += " It ties with " + t + ".";
    }
    s.paragraphs.push_back(verdict);
    s.paragraphs.push_back("Evidence: " + r.evidence);
    if (r.found.size() > 1 || (!r.found.empty() && !r.stopReason.empty())) {
      // The ladder: the held-out residual and fit % of the base and after every effect.
      ReportTable ladder{"The gap step by step (held-out data: " + r.validationData + ")",
                         {"Step", "Model", "Fit % val.", "RMS val. (rad/s)", "Confirmed"}, {}};
      ladder.rows.push_back({"0", "base", formatFixed(r.found.front().before.fitPercentValidation, 2),
                             formatSignificant(r.found.front().before.rmsValidation), "-"});
      std::string model = "base";
      for (std::size_t i = 0; i < r.found.size(); ++i) {
        const FoundEffect& f = r.found[i];
        model += " + " + std::string(toString(f.kind));
        ladder.rows.push_back({std::to_string(i + 1), model, formatFixed(f.after.fitPercentValidation, 2),
                               formatSignificant(f.after.rmsValidation), f.confirmation.confirmed ? "yes" : "no"});
        if (!f.confirmation.text.empty())
          s.paragraphs.push_back(std::string(toString(f.kind)) + ": " + f.confirmation.text);
      }
      s.tables.push_back(ladder);
    }
    if (!r.alsoTried.empty()) {
      // What was tried and rejected, apart from the effects found.
      ReportTable tried{"Also tried (not named)", {"Round", "Effect", "Size", "Torque share", "Why not"}, {}};
      for (const auto& t : r.alsoTried)
        tried.rows.push_back({std::to_string(t.round + 1), toString(t.kind),
                              t.magnitude.name.empty() ? "-" : t.magnitude.name + " = " + formatSignificant(t.magnitude.value),
                              t.size.measured() ? formatFixed(100.0 * t.size.share(), 2) + " %" : "-", t.reason});
      s.tables.push_back(tried);
    }
    if (!r.disagreement.summary.empty())
      s.paragraphs.push_back("Where the base model disagrees: " + r.disagreement.summary);

    const CandidateFit* best = r.best >= 0 ? &r.candidates[static_cast<std::size_t>(r.best)] : nullptr;
    if (best) {
      ReportTable t{"Parameters of " + effect + " (99 % interval)",
                    {"Parameter", "Value", "Std", "Lower", "Upper", "Unit"}, {}};
      for (const auto& p : best->parameters) {
        t.rows.push_back({p.name, formatSignificant(p.value), p.estimated ? formatSignificant(p.std, 3) : "held",
                          formatSignificant(p.lower), formatSignificant(p.upper), p.unit});
      }
      s.tables.push_back(t);
    }
    ReportTable cand{"Candidates", {"Effect", "Loss (est.)", "RMS val. (rad/s)", "AIC - base", "F / threshold",
                                    "Significant", "Reason"}, {}};
    for (const auto& c : r.candidates) {
      cand.rows.push_back({toString(c.kind), formatSignificant(c.lossEst),
                           r.hasValidation ? formatSignificant(c.score.rmsValidation) : "-",
                           std::isfinite(c.aic) ? formatFixed(c.aic - r.baseAic, 1) : "-",
                           formatSignificant(c.fStatistic, 3) + " / " + formatSignificant(c.fThreshold, 3),
                           c.significant ? "yes" : "no", c.reason});
    }
    s.tables.push_back(cand);

    ReportTable cmp{"Base and augmented model: fit % (5.2) and residual RMS",
                    {"Model", "Fit % est.", "Fit % val.", "RMS est. (rad/s)", "RMS val. (rad/s)"}, {}};
    auto row = [&](const std::string& name, const DiscoveryScore& sc) {
      cmp.rows.push_back({name, formatFixed(sc.fitPercent, 2),
                          r.hasValidation ? formatFixed(sc.fitPercentValidation, 2) : "-",
                          formatSignificant(sc.rmsEstimation),
                          r.hasValidation ? formatSignificant(sc.rmsValidation) : "-"});
    };
    row("base", r.base);
    std::string all;
    for (const auto& f : r.found) all += " + " + std::string(toString(f.kind));
    row(all.empty() ? "augmented (= base)" : "base" + all, r.augmented);
    s.tables.push_back(cmp);
    if (r.hasValidation && r.base.rmsValidation > 0.0)
      s.paragraphs.push_back("The validation residual RMS falls from " + formatSignificant(r.base.rmsValidation) +
                             " to " + formatSignificant(r.augmented.rmsValidation) + " rad/s (" +
                             formatFixed(100.0 * (1.0 - r.augmented.rmsValidation / r.base.rmsValidation), 0) +
                             " % lower).");

    // The data: the result as every output writes it (discoveryResultJson).
    const json result = discoveryResultJson(r);
    for (auto it = result.begin(); it != result.end(); ++it) s.values[it.key()] = it.value();

    const DiscoveryTrace& t = r.hasValidation ? r.validation : r.estimation;
    const std::string where = r.hasValidation ? "validation" : "estimation";
    if (t.time.empty()) return;
    const std::string augName = r.effect ? "base + " + effect : "augmented (= base)";
    s.plots.push_back(ReportPlot{"Motor velocity on the " + where + " data, before and after",
                                 "time (s)", "motor velocity (rad/s)", false, false,
                                 {series("measured", t.time, t.measured, false, 0),
                                  series("base", t.time, t.base, true, 1),
                                  series(augName, t.time, t.augmented, false, 2)}});
    s.plots.push_back(ReportPlot{"Residual on the " + where + " data, before and after", "time (s)",
                                 "residual (rad/s)", false, false,
                                 {series("base", t.time, difference(t.measured, t.base), false, 1),
                                  series(augName, t.time, difference(t.measured, t.augmented), false, 2)}});
  }
};

}  // namespace

bool DiscoveryRequest::isValid(std::string* why) const {
  if (baseModel.empty()) {
    bool known = false;
    for (const char* s : kStructures) known = known || baseStructure == s;
    if (!known) {
      if (why) *why = "the base structure must be two-mass, three-mass or four-mass, not " + inQuotes(baseStructure);
      return false;
    }
  }
  return options.isValid(why);
}

json discoveryRequestToJson(const DiscoveryRequest& q) {
  json j = json::object();
  if (q.baseModel.empty()) j["base_structure"] = q.baseStructure;
  else j["base_model"] = q.baseModel;
  j["data"] = q.rawData ? "as-read" : "preprocessed";
  j["estimation"] = dataRefToJson(q.estimation);
  j["validation"] = q.validation ? dataRefToJson(*q.validation) : json(nullptr);
  json candidates = json::array();
  for (EffectKind k : q.options.candidates) candidates.push_back(toString(k));
  json startEffects = json::array();
  for (const Effect& e : q.options.startEffects) startEffects.push_back(toString(e));
  const DiscoveryOptions& o = q.options;
  j["options"] = {{"candidates", candidates},
                  {"observer_bandwidth_hz", o.observerBandwidthHz},
                  {"max_rate_hz", o.maxRateHz},
                  {"substeps", o.substeps},
                  {"base_iterations", o.baseIterations},
                  {"candidate_iterations", o.candidateIterations},
                  {"level", o.level},
                  {"min_validation_improvement", o.minValidationImprovement},
                  {"tie_tolerance", o.tieTolerance},
                  {"held_out_fraction", o.heldOutFraction},
                  {"max_effects", o.maxEffects},
                  {"start_effects", startEffects},
                  {"threads", o.threads}};
  return j;
}

std::optional<DiscoveryRequest> discoveryRequestFromJson(const json& j, std::string* why) {
  const std::string where = "the discovery request: ";
  if (!j.is_object()) {
    if (why) *why = where + "must be an object";
    return std::nullopt;
  }
  DiscoveryRequest q;
  if (!readText(j, "base_model", q.baseModel, false, why, where) ||
      !readText(j, "base_structure", q.baseStructure, false, why, where))
    return std::nullopt;
  if (q.baseModel.empty() == q.baseStructure.empty()) {
    if (why) *why = where + "give either base_model (a model of the list) or base_structure";
    return std::nullopt;
  }
  std::string data = "preprocessed";
  if (!readText(j, "data", data, false, why, where)) return std::nullopt;
  if (data != "preprocessed" && data != "as-read") {
    if (why) *why = where + "data must be \"preprocessed\" or \"as-read\", not " + inQuotes(data);
    return std::nullopt;
  }
  q.rawData = data == "as-read";
  if (!j.contains("estimation")) {
    if (why) *why = where + "estimation is missing";
    return std::nullopt;
  }
  if (!dataRefFromJson(j["estimation"], q.estimation, why, where + "estimation: ")) return std::nullopt;
  if (j.contains("validation") && !j["validation"].is_null()) {
    q.validation.emplace();
    if (!dataRefFromJson(j["validation"], *q.validation, why, where + "validation: ")) return std::nullopt;
  }
  if (j.contains("options")) {
    const json& o = j["options"];
    const std::string ow = where + "options: ";
    if (!o.is_object()) {
      if (why) *why = ow + "must be an object";
      return std::nullopt;
    }
    DiscoveryOptions& d = q.options;
    if (!readEffectList(o, "candidates", "candidates must be a list of effect names",
                        "unknown candidate effect ", d.candidates, why, ow))
      return std::nullopt;
    if (!readNumber(o, "observer_bandwidth_hz", d.observerBandwidthHz, false, why, ow) ||
        !readNumber(o, "max_rate_hz", d.maxRateHz, false, why, ow) ||
        !readWhole(o, "substeps", d.substeps, why, ow) ||
        !readWhole(o, "base_iterations", d.baseIterations, why, ow) ||
        !readWhole(o, "candidate_iterations", d.candidateIterations, why, ow) ||
        !readNumber(o, "level", d.level, false, why, ow) ||
        !readNumber(o, "min_validation_improvement", d.minValidationImprovement, false, why, ow) ||
        !readNumber(o, "tie_tolerance", d.tieTolerance, false, why, ow) ||
        !readNumber(o, "held_out_fraction", d.heldOutFraction, false, why, ow) ||
        !readWhole(o, "max_effects", d.maxEffects, why, ow) ||
        !readWhole(o, "threads", d.threads, why, ow) || !readEffects(o, "start_effects", d.startEffects, why, ow))
      return std::nullopt;
  }
  std::string reason;
  if (!q.isValid(&reason)) {
    if (why) *why = where + reason;
    return std::nullopt;
  }
  return q;
}

json discoveryResultToJson(const DiscoveryResult& r) { return discoveryResultJson(r); }

namespace {

// The candidates listed under "candidates" (required).
bool candidatesFromJson(const json& j, std::vector<CandidateFit>& out, std::string* why, const std::string& where) {
  if (!j.contains("candidates") || !j["candidates"].is_array()) {
    if (why) *why = where + "candidates must be a list";
    return false;
  }
  for (const auto& c : j["candidates"]) {
    CandidateFit f;
    std::string name, spec, termination;
    const std::string cw = where + "candidate: ";
    if (!c.is_object() || !readText(c, "effect", name, true, why, cw)) {
      if (why && !c.is_object()) *why = cw + "must be an object";
      return false;
    }
    auto k = effectKindFromString(name);
    if (!k) {
      if (why) *why = cw + "unknown effect " + inQuotes(name);
      return false;
    }
    f.kind = *k;
    f.termination = Termination::Converged;
    if ((c.contains("parameters") && !parametersFromJson(c["parameters"], f.parameters, why, cw)) ||
        !(c.contains("spec") && c["spec"].is_null() ? true : readText(c, "spec", spec, false, why, cw)) ||
        !readText(c, "termination", termination, false, why, cw) ||
        !readWhole(c, "parameter_count", f.parameterCount, why, cw) ||
        !readNumber(c, "loss_est", f.lossEst, true, why, cw) ||
        !readNumber(c, "aic", f.aic, false, why, cw) || !readNumber(c, "f", f.fStatistic, false, why, cw) ||
        !readNumber(c, "f_threshold", f.fThreshold, false, why, cw) ||
        !readNumber(c, "held_out_z", f.heldOutZ, false, why, cw) || !readNumber(c, "rho", f.rho, false, why, cw) ||
        !readNumber(c, "survival_f", f.survivalF, false, why, cw) ||
        !readFlag(c, "interval_excludes_zero", f.intervalExcludesZero, why, cw) ||
        !readFlag(c, "significant", f.significant, why, cw) || !readText(c, "reason", f.reason, false, why, cw) ||
        !readFlag(c, "matters", f.matters, why, cw) || !readEstimate(c, "magnitude", f.magnitude, why, cw) ||
        !readSize(c, f.size, why, cw) || !readConfirmation(c, f.confirmation, why, cw) ||
        (c.contains("score") && !scoreFromJson(c["score"], f.score, why, cw + "score: ")))
      return false;
    if (!termination.empty())
      if (const auto t = terminationFromString(termination)) f.termination = *t;
    std::string reason;
    if (!spec.empty())
      if (auto e = parseEffect(spec, &reason)) f.effect = *e;
    out.push_back(f);
  }
  return true;
}

}  // namespace

std::optional<DiscoveryResult> discoveryResultFromJson(const json& j, std::string* why) {
  const std::string where = "the discovery result: ";
  if (!j.is_object()) {
    if (why) *why = where + "must be an object";
    return std::nullopt;
  }
  DiscoveryResult r;
  r.termination = Termination::Converged;
  std::string effect;
  if (!readText(j, "effect", effect, true, why, where)) return std::nullopt;
  if (effect != "none") {
    r.effect = effectKindFromString(effect);
    if (!r.effect) {
      if (why) *why = where + "unknown effect " + inQuotes(effect);
      return std::nullopt;
    }
  }
  if (!readEffectList(j, "tied", "tied must be a list", "unknown tied effect ", r.tied, why,
                      where) ||
      !readText(j, "stop_reason", r.stopReason, false, why, where) ||
      !readText(j, "validation_data", r.validationData, false, why, where) ||
      !readText(j, "fit_basis", r.fitBasis, false, why, where))
    return std::nullopt;
  if (j.contains("effects")) {
    if (!j["effects"].is_array()) {
      if (why) *why = where + "effects must be a list";
      return std::nullopt;
    }
    for (const auto& e : j["effects"]) {
      const std::string ew = where + "found effect: ";
      FoundEffect f;
      std::string spec, reason;
      if (!e.is_object() || !readText(e, "spec", spec, true, why, ew)) {
        if (why && !e.is_object()) *why = ew + "must be an object";
        return std::nullopt;
      }
      auto parsed = parseEffect(spec, &reason);
      if (!parsed) {
        if (why) *why = ew + reason;
        return std::nullopt;
      }
      f.kind = parsed->kind;
      f.effect = *parsed;
      if ((e.contains("parameters") && !parametersFromJson(e["parameters"], f.parameters, why, ew)) ||
          !readText(e, "evidence", f.evidence, false, why, ew) ||
          !readFlag(e, "confirmed", f.confirmation.confirmed, why, ew) ||
          !readConfirmation(e, f.confirmation, why, ew) ||
          !readEstimate(e, "magnitude", f.magnitude, why, ew) || !readSize(e, f.size, why, ew) ||
          (e.contains("before") && !scoreFromJson(e["before"], f.before, why, ew + "before: ")) ||
          (e.contains("after") && !scoreFromJson(e["after"], f.after, why, ew + "after: ")))
        return std::nullopt;
      r.found.push_back(std::move(f));
    }
  }
  // The disagreement: an object with its summary (sessions stored before: the summary).
  const bool disagreementObject = j.contains("disagreement") && j["disagreement"].is_object();
  if (!readText(j, "evidence", r.evidence, false, why, where) ||
      (disagreementObject ? !readText(j["disagreement"], "summary", r.disagreement.summary, false, why, where)
                          : !readText(j, "disagreement", r.disagreement.summary, false, why, where)) ||
      !readFlag(j, "has_validation", r.hasValidation, why, where) ||
      !readFlag(j, "held_out_split", r.heldOutSplit, why, where) ||
      !readNumber(j, "sample_time", r.sampleTime, false, why, where) ||
      !readNumber(j, "seconds", r.seconds, false, why, where) ||
      !readNumber(j, "base_loss", r.baseLoss, false, why, where) ||
      !readNumber(j, "base_aic", r.baseAic, false, why, where) ||
      !readWhole(j, "best", r.best, why, where))
    return std::nullopt;
  if (j.contains("base") && j["base"].is_object() &&
      (!readNumber(j["base"], "loss", r.baseLoss, false, why, where + "base: ") ||
       !readNumber(j["base"], "aic", r.baseAic, false, why, where + "base: ")))
    return std::nullopt;
  if (j.contains("also_tried") && j["also_tried"].is_array())
    for (const auto& t : j["also_tried"]) {
      DiscoveryResult::Rejected x;
      std::string name, spec;
      const std::string tw = where + "also tried: ";
      if (!t.is_object() || !readText(t, "effect", name, true, why, tw) ||
          !(t.contains("spec") && t["spec"].is_null() ? true : readText(t, "spec", spec, false, why, tw)) ||
          !readWhole(t, "round", x.round, why, tw) || !readText(t, "reason", x.reason, false, why, tw) ||
          !readEstimate(t, "magnitude", x.magnitude, why, tw) || !readSize(t, x.size, why, tw))
        return std::nullopt;
      const auto k = effectKindFromString(name);
      if (!k) {
        if (why) *why = tw + "unknown effect " + inQuotes(name);
        return std::nullopt;
      }
      x.kind = *k;
      std::string reason;
      if (!spec.empty())
        if (auto e = parseEffect(spec, &reason)) x.effect = *e;
      r.alsoTried.push_back(std::move(x));
    }
  if (!j.contains("base") || !scoreFromJson(j["base"], r.base, why, where + "base: ") ||
      !j.contains("augmented") || !scoreFromJson(j["augmented"], r.augmented, why, where + "augmented: ")) {
    if (why && (!j.contains("base") || !j.contains("augmented"))) *why = where + "base and augmented scores are needed";
    return std::nullopt;
  }
  if (!candidatesFromJson(j, r.candidates, why, where)) return std::nullopt;
  // The run's end, the final model's effects, every round.
  std::string termination;
  if (!readText(j, "termination", termination, false, why, where) ||
      !readText(j, "message", r.message, false, why, where))
    return std::nullopt;
  if (!termination.empty()) {
    const auto t = terminationFromString(termination);
    if (!t) {
      if (why) *why = where + "unknown termination " + inQuotes(termination);
      return std::nullopt;
    }
    r.termination = *t;
  }
  if (j["base"].contains("parameter_count") && !readWhole(j["base"], "parameter_count", r.baseParameterCount, why, where))
    return std::nullopt;
  if (j["augmented"].contains("effects") && !readEffects(j["augmented"], "effects", r.augmentedEffects, why, where))
    return std::nullopt;
  if (disagreementObject) {
    const json& d = j["disagreement"];
    const std::string dw = where + "disagreement: ";
    if (!readFlag(d, "white", r.disagreement.tests.white, why, dw) ||
        !readFlag(d, "independent", r.disagreement.tests.independent, why, dw) ||
        !readNumber(d, "residual_peak_rad_s", r.disagreement.spectrumPeakRadS, false, why, dw) ||
        !readNumber(d, "correlation_sign_velocity", r.disagreement.correlationSignVelocity, false, why, dw) ||
        !readNumber(d, "rms_low_speed", r.disagreement.rmsLowSpeed, false, why, dw) ||
        !readNumber(d, "rms_high_speed", r.disagreement.rmsHighSpeed, false, why, dw))
      return std::nullopt;
    if (d.contains("resonances_rad_s") && d["resonances_rad_s"].is_array())
      for (const auto& w : d["resonances_rad_s"])
        if (w.is_number()) r.disagreement.resonancesRadS.push_back(w.get<double>());
  }
  if (j.contains("rounds") && j["rounds"].is_array())
    for (const auto& d : j["rounds"]) {
      DiscoveryRound round;
      const std::string rw = where + "round: ";
      std::string named;
      if (!d.is_object() || !readEffects(d, "effects", round.effects, why, rw) ||
          !readText(d, "effect", named, false, why, rw) || !readWhole(d, "best", round.best, why, rw) ||
          !readText(d, "decision", round.decision, false, why, rw) ||
          !readText(d, "evidence", round.evidence, false, why, rw) ||
          !readEffectList(d, "tied", "tied must be a list", "unknown tied effect ", round.tied, why, rw) ||
          !readNumber(d, "aic", round.aic, false, why, rw) ||
          (d.contains("score") && !scoreFromJson(d["score"], round.score, why, rw + "score: ")) ||
          !candidatesFromJson(d, round.candidates, why, rw))
        return std::nullopt;
      if (!named.empty() && named != "none") round.effect = effectKindFromString(named);
      r.rounds.push_back(std::move(round));
    }
  if (r.best < -1 || r.best >= static_cast<int>(r.candidates.size())) {
    if (why) *why = where + "best must index a candidate (or be -1)";
    return std::nullopt;
  }
  // The named candidate's confirmation is the first effect's, stored with it.
  // (sessions stored before candidates kept their own).
  if (r.best >= 0 && !r.found.empty() && r.found.front().kind == r.candidates[static_cast<std::size_t>(r.best)].kind &&
      !r.candidates[static_cast<std::size_t>(r.best)].confirmation.ran)
    r.candidates[static_cast<std::size_t>(r.best)].confirmation = r.found.front().confirmation;
  return r;
}

std::shared_ptr<const SessionPart> makeDiscoveryPart() { return std::make_shared<DiscoveryPart>(); }

}  // namespace flexarm
