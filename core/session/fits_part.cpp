// The session part "fits": every stored fit request replayed through the fit pipeline into a
// report section (fit_report.h), and an SPA section of the estimation data on request.
#include <stdexcept>

#include "core/session/fit_report.h"
#include "core/session/fit_request.h"
#include "core/session/report.h"

namespace flexarm {

using nlohmann::json;

namespace {

class FitsPart : public SessionPart {
 public:
  std::string key() const override { return "fits"; }

  bool validate(const json& section, std::string* why) const override {
    if (!section.is_object()) {
      if (why) *why = "must be an object with \"requests\" and \"nonparametric\"";
      return false;
    }
    if (section.contains("nonparametric") && !section["nonparametric"].is_boolean()) {
      if (why) *why = "nonparametric must be true or false";
      return false;
    }
    if (!section.contains("requests") || !section["requests"].is_array()) {
      if (why) *why = "requests must be a list of fits";
      return false;
    }
    if (section["requests"].size() > kMaxPartItems) {
      if (why) *why = "more than " + std::to_string(kMaxPartItems) + " fits";
      return false;
    }
    for (const auto& r : section["requests"]) {
      auto request = fitRequestFromJson(r, why);
      if (!request) return false;
      if (r.contains("estimate") && !polynomialEstimateFromJson(r["estimate"], *request, why)) return false;
    }
    return true;
  }

  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    if (section.value("nonparametric", false))
      report.sections.push_back(spaSection(context));
    for (const auto& j : section["requests"]) {
      std::string why;
      auto request = fitRequestFromJson(j, &why);
      if (!request) continue;  // validated on load
      if (const std::string other = mismatchWithOpen(request->provenance, context); !other.empty()) {
        report.sections.push_back(storedFitReportSection(*request, other));
        report.warnings.push_back("fit " + request->name + " was " + other);
        continue;
      }
      ReportSection s = fitSection(*request, context);
      if (request->provenance)
        s.paragraphs.insert(s.paragraphs.begin(), "Computed on " + longDescription(*request->provenance) +
                                                      (request->provenance->when.empty()
                                                           ? ""
                                                           : " at " + request->provenance->when) +
                                                      "; recomputed here on the same data.");
      report.sections.push_back(s);
    }
  }

 private:
  // SPA (4.28) of the estimation data with its 99 % band, notches and peaks.
  static ReportSection spaSection(const ReplayContext& context) {
    FitOptions o;
    o.model.kind = FitModelKind::Spa;
    o.responsePoints = 400;
    o.level = 0.99;
    o.estimation = {{std::shared_ptr<const IdData>(&context.data, [](const IdData*) {}), context.session.estimation}};
    return spaReportSection(fitModel(o, context.progress));
  }

  static ReportSection fitSection(const FitRequest& request, const ReplayContext& context) {
    FitRequest r = request;  // ranges the request does not name are the session's
    if (!r.estimation) r.estimation = context.session.estimation;
    if (!r.validation) r.validation = context.session.validation;
    FitResult run;
    try {
      run = runFitRequest(r, context.data, context.progress);
    } catch (const std::invalid_argument& e) {  // a request these data cannot run
      run.status = FitStatus::BadRequest;
      run.message = e.what();
      run.model = r.options.model;
    }
    const std::string log = context.session.logs.empty() ? std::string() : context.session.logs.front().path;
    return fitReportSection(r, run, fitLogNamesOf(r, log));
  }
};

}  // namespace

std::shared_ptr<const SessionPart> makeFitsPart() { return std::make_shared<FitsPart>(); }

}  // namespace flexarm
