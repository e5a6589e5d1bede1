#include "core/fleet/fleet_report.h"

#include <algorithm>
#include <cmath>

namespace flexarm {

namespace {

std::string dateOf(double day) { return isoFromDay(day).substr(0, 10); }

std::string percentText(double v, int digits = 1) {
  return (v >= 0 ? "+" : "") + formatFixed(100.0 * v, digits) + " %";
}

double firstDay(const FleetAxisReport& a) { return a.points.empty() ? a.trend.lastDay : a.points.front().day; }

}  // namespace

ReportPlot fleetTrendPlot(const FleetAxisReport& a, const ParameterSeries& s, double threshold) {
  const double d0 = firstDay(a);
  ReportPlot p;
  p.title = a.robot + " axis " + std::to_string(a.axis) + ": " + s.name + " over days";
  p.xLabel = "time [days since " + dateOf(d0) + "]";
  p.yLabel = s.name + " - theta_0 [%]";
  ReportSeries est{"estimate", {}, {}}, hi{"+2 std", {}, {}, true, 0}, lo{"-2 std", {}, {}, true, 0},
      fit{s.kind == "none" ? "mean" : s.kind == "step" ? "fitted step" : "fitted drift", {}, {}, false, 1};
  for (std::size_t i = 0; i < s.day.size(); ++i) {
    const double x = s.day[i] - d0;
    est.x.push_back(x);
    est.y.push_back(100.0 * s.value[i]);
    hi.x.push_back(x);
    hi.y.push_back(100.0 * (s.value[i] + 2.0 * s.std[i]));
    lo.x.push_back(x);
    lo.y.push_back(100.0 * (s.value[i] - 2.0 * s.std[i]));
    fit.x.push_back(x);
    fit.y.push_back(100.0 * s.fitted[i]);
  }
  est.color = 0;
  p.series = {est, hi, lo, fit};
  if (s.name == "f_m" && !s.day.empty()) {
    double end = s.day.back() - d0;
    if (a.trend.crossingDay && a.trend.parameter == s.name) {
      const double cross = *a.trend.crossingDay - d0;
      end = std::max(end, cross + 1.0);
      ReportSeries ahead{"predicted", {s.day.back() - d0, cross}, {100.0 * s.level, 100.0 * threshold}, true, 1};
      ReportSeries mark{"crossing " + dateOf(*a.trend.crossingDay), {cross, cross},
                        {100.0 * std::min(0.0, s.level), 100.0 * threshold}, true, 3};
      p.series.push_back(ahead);
      p.series.push_back(mark);
    }
    p.series.push_back({"threshold " + percentText(threshold, 0), {0.0, end}, {100.0 * threshold, 100.0 * threshold}, true, 2});
  }
  // Every point in view, with room below them for the legend (changes mostly rise).
  double bottom = 0.0, top = 0.0;
  for (const auto& x : p.series)
    for (double y : x.y) {
      bottom = std::min(bottom, y);
      top = std::max(top, y);
    }
  const double span = std::max(top - bottom, 1.0);
  p.yRange = std::make_pair(bottom - 0.9 * span, top + 0.05 * span);
  return p;
}

ReportPlot fleetTemperaturePlot(const FleetAxisReport& a) {
  const double d0 = firstDay(a);
  ReportPlot p;
  p.title = a.robot + " axis " + std::to_string(a.axis) + ": temperature of the daily logs";
  p.xLabel = "time [days since " + dateOf(d0) + "]";
  p.yLabel = "temperature [degC]";
  ReportSeries t{"temperature", {}, {}, false, 4};
  for (const auto& pt : a.points)
    if (pt.temperatureC) {
      t.x.push_back(pt.day - d0);
      t.y.push_back(*pt.temperatureC);
    }
  p.series = {t};
  return p;
}

Report fleetReport(const FleetRunResult& run, const std::string& manifest, const std::string& store) {
  Report r;
  r.title = "FlexArm fleet report";
  r.flexarmVersion = FLEXARM_VERSION;
  r.session = manifest;

  ReportSection summary;
  summary.title = "Run";
  summary.paragraphs.push_back("Manifest " + manifest + ", store " + store + ", engine " + toString(run.engine) + ": " +
                               std::to_string(run.analysed) + " new logs analysed, " + std::to_string(run.skipped) +
                               " already in the store, " + std::to_string(run.failed) + " failed, in " +
                               formatFixed(run.seconds, 1) + " s.");
  summary.paragraphs.push_back(
      "Each log is diagnosed against its axis' fault-free reference as in the seed's chapters 6 and 7 (recursive "
      "estimates of k_T, J_a and f_m, the robust, CUSUM and hypothesis tests, the decision of Section 7.5.2); the "
      "trends follow each parameter over days relative to theta_0. A step is a fault (J_a: a load change), a drift "
      "of f_m is wear; f_m is compared at the reference log's temperature, f_m = f_m0 (1 + alpha (T - T_ref)).");
  if (!run.failures.empty()) {
    ReportTable f{"Logs that could not be analysed", {"robot", "axis", "time", "log", "why"}, {}};
    for (const auto& x : run.failures) f.rows.push_back({x.robot, std::to_string(x.axis), x.time, x.log, x.message});
    summary.tables.push_back(f);
  }
  summary.values = {{"analysed", run.analysed}, {"skipped", run.skipped}, {"failed", run.failed}, {"seconds", run.seconds}};
  r.sections.push_back(summary);

  ReportSection maintenance;
  maintenance.title = "Maintenance at the next stop";
  ReportTable due{"Axes to service, the most urgent first", {"robot", "axis", "status", "parameter", "days to threshold", "what to do"}, {}};
  std::vector<const FleetAxisReport*> urgent;
  for (const auto& a : run.axes)
    if (a.trend.serviceAtNextStop) urgent.push_back(&a);
  std::stable_sort(urgent.begin(), urgent.end(), [](const FleetAxisReport* x, const FleetAxisReport* y) {
    return x->trend.daysToThreshold.value_or(1e9) < y->trend.daysToThreshold.value_or(1e9);
  });
  for (const auto* a : urgent)
    due.rows.push_back({a->robot, std::to_string(a->axis), a->trend.status, a->trend.parameter,
                        a->trend.daysToThreshold ? formatFixed(*a->trend.daysToThreshold, 1) : "-", a->trend.suggestion});
  if (urgent.empty()) maintenance.paragraphs.push_back("No axis needs service at the next stop.");
  else maintenance.tables.push_back(due);
  r.sections.push_back(maintenance);

  ReportSection status;
  status.title = "Every axis";
  ReportTable t{"Status of every axis", {"robot", "axis", "logs", "status", "parameter", "since", "change", "days to threshold"}, {}};
  for (const auto& a : run.axes) {
    const auto& tr = a.trend;
    std::string change = "-";
    if (tr.stepSize) change = "step " + percentText(*tr.stepSize);
    if (tr.slopePerDay) change = formatSignificant(100.0 * *tr.slopePerDay, 3) + " %/day";
    t.rows.push_back({a.robot, std::to_string(a.axis), std::to_string(a.logs), tr.status,
                      tr.parameter.empty() ? "-" : tr.parameter, tr.since ? dateOf(*tr.since) : "-", change,
                      tr.daysToThreshold ? formatFixed(*tr.daysToThreshold, 1) : "-"});
  }
  status.tables.push_back(t);
  r.sections.push_back(status);

  for (const auto& a : run.axes) {
    if (a.trend.status == "healthy") continue;
    ReportSection s;
    s.title = a.robot + " axis " + std::to_string(a.axis) + ": " + a.trend.status + " in " + a.trend.parameter;
    s.paragraphs.push_back(a.trend.evidence);
    s.paragraphs.push_back("Suggestion: " + a.trend.suggestion + ".");
    if (!a.trend.caveat.empty()) s.paragraphs.push_back("Caveat: " + a.trend.caveat);
    if (const auto* series = a.trend.find(a.trend.parameter)) s.plots.push_back(fleetTrendPlot(a, *series, a.trend.threshold));
    if (a.trend.parameter == "f_m") s.plots.push_back(fleetTemperaturePlot(a));
    s.values = fleetAxisJson(a);
    r.sections.push_back(s);
  }
  return r;
}

}  // namespace flexarm
