// The report sections of Compare, the residual analysis and the sensitivity study
// (compare_part.h): their sentences, tables, plots and the JSON writers' values without run
// times (a replayed report must equal the saved one).
#include <cmath>

#include "core/compare/compare_json.h"
#include "core/session/compare_part.h"

namespace flexarm {

using nlohmann::json;

namespace {

void dropSeconds(json& j) {
  if (!j.is_object()) return;
  j.erase("seconds");
  for (auto& [key, value] : j.items()) dropSeconds(value);
}

ReportSeries timeSeries(const std::string& name, double start, double step, const Eigen::VectorXd& y, bool dashed,
                        int color) {
  ReportSeries s{name, {}, {}, dashed, color};
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    s.x.push_back(start + static_cast<double>(i) * step);
    s.y.push_back(y[i]);
  }
  thinSeries(s.x, s.y, 3000);
  return s;
}

std::string percentText(double v) { return std::isfinite(v) ? formatFixed(v, 2) : std::string("-"); }

}  // namespace

ReportSection compareReportSection(const CompareResult& r) {
  ReportSection s;
  s.title = "Compare on " + r.rangeText() + " (Figure 5.11)";
  for (const auto& line : r.lines()) s.paragraphs.push_back(line);
  ReportTable fits{"Fit % of each model: the seed's (5.2) and MATLAB compare's NRMSE",
                   {"Model", "Fit % (5.2)", "NRMSE %", "What it is of"},
                   {}};
  for (const auto& m : r.models) {
    if (!m.fit) {
      fits.rows.push_back({m.name, "-", "-", std::string("not compared: ") + m.message});
      continue;
    }
    fits.rows.push_back({m.name, percentText(m.fit->percent.seed52), percentText(m.fit->percent.nrmse),
                         fitBasisText(m.fit->basis)});
  }
  s.tables.push_back(fits);
  ReportTable deflection{"Deflection r phi_m - phi_a predicted from the torque, about its mean",
                         {"Model", "Fit % (5.2)", "NRMSE %", "RMS error (mrad)"},
                         {}};
  for (const auto& m : r.models)
    if (m.deflection)
      deflection.rows.push_back({m.name, percentText(m.deflection->figure.percent.seed52),
                                 percentText(m.deflection->figure.percent.nrmse),
                                 formatSignificant(1e3 * m.deflection->rmsError, 3)});
  if (!deflection.rows.empty()) s.tables.push_back(deflection);
  if (r.measured.size()) {
    ReportPlot plot{"Measured and model outputs, " + r.rangeText(), "time (s)",
                    r.outputName + (r.outputUnit.empty() ? "" : " (" + r.outputUnit + ")"), false, false, {}};
    plot.series.push_back(timeSeries("measured", r.startTime, r.sampleTime, r.measured, false, 0));
    int color = 1;
    for (const auto& m : r.models)
      if (m.compared()) plot.series.push_back(timeSeries(m.name, m.startTime, m.sampleTime, m.output, true, color++));
    s.plots.push_back(std::move(plot));
  }
  s.values = compareResultJson(r);
  dropSeconds(s.values);
  return s;
}

ReportSection residualsReportSection(const ResidualsResult& r) {
  ReportSection s;
  s.title = "Residual analysis: " + r.modelName;
  s.paragraphs.push_back(r.summary());
  const ResidualAnalysis& a = r.analysis;
  if (!a.lags.empty()) {
    s.tables.push_back(ReportTable{
        "Tests of the residuals at 99 %",
        {"Test", "Statistic", "Threshold", "Passed"},
        {{"whiteness", formatSignificant(a.whitenessStatistic, 4), formatSignificant(a.whitenessThreshold, 4),
          a.white ? "yes" : "no"},
         {"independence from the input", formatSignificant(a.independenceStatistic, 4),
          formatSignificant(a.independenceThreshold, 4), a.independent ? "yes" : "no"}}});
    auto correlationPlot = [](const std::string& title, const std::vector<int>& lags, const std::vector<double>& r0,
                              double bound) {
      ReportPlot p{title, "lag (samples)", "correlation", false, false, {}};
      ReportSeries c{"correlation", {}, r0, false, 0}, hi{"bound", {}, {}, true, 1}, lo{"-bound", {}, {}, true, 1};
      for (int l : lags) {
        c.x.push_back(l);
        hi.x.push_back(l);
        lo.x.push_back(l);
        hi.y.push_back(bound);
        lo.y.push_back(-bound);
      }
      p.series = {c, hi, lo};
      return p;
    };
    s.plots.push_back(correlationPlot("Autocorrelation of the residuals", a.lags, a.autocorrelation,
                                      a.autocorrelationBound));
    s.plots.push_back(correlationPlot("Cross-correlation of input and residuals", a.crossLags, a.crossCorrelation,
                                      a.crossCorrelationBound));
  }
  s.values = residualsResultJson(r);
  dropSeconds(s.values);
  return s;
}

ReportSection sensitivityReportSection(const SensitivityResult& r) {
  ReportSection s;
  s.title = "Sensitivity study (Section 5.3.3): " + r.modelName;
  s.paragraphs.push_back("Fits (5.7) on the " + r.rangeText + " of " + r.dataName + " (" + r.dataNote + ", " +
                         std::to_string(r.samples) + " samples); a fit succeeds when its loss is within 5 % of the "
                         "refit from the model itself.");
  s.paragraphs.push_back(r.summary());
  ReportTable limits{"Domain of attraction of the initial values (Table 5.8), % of the estimate",
                     {"Parameter", "Lower limit", "Upper limit"},
                     {}};
  auto limit = [](double f, bool open) { return (open ? "beyond " : "") + formatSignificant(100.0 * f, 4) + " %"; };
  for (const auto& p : r.attraction.parameters)
    limits.rows.push_back({p.name, limit(p.lowerFactor, p.lowerOpen), limit(p.upperFactor, p.upperOpen)});
  if (!limits.rows.empty()) s.tables.push_back(limits);
  s.values = sensitivityResultJson(r);
  dropSeconds(s.values);
  return s;
}

}  // namespace flexarm
