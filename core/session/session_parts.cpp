// The parts a session holds today: the model list, fits, discovery, the LQG design and view
// state. A capability that lands later adds its class here (or in its own module) and one
// line to sessionParts().
#include <algorithm>
#include <cmath>
#include <complex>
#include <cctype>
#include <set>

#include "core/common/text.h"
#include "core/models/analysis.h"
#include "core/models/nonlinear_plant.h"
#include "core/session/compare_part.h"
#include "core/session/diagnosis_part.h"
#include "core/session/discovery_part.h"
#include "core/session/fit_request.h"
#include "core/session/lqg_part.h"
#include "core/session/model_json.h"
#include "core/session/recursive_part.h"
#include "core/session/session_part.h"
#include "core/compare/compare_json.h"

namespace flexarm {

using nlohmann::json;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The model list: each model's parameters (value, unit, free flag), effects, notch and peak
// frequencies (5.4), Bode plot, and its fit % (5.2) on the estimation and validation ranges as
// Compare forms it (core/compare/compare.h), each figure with what it is of.
// The data an estimate of the list was computed on, for its section.
void estimatedOnNote(ReportSection& s, const Provenance& p) {
  s.paragraphs.insert(s.paragraphs.begin() + 1, "Estimated on " + longDescription(p) +
                                                    (p.when.empty() ? "" : " at " + p.when) + ".");
  s.values["estimated_on"] = provenanceToJson(p);
}

class ModelsPart : public SessionPart {
 public:
  std::string key() const override { return "models"; }

  bool validate(const json& section, std::string* why) const override {
    if (!section.is_array()) {
      if (why) *why = "must be a list of models";
      return false;
    }
    if (section.size() > kMaxPartItems) {
      if (why) *why = "more than " + std::to_string(kMaxPartItems) + " models";
      return false;
    }
    std::set<std::string> names;
    for (const auto& m : section) {
      auto spec = modelFromJson(m, why);
      if (!spec) return false;
      if (!names.insert(spec->name).second) {
        if (why) *why = "the model name '" + spec->name + "' is used twice";
        return false;
      }
    }
    return true;
  }

  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    for (const auto& m : section) {
      std::string why;
      auto spec = modelFromJson(m, &why);
      if (!spec) continue;  // validated on load
      report.sections.push_back(modelSection(*spec, context));
      // An estimate made on other data: its values are as estimated, the fit % is of the
      // open log, and the report says so.
      const auto provenance = provenanceIn(m);
      if (const std::string other = mismatchWithOpen(provenance, context); !other.empty()) {
        ReportSection& s = report.sections.back();
        s.paragraphs.insert(s.paragraphs.begin() + 1,
                            "Estimated on other data: " + other +
                                ". The fit % below is of this model on the open log.");
        s.values["estimated_on"] = provenanceToJson(*provenance);
      } else if (provenance) {
        estimatedOnNote(report.sections.back(), *provenance);
      }
    }
  }

 private:
  static ReportSection modelSection(const ModelSpec& spec, const ReplayContext& context) {
    const PhysicalModel& model = *spec.model;
    ReportSection s;
    s.title = "Model " + spec.name;
    s.paragraphs.push_back(model.description() + ".");
    std::string fx;
    for (const auto& e : spec.effects) {
      const auto info = effectParameters(e);
      fx += (fx.empty() ? "" : "; ") + std::string(toString(e.kind)) + " (";
      for (std::size_t i = 0; i < info.size(); ++i)
        fx += (i ? ", " : "") + info[i].name + " = " + formatSignificant(e.values[i]) +
              (info[i].unit.empty() ? "" : " " + info[i].unit);
      fx += ")";
    }
    s.paragraphs.push_back(fx.empty() ? "No nonlinear effects." : "Effects: " + fx + ".");
    s.paragraphs.push_back("Parameter values as set in the model list (not estimated here).");
    ReportTable params{"Parameters", {"Parameter", "Value", "Unit", "Free"}, {}};
    json paramsJson = json::object();
    for (const auto& p : model.parameters()) {
      params.rows.push_back({p.name, formatSignificant(p.value, 6), p.unit, p.free ? "yes" : "no"});
      paramsJson[p.name] = p.value;
    }
    s.tables.push_back(params);
    s.values = {{"name", spec.name}, {"structure", model.structureName()}, {"parameters", paramsJson}};

    const StateSpace sys = model.stateSpace();
    // FlexArm's one definition (core/models/analysis.h): extrema of |G(i w)|.
    ReportTable modes{"Notches and peaks: minima and maxima of |G(i w)|", {"Kind", "Frequency (rad/s)"}, {}};
    const NotchesPeaks np = notchesAndPeaks(sys);
    json notches = np.notches, peaks = np.peaks;
    for (double w : np.notches) modes.rows.push_back({"notch", formatSignificant(w, 5)});
    for (double w : np.peaks) modes.rows.push_back({"peak", formatSignificant(w, 5)});
    s.tables.push_back(modes);
    s.values["notches_rad_s"] = notches;
    s.values["peaks_rad_s"] = peaks;
    s.plots = bodePlots(sys, spec.name);
    addFit(spec, context, s);
    return s;
  }

  static std::vector<ReportPlot> bodePlots(const StateSpace& sys, const std::string& name) {
    const std::vector<double> w = logGrid(1.0, 3000.0, 500);
    const auto g = frequencyResponse(sys, w);
    ReportSeries mag{name, w, {}, false}, phase{name, w, {}, false};
    double offset = 0.0, last = 0.0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      mag.y.push_back(std::abs(g[i]));
      double p = std::arg(g[i]) * 180.0 / kPi + offset;
      while (i > 0 && p - last > 180.0) p -= 360.0, offset -= 360.0;
      while (i > 0 && p - last < -180.0) p += 360.0, offset += 360.0;
      phase.y.push_back(p);
      last = p;
    }
    return {ReportPlot{"Bode magnitude, " + name, "frequency (rad/s)", "|G| (rad/s per N m)", true,
                       true, {mag}},
            ReportPlot{"Bode phase, " + name, "frequency (rad/s)", "phase (deg)", true, false, {phase}}};
  }

  // Fit % (5.2) on the ranges, as Compare forms it (runCompare): the model at its fit's rate,
  // simulated from the input (through its fit's load observer when it has effects and the log
  // was recorded in closed loop), each figure with what it is of; the plot of the last range.
  static void addFit(const ModelSpec& spec, const ReplayContext& context, ReportSection& s) {
    CompareRequest r;
    r.data = evaluationDataOf(context);
    for (const auto& m : evaluatedModelsOf(context.session))
      if (m.name == spec.name) r.models = {m};
    if (r.models.empty()) return;
    ReportTable fit{"Fit % (5.2) of the model's output", {"Range", "Samples", "Fit %", "NRMSE %", "What it is of"}, {}};
    std::optional<CompareResult> shown;
    const bool both = r.data.validation.has_value();
    for (const DataRange range : {DataRange::Estimation, DataRange::Validation}) {
      if (range == DataRange::Validation && !both) continue;
      r.range = range;
      CompareResult c = runCompare(r, context.progress);
      if (!c.ok() || !c.models.front().fit) {
        s.paragraphs.push_back("No fit % on the " + std::string(toString(range)) + " range: " +
                               (c.ok() ? c.models.front().message : c.message) + ".");
        continue;
      }
      const FitFigure& f = *c.models.front().fit;
      const auto samples = static_cast<std::size_t>(c.models.front().output.size());
      fit.rows.push_back({toString(range), std::to_string(samples), formatFixed(f.percent.seed52, 2),
                          formatFixed(f.percent.nrmse, 2), fitBasisText(f.basis)});
      // The fit schema's names (core/ident/fit_json.h): fit_percent of the estimation range,
      // fit_percent_validation of the validation range, each with what it is of.
      const std::string suffix = range == DataRange::Estimation ? "" : "_validation";
      s.values["fit_percent" + suffix] = f.percent.seed52;
      s.values["fit_basis" + suffix] = fitBasisJson(f.basis);
      shown = std::move(c);
    }
    if (fit.rows.empty()) return;
    s.tables.push_back(fit);
    const CompareResult& c = *shown;
    const ComparedModel& m = c.models.front();
    ReportSeries meas{"measured", {}, {}, false}, sim{"model " + spec.name, {}, {}, true};
    for (Eigen::Index i = 0; i < c.measured.size(); ++i) {
      meas.x.push_back(c.startTime + static_cast<double>(i) * c.sampleTime);
      meas.y.push_back(c.measured[i]);
    }
    for (Eigen::Index i = 0; i < m.output.size(); ++i) {
      sim.x.push_back(m.startTime + static_cast<double>(i) * m.sampleTime);
      sim.y.push_back(m.output[i]);
    }
    thinSeries(meas.x, meas.y, 3000);
    thinSeries(sim.x, sim.y, 3000);
    s.plots.push_back(ReportPlot{"Measured and model motor velocity, " + spec.name, "time (s)",
                                 "motor velocity (rad/s)", false, false, {meas, sim}});
  }
};

// View state (window layout, selected panel items): restored by the window, not replayed.
class ViewPart : public SessionPart {
 public:
  std::string key() const override { return "view"; }
  bool validate(const json& section, std::string* why) const override {
    if (section.is_object()) return true;
    if (why) *why = "must be an object";
    return false;
  }
  void replay(const json&, const ReplayContext&, Report&) const override {}
};

}  // namespace

const std::vector<std::shared_ptr<const SessionPart>>& sessionParts() {
  // Report order. Later capabilities add their part here.
  static const std::vector<std::shared_ptr<const SessionPart>> kParts = {
      std::make_shared<ModelsPart>(),
      makeFitsPart(),
      makeComparePart(),
      makeResidualsPart(),
      makeSensitivityPart(),
      makeDiscoveryPart(),
      makeLqgPart(),
      makeRecursivePart(),
      makeDiagnosisPart(),
      std::make_shared<ViewPart>(),
  };
  return kParts;
}

std::string mismatchWithOpen(const std::optional<Provenance>& result, const ReplayContext& context) {
  if (!result || !context.open) return {};
  return dataMismatch(*result, *context.open);
}

void SessionPart::replayStored(const nlohmann::json& section, const std::string& mismatch, Report& report) const {
  ReportSection s;
  std::string title = key();
  if (!title.empty()) title[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(title[0])));
  s.title = title + " (computed on other data)";
  s.paragraphs.push_back("Not recomputed on the open data: " + mismatch +
                         ". Open that log, or recompute in the window, to see its results.");
  s.values = {{"recomputed", false}, {"computed_on", section["provenance"]}};
  report.sections.push_back(s);
  report.warnings.push_back(key() + ": " + mismatch);
}

const IdData* findLog(const ReplayContext& context, const std::string& name, bool raw, std::string* why) {
  const auto* logs = raw ? context.rawLogs : &context.logs;
  if (!logs || logs->empty()) {
    if (why) *why = raw ? "the logs as read are not available" : "the session has no log";
    return nullptr;
  }
  const IdData* d = nullptr;
  for (const auto& [logName, data] : *logs)
    if (name.empty() ? d == nullptr : logName == name) d = data;
  if (!d && why) *why = "the session has no log named " + inQuotes(name);
  return d;
}

const SessionPart* findSessionPart(const std::string& key) {
  for (const auto& p : sessionParts())
    if (p->key() == key) return p.get();
  return nullptr;
}

}  // namespace flexarm
