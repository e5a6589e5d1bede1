#include "core/session/fit_report.h"

#include <cmath>
#include <limits>

#include "core/ident/fit_spec.h"

namespace flexarm {

using nlohmann::json;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string joinedFrequencies(const std::vector<double>& w) {
  std::string text;
  for (double x : w) text += (text.empty() ? "" : ", ") + formatFixed(x, 1);
  return text.empty() ? "none" : text + " rad/s";
}

// Bode magnitude and phase of a response with its 99 % band drawn as dashed bounds.
std::vector<ReportPlot> bodeWithBand(const FrequencyResponse& r, const std::string& name, const std::string& what) {
  const double deg = 180.0 / kPi;
  ReportPlot mag{"Bode magnitude, " + what, "frequency (rad/s)", "|G|", true, true, {}};
  ReportPlot ph{"Bode phase, " + what, "frequency (rad/s)", "phase (deg)", true, false, {}};
  mag.series.push_back({name, r.omega, r.magnitude, false});
  std::vector<double> phase;
  for (double p : r.phase) phase.push_back(p * deg);
  ph.series.push_back({name, r.omega, phase, false});
  if (r.hasBands()) {
    const std::string band = formatFixed(100.0 * r.level, 0) + " % bound";
    // A lower bound at or below zero has no place on a log axis: the curve has a gap there.
    std::vector<double> lower;
    for (double v : r.magnitudeLower) lower.push_back(v > 0.0 ? v : std::numeric_limits<double>::quiet_NaN());
    mag.series.push_back({"upper " + band, r.omega, r.magnitudeUpper, true, 1});
    mag.series.push_back({"lower " + band, r.omega, lower, true, 1});
    std::vector<double> lo, hi;
    for (std::size_t i = 0; i < r.phaseLower.size(); ++i) {
      lo.push_back(r.phaseLower[i] * deg);
      hi.push_back(r.phaseUpper[i] * deg);
    }
    ph.series.push_back({"upper " + band, r.omega, hi, true, 1});
    ph.series.push_back({"lower " + band, r.omega, lo, true, 1});
  }
  return {mag, ph};
}

// The parameter table of a fit: value, std and interval of the free ones; "fixed" for the others.
ReportTable parameterTable(const std::string& caption, const std::vector<FitParameter>& parameters) {
  ReportTable t{caption, {"Parameter", "Value", "+- std", "99 % lower", "99 % upper", "Unit"}, {}};
  for (const auto& p : parameters) {
    if (p.free && !p.determined)  // no std or interval to quote: what the data do not say
      t.rows.push_back({fitParameterLabel(p), formatSignificant(p.value, 6), "undetermined: " + p.undetermined, "",
                        "", p.unit});
    else if (p.free)
      t.rows.push_back({fitParameterLabel(p), formatSignificant(p.value, 6), formatSignificant(p.std, 3),
                        formatSignificant(p.lower, 6), formatSignificant(p.upper, 6), p.unit});
    else
      t.rows.push_back({fitParameterLabel(p), formatSignificant(p.value, 6), "fixed", "", "", p.unit});
  }
  return t;
}

ReportSeries stepSeries(const std::string& name, const std::vector<int>& lags, const std::vector<double>& v,
                        bool dashed) {
  ReportSeries s{name, {}, v, dashed};
  for (int l : lags) s.x.push_back(l);
  return s;
}

ReportSeries constantSeries(const std::string& name, const std::vector<int>& lags, double v) {
  ReportSeries s = stepSeries(name, lags, std::vector<double>(lags.size(), v), true);
  s.color = 1;
  return s;
}

// The model and how it is estimated, in a sentence.
std::string methodParagraph(const FitRequest& r) {
  const FitOptions& o = r.options;
  if (!r.physical()) return "black-box model " + o.model.name() + " (4.8), prediction-error fit (4.6).";
  std::string free;
  for (const auto& p : o.model.start->parameters())
    if (p.free) free += (free.empty() ? "" : ", ") + p.name + " from " + formatSignificant(p.value);
  for (const auto& f : o.model.effects)
    for (std::size_t k = 0; k < f.effect.values.size(); ++k)
      if (f.isFree(k))
        free += (free.empty() ? "" : ", ") + effectParameters(f.effect)[k].name + " (" +
                toString(f.effect.kind) + ") from " + formatSignificant(f.effect.values[k]);
  return o.model.name() + (o.model.nonlinear() ? " nonlinear" : "") +
         " grey-box model (5.3), prediction-error fit (5.7) in " +
         (o.noiseModel == NoiseModel::OutputError ? "output-error form (K = 0)" : "innovations form (K estimated)") +
         "; free parameters (start values) " + free + "; the others held as listed" +
         (o.randomStarts > 0 ? "; " + std::to_string(o.randomStarts) +
                                   " random starts and two at the SPA notches and peaks (seed " +
                                   std::to_string(o.seed) + ")"
                             : "") +
         ".";
}

// Measured and simulated output on the validation range (the estimation range without one).
void addCompare(const FitResult& run, const std::string& name, ReportSection& s) {
  const bool validation = !run.validation.empty();
  const PreparedData& sig = validation ? run.validation.front().data : run.data;
  const Eigen::VectorXd& simulated = validation ? run.validation.front().simulated : run.simulated;
  const SampleRange range = validation ? sig.validation : sig.estimation;
  if (simulated.size() != sig.y.size()) return;
  ReportSeries meas{"measured", {}, {}, false}, sim{"simulated " + name, {}, {}, true};
  for (std::size_t i = range.begin; i < range.end; ++i) {
    meas.x.push_back(sig.timeAt(i));
    meas.y.push_back(sig.y[static_cast<Eigen::Index>(i)]);
    sim.y.push_back(simulated[static_cast<Eigen::Index>(i)]);
  }
  sim.x = meas.x;
  thinSeries(meas.x, meas.y, 3000);
  thinSeries(sim.x, sim.y, 3000);
  const std::string where = validation ? "validation" : "estimation";
  s.plots.push_back(ReportPlot{"Measured and simulated output on the " + where + " range, " + name, "time (s)",
                               "output minus its estimation mean", false, false, {meas, sim}});
}

// Correlation tests of the residuals on the validation range (the estimation range without
// one), with their 99 % bounds and verdicts.
void addResiduals(const FitResult& run, ReportSection& s) {
  const std::string where = run.residualsOnValidation ? "validation" : "estimation";
  if (!run.residuals) {
    s.paragraphs.push_back("No residual tests: the " + where + " range is too short.");
    return;
  }
  const ResidualAnalysis& a = *run.residuals;
  ReportTable tests{"Residual tests on the " + where + " range (99 %)", {"Test", "Statistic", "Threshold", "Verdict"}, {}};
  tests.rows.push_back({"whiteness (autocorrelation)", formatSignificant(a.whitenessStatistic, 4),
                        formatSignificant(a.whitenessThreshold, 4), a.white ? "white" : "not white"});
  tests.rows.push_back({"independence of the input (cross-correlation)", formatSignificant(a.independenceStatistic, 4),
                        formatSignificant(a.independenceThreshold, 4), a.independent ? "independent" : "correlated"});
  s.tables.push_back(tests);
  s.paragraphs.push_back("Residual tests: " + a.verdict);
  s.plots.push_back(ReportPlot{"Residual autocorrelation", "lag (samples)", "r_eps(tau) / r_eps(0)", false, false,
                               {stepSeries("autocorrelation", a.lags, a.autocorrelation, false),
                                constantSeries("+99 % bound", a.lags, a.autocorrelationBound),
                                constantSeries("-99 % bound", a.lags, -a.autocorrelationBound)}});
  s.plots.push_back(ReportPlot{"Cross-correlation of residuals and input", "lag (samples)",
                               "r_eps,u(tau), normalized", false, false,
                               {stepSeries("cross-correlation", a.crossLags, a.crossCorrelation, false),
                                constantSeries("+99 % bound", a.crossLags, a.crossCorrelationBound),
                                constantSeries("-99 % bound", a.crossLags, -a.crossCorrelationBound)}});
}

}  // namespace

FitLogNames fitLogNamesOf(const FitRequest& request, const std::string& logName) {
  FitLogNames names{{logName}, {}};
  if (request.validation) names.validation.push_back(logName);
  for (const auto& e : request.experiments) (e.validation ? names.validation : names.estimation).push_back(e.path);
  return names;
}

ReportSection fitReportSection(const FitRequest& r, const FitResult& run, const FitLogNames& logs) {
  ReportSection s;
  s.title = "Fit " + r.name;
  s.paragraphs.push_back(methodParagraph(r));
  json fit = fitResultJson(run, logs);
  // The time the run took is no result: a replayed report must equal the saved one.
  fit.erase("seconds");
  s.values = {{"name", r.name}, {"recomputed", true}, {"fit", fit}};
  if (!run.ok()) {
    s.paragraphs.push_back("No fit: " + run.message + ".");
    return s;
  }
  const PreparedData& sig = run.data;
  s.paragraphs.push_back("Data: " + std::to_string(sig.estimation.size()) + " estimation samples at " +
                         formatSignificant(1.0 / sig.sampleTime, 6) + " Hz (" + sig.note() + "); " +
                         toString(run.summary.termination) + " after " + std::to_string(run.summary.iterations) +
                         " iterations.");
  if (run.method) s.paragraphs.push_back("Closed-loop method: " + run.methodDescription + " (" + run.methodReason + ").");
  if (!run.controllerSource.empty()) s.paragraphs.push_back("Controller: " + run.controllerSource + ".");
  for (const auto& w : run.warnings) s.paragraphs.push_back("Note: " + w + ".");
  s.tables.push_back(parameterTable("Estimated parameters (value +- std, 99 % interval)", run.parameters));

  ReportTable quality{"Loss and fit %: the seed's (5.2) and MATLAB compare's NRMSE", {"Quantity", "Value"}, {}};
  quality.rows.push_back({"loss V_N (4.6)", formatSignificant(run.summary.loss, 6)});
  quality.rows.push_back({"FPE", formatSignificant(run.summary.fpe, 6)});
  if (run.fitEstimation) {
    quality.rows.push_back({"fit % (5.2) on the estimation range", formatFixed(*run.fitEstimation, 2)});
    quality.rows.push_back({"NRMSE fit % on the estimation range", formatFixed(*run.fitEstimationNrmse, 2)});
  }
  if (auto v = run.fitValidation()) {
    quality.rows.push_back({"fit % (5.2) on the validation range", formatFixed(*v, 2)});
    quality.rows.push_back({"NRMSE fit % on the validation range", formatFixed(*run.fitValidationNrmse(), 2)});
  } else {
    s.paragraphs.push_back("No validation range: the fit is not validated.");
  }
  s.tables.push_back(quality);

  ReportTable modes{"Notches and peaks of the estimate: minima and maxima of |G(i w)|", {"Kind", "Frequency (rad/s)"}, {}};
  for (double w : run.notches) modes.rows.push_back({"notch", formatSignificant(w, 5)});
  for (double w : run.peaks) modes.rows.push_back({"peak", formatSignificant(w, 5)});
  s.tables.push_back(modes);

  s.plots = bodeWithBand(run.response, r.name, r.name + " with its 99 % band");
  addCompare(run, r.name, s);
  addResiduals(run, s);
  return s;
}

ReportSection storedFitReportSection(const FitRequest& r, const std::string& mismatch) {
  ReportSection s;
  s.title = "Fit " + r.name;
  s.paragraphs.push_back("Not recomputed on the open data: this fit was " + mismatch +
                         ". The numbers below are those stored when it was computed.");
  s.values = {{"name", r.name}, {"recomputed", false}};
  if (r.provenance) s.values["computed_on"] = provenanceToJson(*r.provenance);
  if (!r.stored) {
    s.paragraphs.push_back("The session stored no numbers of this fit: open its log to recompute it.");
    return s;
  }
  const StoredFit& f = *r.stored;
  s.tables.push_back(parameterTable("Estimated parameters as stored (value +- std, 99 % interval)", f.parameters));
  ReportTable quality{"Loss and fit % (5.2) as stored", {"Quantity", "Value"}, {}};
  quality.rows.push_back({"loss V_N (4.6)", formatSignificant(f.loss, 6)});
  if (f.fitEstimation) quality.rows.push_back({"fit % on the estimation range", formatFixed(*f.fitEstimation, 2)});
  if (f.fitValidation) quality.rows.push_back({"fit % on the validation range", formatFixed(*f.fitValidation, 2)});
  s.tables.push_back(quality);
  s.paragraphs.push_back("Notches: " + joinedFrequencies(f.notches) + ". Peaks: " + joinedFrequencies(f.peaks) + ".");
  s.values["fit"] = storedFitToJson(f);
  return s;
}

ReportSection spaReportSection(const FitResult& e) {
  ReportSection s;
  s.title = "Non-parametric estimate (SPA)";
  if (!e.ok()) {
    s.paragraphs.push_back("No estimate: " + e.message + ".");
    return s;
  }
  const auto n = static_cast<Eigen::Index>(e.data.estimation.size());
  const int m = e.nonparametric.window;
  s.paragraphs.push_back("Blackman-Tukey spectral analysis (4.28) of the estimation data (" + std::to_string(n) +
                         " samples, " + e.data.note() + "), Hann lag window M = " + std::to_string(m) +
                         ", 99 % band from (6.62): " + e.nonparametric.message + ".");
  for (const auto& w : e.warnings) s.paragraphs.push_back(w);
  std::size_t undefined = 0;
  for (std::size_t i = 0; i < e.response.omega.size(); ++i)
    undefined += !std::isfinite(e.response.magnitude[i]) || !std::isfinite(e.response.phase[i]);
  if (undefined > 0)
    s.paragraphs.push_back("The estimate is undefined at " + std::to_string(undefined) + " of " +
                           std::to_string(e.response.omega.size()) + " frequencies; the plots leave gaps there.");
  s.paragraphs.push_back("Notches: " + joinedFrequencies(e.notches) + ". Peaks: " + joinedFrequencies(e.peaks) +
                         " (minima and maxima of the magnitude).");
  s.plots = bodeWithBand(e.response, "SPA", "SPA of the estimation data");
  s.values = {{"samples", n},
              {"lag_window", m},
              {"lag_window_note", e.nonparametric.message},
              {"undefined_frequencies", undefined},
              {"notches_rad_s", e.notches},
              {"peaks_rad_s", e.peaks}};
  return s;
}

}  // namespace flexarm
