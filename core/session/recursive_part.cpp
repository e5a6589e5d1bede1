#include "core/session/recursive_part.h"

#include <cmath>

#include "core/common/text.h"
#include "core/session/fit_request.h"
#include "core/session/model_json.h"
#include "core/session/report.h"

namespace flexarm {

using nlohmann::json;

namespace {

json numbers(const std::vector<double>& v) { return json(v); }

bool readNumbers(const json& j, const char* key, std::vector<double>& out, std::string* why) {
  if (!j.contains(key)) return true;
  out.clear();
  if (!j[key].is_array()) {
    *why = std::string(key) + " must be a list of numbers";
    return false;
  }
  for (const auto& v : j[key]) {
    if (!v.is_number()) {
      *why = std::string(key) + " must be a list of numbers";
      return false;
    }
    out.push_back(v.get<double>());
  }
  return true;
}

bool readNames(const json& j, const char* key, std::vector<std::string>& out, std::string* why) {
  if (!j.contains(key)) return true;
  out.clear();
  if (!j[key].is_array()) {
    *why = std::string(key) + " must be a list of names";
    return false;
  }
  for (const auto& v : j[key]) {
    if (!v.is_string()) {
      *why = std::string(key) + " must be a list of names";
      return false;
    }
    out.push_back(v.get<std::string>());
  }
  return true;
}

bool readNumber(const json& j, const char* key, double& out, std::string* why) {
  if (!j.contains(key)) return true;
  if (!j[key].is_number()) {
    *why = std::string(key) + " must be a number";
    return false;
  }
  out = j[key].get<double>();
  return true;
}

bool readText(const json& j, const char* key, std::string& out, std::string* why) {
  if (!j.contains(key)) return true;
  if (!j[key].is_string()) {
    *why = std::string(key) + " must be text";
    return false;
  }
  out = j[key].get<std::string>();
  return true;
}

std::string list(const std::vector<std::string>& names) {
  std::string t;
  for (const auto& n : names) t += (t.empty() ? "" : ", ") + n;
  return t;
}

std::string list(const std::vector<double>& v) {
  std::string t;
  for (double x : v) t += (t.empty() ? "" : ", ") + formatSignificant(x, 3);
  return t;
}

ReportSeries thinned(const std::string& name, std::vector<double> x, std::vector<double> y,
                     bool dashed, int color) {
  ReportSeries s{name, std::move(x), std::move(y), dashed, color};
  thinSeries(s.x, s.y, 3000);
  return s;
}

class RecursivePart : public SessionPart {
 public:
  std::string key() const override { return "recursive"; }

  bool validate(const json& section, std::string* why) const override {
    if (!section.is_object() || !section.contains("runs") || !section["runs"].is_array()) {
      if (why) *why = "must be an object with a list of runs";
      return false;
    }
    for (const auto& run : section["runs"]) {
      if (!run.is_object() || !run.contains("request")) {
        if (why) *why = "every run needs a request";
        return false;
      }
      if (!recursiveRequestFromJson(run["request"], why)) return false;
    }
    return true;
  }

  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    const auto& runs = section["runs"];
    for (std::size_t i = 0; i < runs.size(); ++i) {
      std::string why;
      auto request = recursiveRequestFromJson(runs[i]["request"], &why);
      if (!request) continue;  // validated on load
      const ProgressCallback progress = [&](double f, const std::string& stage) {
        return context.progress ? context.progress((static_cast<double>(i) + f) / runs.size(), stage)
                                : ProgressAction::Continue;
      };
      report.sections.push_back(runSection(*request, runs[i], context, progress, report));
    }
  }

 private:
  static ReportSection runSection(const RecursiveRequest& q, const json& stored,
                                  const ReplayContext& context, const ProgressCallback& progress,
                                  Report& report) {
    ReportSection s;
    s.title = "Recursive identification" + (q.label.empty() ? std::string() : ": " + q.label);
    const RecursiveOptions& o = q.options;
    const std::string firstLog = context.session.logs.empty() ? "" : context.session.logs.front().name;
    std::string design =
        "The recursive prediction-error method of chapter 6 (" +
        std::string(o.algorithm == RecursiveAlgorithm::Kalman
                        ? "Algorithm 6.2, the Kalman gain with R1 = diag(" +
                              (o.r1.empty() ? std::string("(6.54)") : list(o.r1)) + ") " +
                              designRateText(o) + ", R2 = " + formatSignificant(o.r2, 3)
                        : "Algorithm 6.1, forgetting factor " + formatSignificant(o.lambda, 6) +
                              " " + designRateText(o)) +
        (o.mu > 0.0 ? ", regularisation mu = " + formatSignificant(o.mu, 3) : "") +
        (o.tracking != RecursiveTracking::Fixed ? std::string(", tracking ") + toString(o.tracking) : "") +
        "), psi from " +
        (o.gradient == RecursiveGradient::Sensitivity ? "the sampled sensitivity system (6.27)"
                                                       : "the differences (6.33)") +
        ". Model " + (q.model.empty() ? q.structure + " (nominal defaults)" : q.model) +
        "; estimated: " + list(o.estimate) + ", from " + formatSignificant(o.startScale, 3) +
        " times nominal; log '" + (q.log.empty() ? firstLog : q.log) + "'" +
        (q.data.range ? ", " + formatSignificant(q.data.range->start, 6) + "-" +
                            formatSignificant(q.data.range->end, 6) + " s"
                      : "") +
        " as read.";
    s.paragraphs.push_back(design);
    s.values = {{"label", q.label}, {"algorithm", toString(o.algorithm)}};
    auto fail = [&](const std::string& text) {
      report.warnings.push_back("recursive identification" + (q.label.empty() ? std::string() : " " + q.label) +
                                ": could not run: " + text);  // e.g. a log the session lacks
      s.paragraphs.push_back("The recursive identification could not run: " + text + ".");
      s.values["termination"] = "failed";
      s.values["message"] = text;
      return s;
    };
    std::string why;
    const auto model = recursiveNominalModel(q, context.session, &why);
    if (!model) return fail(why);
    const IdData* log = nullptr;
    if (context.rawLogs)
      for (const auto& [name, data] : *context.rawLogs)
        if (q.log.empty() ? log == nullptr : name == q.log) log = data;
    if (!log) return fail(context.rawLogs ? "the session has no log named " + inQuotes(q.log)
                                          : "the logs as read are not available");
    RecursiveLogResult run;
    try {
      run = recursiveIdentification(*log, *model, q.data, q.options, progress);
    } catch (const std::invalid_argument& e) {
      return fail(e.what());
    }
    const RecursiveResult& r = run.result;
    if (r.termination == Termination::Failed || r.termination == Termination::Cancelled)
      return fail(r.message);
    s.paragraphs.push_back("Data: " + run.preparation + "; " + std::to_string(r.samples) +
                           " samples at " + formatSignificant(1.0 / run.sampleTime, 4) + " Hz. " +
                           r.message);
    if (!r.caveat.empty()) s.paragraphs.push_back("Note: " + r.caveat);
    ReportTable t{"Estimates at the end", {"Parameter", "Nominal", "Start", "Final", "Sigma", "Unit"}, {}};
    json finals = json::object(), sigmas = json::object();
    for (const auto& e : r.estimates) {
      t.rows.push_back({e.parameter.modelName, formatSignificant(e.modelNominal, 5),
                        formatSignificant(e.modelStart, 5), formatSignificant(e.modelFinal, 5),
                        formatSignificant(e.modelSigma, 3), e.parameter.modelUnit});
      if (e.parameter.inverted)
        t.rows.push_back({e.parameter.name + " (theta)", formatSignificant(e.parameter.nominal, 5),
                          formatSignificant(e.start, 5), formatSignificant(e.final, 5),
                          formatSignificant(e.sigma, 3), e.parameter.unit});
      finals[e.parameter.modelName] = e.modelFinal;
      sigmas[e.parameter.modelName] = e.modelSigma;
    }
    s.tables.push_back(t);
    s.values["termination"] = toString(r.termination);
    s.values["message"] = r.message;
    s.values["final"] = finals;
    s.values["std"] = sigmas;
    s.values["samples"] = r.samples;
    if (stored.contains("result") && stored["result"].is_object() && stored["result"].contains("final")) {
      const json& was = stored["result"]["final"];
      for (const auto& e : r.estimates) {
        if (!was.contains(e.parameter.modelName) || !was[e.parameter.modelName].is_number()) continue;
        const double before = was[e.parameter.modelName].get<double>();
        if (std::abs(before - e.modelFinal) > 1e-6 * std::max(1.0, std::abs(before))) {
          s.paragraphs.push_back("The session recorded " + e.parameter.modelName + " = " +
                                 formatSignificant(before, 6) + " at the end; this replay gives " +
                                 formatSignificant(e.modelFinal, 6) + ".");
          report.warnings.push_back("recursive identification " + q.label + ": " +
                                    e.parameter.modelName + " differs from the session's");
        }
      }
    }
    // Figures 6.5 / 6.7: the estimates relative to nominal with +-3 sigma; 6.6 / 6.8: P.
    const RecursiveTrajectory& tr = r.trajectory;
    ReportPlot est{"Estimates relative to nominal (+-3 sigma dashed)", "time (s)", "theta / nominal",
                   false, false, {}};
    ReportPlot pd{"Diagonal of P", "time (s)", "P_ii", false, true, {}};
    for (std::size_t i = 0; i < r.estimates.size(); ++i) {
      const RecursiveParameter& p = r.estimates[i].parameter;
      const double n = p.nominal;
      std::vector<double> rel(tr.size()), lo(tr.size()), hi(tr.size());
      for (std::size_t k = 0; k < tr.size(); ++k) {
        rel[k] = tr.theta[i][k] / n;
        lo[k] = (tr.theta[i][k] - 3.0 * tr.sigma[i][k]) / n;
        hi[k] = (tr.theta[i][k] + 3.0 * tr.sigma[i][k]) / n;
      }
      const int color = static_cast<int>(i);
      est.series.push_back(thinned(p.name, tr.time, rel, false, color));
      est.series.push_back(thinned(p.name + " - 3 sigma", tr.time, lo, true, color));
      est.series.push_back(thinned(p.name + " + 3 sigma", tr.time, hi, true, color));
      pd.series.push_back(thinned("P " + p.name, tr.time, tr.pDiagonal[i], false, color));
    }
    if (!tr.time.empty())
      est.series.push_back(ReportSeries{"nominal", {tr.time.front(), tr.time.back()}, {1.0, 1.0}, true,
                                        static_cast<int>(r.estimates.size())});
    if (!r.estimates.empty()) {
      s.plots.push_back(est);
      s.plots.push_back(pd);
    }
    s.plots.push_back(ReportPlot{"Prediction error (6.3)", "time (s)", "epsilon (rad/s)", false, false,
                                 {thinned("epsilon", tr.time, tr.epsilon, false, 0)}});
    return s;
  }
};

}  // namespace

bool RecursiveRequest::isValid(std::string* why) const {
  if (model.empty() && structure.empty()) {
    if (why) *why = "a model or a structure is needed";
    return false;
  }
  return data.isValid(why) && options.isValid(why);
}

json recursiveRequestToJson(const RecursiveRequest& q) {
  const RecursiveOptions& o = q.options;
  return {{"label", q.label},
          {"model", q.model},
          {"structure", q.structure},
          {"log", q.log},
          {"decimation", q.data.decimation},
          {"max_rate_hz", q.data.maxRateHz},
          {"range_s", secondsRangeToJson(q.data.range)},
          {"estimate", o.estimate},
          {"inverted", o.inverted},
          {"algorithm", toString(o.algorithm)},
          {"lambda", o.lambda},
          {"r1", numbers(o.r1)},
          {"design_sample_time_s", o.designSampleTime},
          {"tracking", toString(o.tracking)},
          {"lambda_min", o.lambdaMin},
          {"bank_spacing_s", o.bankSpacingS},
          {"bank_size", o.bankSize},
          {"bank_threshold", o.bankThreshold},
          {"r2", o.r2},
          {"mu", o.mu},
          {"gradient", toString(o.gradient)},
          {"difference_step", o.differenceStep},
          {"start_scale", o.startScale},
          {"p0", numbers(o.p0)}};
}

std::optional<RecursiveRequest> recursiveRequestFromJson(const json& j, std::string* why) {
  std::string reason;
  auto fail = [&](const std::string& text) -> std::optional<RecursiveRequest> {
    if (why) *why = "the recursive identification: " + text;
    return std::nullopt;
  };
  if (!j.is_object()) return fail("must be an object");
  RecursiveRequest q;
  RecursiveOptions& o = q.options;
  double decimation = 0.0;
  // Sessions written before the estimator ran at the log's rate decimated to 200 Hz and gave
  // lambda and R1 per sample.
  q.data.maxRateHz = 200.0;
  o.designSampleTime = 0.0;
  std::string algorithm = toString(o.algorithm), gradient = toString(o.gradient),
              tracking = toString(o.tracking);
  double bankSize = o.bankSize;
  if (!readText(j, "label", q.label, &reason) || !readText(j, "model", q.model, &reason) ||
      !readText(j, "structure", q.structure, &reason) || !readText(j, "log", q.log, &reason) ||
      !readNumber(j, "decimation", decimation, &reason) ||
      !readNumber(j, "max_rate_hz", q.data.maxRateHz, &reason) ||
      !readNumber(j, "design_sample_time_s", o.designSampleTime, &reason) ||
      !readText(j, "tracking", tracking, &reason) || !readNumber(j, "lambda_min", o.lambdaMin, &reason) ||
      !readNumber(j, "bank_spacing_s", o.bankSpacingS, &reason) ||
      !readNumber(j, "bank_size", bankSize, &reason) ||
      !readNumber(j, "bank_threshold", o.bankThreshold, &reason) ||
      !readSecondsRange(j, "range_s", q.data.range, &reason) ||
      !readNames(j, "estimate", o.estimate, &reason) || !readNames(j, "inverted", o.inverted, &reason) ||
      !readText(j, "algorithm", algorithm, &reason) || !readNumber(j, "lambda", o.lambda, &reason) ||
      !readNumbers(j, "r1", o.r1, &reason) || !readNumber(j, "r2", o.r2, &reason) ||
      !readNumber(j, "mu", o.mu, &reason) || !readText(j, "gradient", gradient, &reason) ||
      !readNumber(j, "difference_step", o.differenceStep, &reason) ||
      !readNumber(j, "start_scale", o.startScale, &reason) || !readNumbers(j, "p0", o.p0, &reason))
    return fail(reason);
  if (decimation != std::floor(decimation) || decimation < 0.0 || decimation > 1e6)
    return fail("decimation must be 0 (to the highest rate) or a positive whole number");
  q.data.decimation = static_cast<int>(decimation);
  const auto a = recursiveAlgorithmFromString(algorithm);
  if (!a) return fail("algorithm must be forgetting or kalman, not " + inQuotes(algorithm));
  o.algorithm = *a;
  const auto t = recursiveTrackingFromString(tracking);
  if (!t) return fail("tracking must be fixed, variable or bank, not " + inQuotes(tracking));
  o.tracking = *t;
  if (bankSize != std::floor(bankSize) || bankSize < 1.0 || bankSize > 64.0)
    return fail("bank_size must be a whole number from 1 to 64");
  o.bankSize = static_cast<int>(bankSize);
  const auto g = recursiveGradientFromString(gradient);
  if (!g) return fail("gradient must be sensitivity or difference, not " + inQuotes(gradient));
  o.gradient = *g;
  if (!q.isValid(&reason)) return fail(reason);
  return q;
}

json recursiveResultToJson(const RecursiveResult& r) {
  json finals = json::object(), sigmas = json::object();
  for (const auto& e : r.estimates) {
    finals[e.parameter.modelName] = e.modelFinal;
    sigmas[e.parameter.modelName] = e.modelSigma;
  }
  return {{"termination", toString(r.termination)},
          {"message", r.message},
          {"samples", r.samples},
          {"final", finals},
          {"std", sigmas}};
}

std::unique_ptr<PhysicalModel> recursiveNominalModel(const RecursiveRequest& q, const Session& session,
                                                     std::string* why) {
  if (q.model.empty()) {
    try {
      return makeModel(q.structure);
    } catch (const std::invalid_argument& e) {
      *why = e.what();
      return nullptr;
    }
  }
  if (session.parts.contains("models"))
    for (const auto& m : session.parts["models"]) {
      auto spec = modelFromJson(m, why);
      if (!spec || spec->name != q.model) continue;
      auto c = spec->model->clone();
      return std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(c.release()));
    }
  *why = "the model list has no model named " + inQuotes(q.model);
  return nullptr;
}

std::shared_ptr<const SessionPart> makeRecursivePart() { return std::make_shared<RecursivePart>(); }

}  // namespace flexarm
