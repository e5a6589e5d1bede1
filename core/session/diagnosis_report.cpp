// The report section of a diagnosis (diagnosis_part.h): verdict, thresholds and their
// false-alarm rate, each test's alarms, the decision table of Section 7.5.2, and the plots.
#include <algorithm>
#include <cmath>

#include "core/diagnosis/diagnosis_json.h"
#include "core/session/diagnosis_part.h"

namespace flexarm {

using nlohmann::json;

namespace {

std::string seconds(double t) { return formatFixed(t, 2) + " s"; }

ReportSeries series(const std::string& name, const std::vector<double>& t, std::vector<double> y,
                    bool dashed, int color) {
  ReportSeries s{name, t, std::move(y), dashed, color};
  thinSeries(s.x, s.y, 2500);
  return s;
}

// The test's thresholds per column in its own units, for the table.
std::string thresholdText(const DiagnosisResult& r, DiagnosisTest t, std::size_t column) {
  const DiagnosisOptions& o = r.options;
  switch (t) {
    case DiagnosisTest::Classical:
      return formatSignificant(o.classicalK * o.thresholdScale(t, column), 3) + " sigma";
    case DiagnosisTest::Robust:
      return formatSignificant(o.robustK * o.thresholdScale(t, column), 3) + " sigma (7.13)";
    case DiagnosisTest::Cusum:
      return "h = " + formatSignificant(o.cusumAlpha2 * o.thresholdScale(t, column), 3) + " theta_0";
    case DiagnosisTest::Hypothesis: return formatSignificant(o.hypothesisThreshold, 4);
    case DiagnosisTest::Joint:
      return formatSignificant(o.jointScale, 3) + " x chi2 quantile (" +
             formatSignificant(o.jointK, 3) + " sigma)";
  }
  return "";
}

}  // namespace

ReportSection diagnosisReportSection(const DiagnosisRun& run, const json& calibration) {
  const DiagnosisResult& r = run.result;
  ReportSection s;
  s.title = "Diagnosis (chapter 7)";
  s.paragraphs.push_back(r.summary());
  s.paragraphs.push_back("Reference: " + r.referenceSource + ".");
  s.values = diagnosisResultJson(r);
  // The time the run took is no result: a replayed report must equal the saved one.
  s.values.erase("seconds");

  // Thresholds and the false-alarm rate they were chosen for.
  ReportTable th{"Thresholds", {"Test", "Parameter", "Threshold", "False alarms per hour"}, {}};
  const bool calibrated = calibration.is_object() && calibration.contains("tests");
  for (const auto& t : r.tests) {
    std::string rate = "-";
    if (calibrated && calibration["tests"].contains(toString(t.test))) {
      const json& p = calibration["tests"][toString(t.test)]["calibrated"];
      rate = formatSignificant(p.value("false_alarms_per_hour", 0.0), 3) + " (95 % <= " +
             (p["false_alarms_per_hour_upper95"].is_number()
                  ? formatSignificant(p["false_alarms_per_hour_upper95"].get<double>(), 3)
                  : std::string("-")) +
             ")";
    }
    const std::size_t columns = t.test == DiagnosisTest::Hypothesis ? 1 : t.columns.size();
    for (std::size_t q = 0; q < columns; ++q)
      th.rows.push_back({toString(t.test), t.test == DiagnosisTest::Hypothesis ? "all" : t.columns[q],
                         thresholdText(r, t.test, q), q == 0 ? rate : ""});
  }
  s.tables.push_back(th);
  if (calibrated) {
    s.paragraphs.push_back("Thresholds calibrated on the simulator: " + calibration.value("conditions", std::string()) +
                           ". " + calibration.value("message", std::string()) + ".");
    s.values["calibration"] = calibration;
    if (calibration.is_object()) s.values["calibration"].erase("seconds");
  } else {
    s.paragraphs.push_back("Thresholds: " + defaultThresholdsProvenance() + ".");
    s.values["thresholds_provenance"] = defaultThresholdsProvenance();
  }

  // Each test's verdict and alarms.
  ReportTable tests{"Tests", {"Test", "Verdict", "Time", "First alarm per quantity (alarms)"}, {}};
  for (std::size_t k = 0; k < r.tests.size() && k < r.outcomes.size(); ++k) {
    const TestOutcome& o = r.outcomes[k];
    std::string alarms;
    for (std::size_t q = 0; q < r.tests[k].columns.size(); ++q)
      alarms += (q ? "; " : "") + r.tests[k].columns[q] + " " +
                (o.firstAlarm[q] ? seconds(*o.firstAlarm[q]) : std::string("-")) + " (" +
                std::to_string(o.alarmEvents[q]) + ")";
    tests.rows.push_back({toString(r.tests[k].test), o.verdict ? r.faults[*o.verdict] : "none",
                          o.verdictTime ? seconds(*o.verdictTime) : "-", alarms});
  }
  s.tables.push_back(tests);

  // The decision table of Section 7.5.2 at the verdict (or at the end).
  if (const TestTrace* h = r.trace(DiagnosisTest::Hypothesis); h && !r.time.empty()) {
    const std::size_t k = r.decision.verdictTime ? r.sampleAt(*r.decision.verdictTime) : r.time.size() - 1;
    const DecisionStructure d = DecisionStructure::hypothesis(r.faults);
    std::vector<bool> fired;
    for (const auto& ratio : h->ratio) fired.push_back(ratio[k] > 1.0);
    std::vector<std::string> header{"Mode"};
    for (const auto& c : h->columns) header.push_back(c);
    ReportTable table{"Decision structure (Section 7.5.2) at " + seconds(r.time[k]) + ": pattern " +
                          patternString(fired) + ", S = " + modeSetString(d.diagnose(fired), r.faults),
                      header, {}};
    for (std::size_t m = 1; m <= r.faults.size(); ++m) {
      std::vector<std::string> row{"F_" + r.faults[m - 1]};
      for (std::size_t c = 0; c < h->columns.size(); ++c) row.push_back(std::string(1, d.mark(m, c)));
      table.rows.push_back(row);
    }
    std::vector<std::string> nf{"NF"};
    for (std::size_t c = 0; c < h->columns.size(); ++c) nf.push_back(std::string(1, d.mark(0, c)));
    table.rows.push_back(nf);
    std::vector<std::string> now{"fired"};
    for (bool f : fired) now.push_back(f ? "1" : "0");
    table.rows.push_back(now);
    s.tables.push_back(table);
  }

  // Plots: estimates relative to theta_0 with the robust test's band, CUSUM against h,
  // hypothesis statistics against their level, the alarm timeline.
  const TestTrace* robust = r.trace(DiagnosisTest::Robust);
  for (std::size_t i = 0; i < r.parameters.size() && i < r.estimates.theta.size(); ++i) {
    const double t0 = r.theta0[i];
    auto percent = [t0](const std::vector<double>& v) {
      std::vector<double> out(v.size());
      for (std::size_t k = 0; k < v.size(); ++k) out[k] = 100.0 * (v[k] / t0 - 1.0);
      return out;
    };
    std::vector<ReportSeries> list{series("estimate", r.time, percent(r.estimates.theta[i]), false, 0)};
    if (robust && i < r.smoothed.size()) {
      list.push_back(series("smoothed (7.12)", r.time, percent(r.smoothed[i]), false, 1));
      std::vector<double> up(r.time.size()), down(r.time.size());
      for (std::size_t k = 0; k < up.size(); ++k) {
        up[k] = 100.0 * robust->threshold[i][k] / std::abs(t0);
        down[k] = -up[k];
      }
      list.push_back(series("threshold", r.time, up, true, 2));
      list.push_back(series("", r.time, down, true, 2));
    }
    s.plots.push_back(ReportPlot{r.parameters[i].name + " against theta_0", "time (s)", "change (%)",
                                 false, false, list});
  }
  if (const TestTrace* c = r.trace(DiagnosisTest::Cusum)) {
    std::vector<ReportSeries> list;
    for (std::size_t q = 0; q < c->columns.size(); ++q)
      list.push_back(series("g / h, " + c->columns[q], r.time, c->ratio[q], false, static_cast<int>(q)));
    list.push_back(series("h", {r.time.front(), r.time.back()}, {1.0, 1.0}, true, 5));
    s.plots.push_back(ReportPlot{"CUSUM (7.1), (7.15)-(7.17) against its threshold", "time (s)", "g / h",
                                 false, false, list});
  }
  if (const TestTrace* h = r.trace(DiagnosisTest::Hypothesis)) {
    std::vector<ReportSeries> list;
    for (std::size_t q = 0; q < h->columns.size(); ++q)
      list.push_back(series(h->columns[q], r.time, h->statistic[q], false, static_cast<int>(q)));
    list.push_back(series("threshold", {r.time.front(), r.time.back()},
                          {r.options.hypothesisThreshold, r.options.hypothesisThreshold}, true, 5));
    s.plots.push_back(ReportPlot{"Hypothesis tests (7.20)/(7.21), " + r.windowText(), "time (s)",
                                 "normalised sum", false, false, list});
  }
  std::vector<ReportSeries> timeline;
  for (std::size_t k = 0; k < r.tests.size() && k < r.outcomes.size(); ++k) {
    std::vector<double> y(r.time.size());
    for (std::size_t n = 0; n < y.size(); ++n)
      y[n] = static_cast<double>(k) + ((r.outcomes[k].statement[n] & 1u) ? 0.0 : 0.8);
    timeline.push_back(series(toString(r.tests[k].test), r.time, y, false, static_cast<int>(k)));
  }
  std::vector<double> d(r.time.size());
  for (std::size_t n = 0; n < d.size(); ++n)
    d[n] = static_cast<double>(r.tests.size()) + ((r.decision.statement[n] & 1u) ? 0.0 : 0.8);
  timeline.push_back(series("decision", r.time, d, false, 6));
  s.plots.push_back(ReportPlot{"Alarm timeline (raised: no fault rejected)", "time (s)", "test", false,
                               false, timeline});
  return s;
}

}  // namespace flexarm
