#include "core/diagnosis/diagnosis_json.h"

#include <algorithm>
#include <cmath>

namespace flexarm {

namespace {

nlohmann::json optionalTime(const std::optional<double>& t) {
  return t ? nlohmann::json(*t) : nlohmann::json();
}

nlohmann::json finiteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json thresholdsJson(DiagnosisTest t, const DiagnosisOptions& o) {
  switch (t) {
    case DiagnosisTest::Classical: return {{"k", o.classicalK}, {"factors", o.classicalScales}};
    case DiagnosisTest::Robust:
      return {{"k", o.robustK}, {"lambda", o.robustLambda}, {"factors", o.robustScales}};
    case DiagnosisTest::Cusum:
      return {{"alpha1", o.cusumAlpha1}, {"alpha2", o.cusumAlpha2}, {"factors", o.cusumScales}};
    case DiagnosisTest::Joint:
      return {{"k", o.jointK}, {"scale", o.jointScale}, {"lambda", o.robustLambda}};
    case DiagnosisTest::Hypothesis:
      return {{"threshold", o.hypothesisThreshold},
              {"window", toString(o.window)},
              {"window_s", o.window == HypothesisWindow::Sliding ? nlohmann::json(o.windowS) : nlohmann::json()}};
  }
  return nlohmann::json::object();
}

}  // namespace

nlohmann::json diagnosisResultJson(const DiagnosisResult& r) {
  nlohmann::json j;
  j["verdict"] = r.verdictName();
  j["alarm_time_s"] = optionalTime(r.verdictTime());
  // The tests' own verdict, which model_mismatch keeps from being reported as a fault.
  j["tests_verdict"] = r.decision.verdict ? nlohmann::json(r.faults.at(*r.decision.verdict)) : nlohmann::json("none");
  // For a change detected but not isolated: the parameters the tests name on their own.
  j["named_by_tests"] = r.namedByTests();
  const ModelCheck& mc = r.modelCheck;
  j["model_check"] = {{"checked", mc.checked},
                      {"fits", !mc.mismatch},
                      {"time_s", optionalTime(mc.time)},
                      {"threshold", mc.threshold},
                      {"median_ratio", mc.medianRatio},
                      {"peak_ratio", mc.peakRatio},
                      {"white", mc.residualsTested ? nlohmann::json(mc.residuals.white) : nlohmann::json()},
                      {"independent", mc.residualsTested ? nlohmann::json(mc.residuals.independent) : nlohmann::json()},
                      {"what", mc.what},
                      {"message", mc.message}};
  const TemperatureCorrection& tc = r.temperature;
  j["temperature"] = {{"monitored_c", tc.monitoredC ? nlohmann::json(*tc.monitoredC) : nlohmann::json()},
                      {"reference_c", tc.referenceC ? nlohmann::json(*tc.referenceC) : nlohmann::json()},
                      {"alpha_per_c", tc.model.alpha},
                      {"alpha_std_per_c", tc.model.alphaStd},
                      {"alpha_logs", tc.model.logs},
                      {"applied", tc.applied},
                      {"f_m_reference", tc.fmReference},
                      {"f_m_expected", tc.fmExpected},
                      {"message", tc.message}};
  j["detection_time_s"] = optionalTime(r.decision.detectionTime);
  j["termination"] = toString(r.termination);
  j["message"] = r.message;
  j["summary"] = r.summary();
  j["window"] = {{"kind", toString(r.window)},
                 {"seconds", r.window == HypothesisWindow::Sliding ? nlohmann::json(r.windowS) : nlohmann::json()},
                 {"text", r.windowText()}};
  nlohmann::json theta0 = nlohmann::json::object(), sigma0 = nlohmann::json::object(),
                 estimates = nlohmann::json::object();
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const auto& p = r.parameters[i];
    theta0[p.name] = r.theta0[i];
    sigma0[p.name] = i < r.sigma0.size() ? r.sigma0[i] : 0.0;
    nlohmann::json e = {{"model_name", p.modelName}, {"unit", p.unit}, {"theta0", r.theta0[i]}};
    if (i < r.estimates.theta.size() && !r.estimates.theta[i].empty()) {
      e["final"] = r.estimates.theta[i].back();
      e["sigma"] = r.estimates.sigma[i].back();
      e["change_percent"] = 100.0 * (r.estimates.theta[i].back() / r.theta0[i] - 1.0);
    }
    estimates[p.name] = e;
  }
  j["reference"] = {{"source", r.referenceSource},
                    {"theta0", theta0},
                    {"sigma0", sigma0},
                    {"lambda0", r.noiseVariance}};
  j["estimates"] = estimates;
  nlohmann::json decide = nlohmann::json::array();
  for (DiagnosisTest t : r.decisionTests) decide.push_back(toString(t));
  j["decision"] = {{"tests", decide},
                   {"statement_final", r.decision.statement.empty()
                                           ? nlohmann::json()
                                           : nlohmann::json(modeSetString(r.decision.statement.back(), r.faults))},
                   {"detection_events", r.decision.detectionEvents},
                   {"confirm_s", r.options.confirmS},
                   {"settle_s", r.options.settleS}};
  nlohmann::json tests = nlohmann::json::object();
  for (std::size_t k = 0; k < r.tests.size() && k < r.outcomes.size(); ++k) {
    const TestTrace& t = r.tests[k];
    const TestOutcome& o = r.outcomes[k];
    nlohmann::json columns = nlohmann::json::object();
    for (std::size_t q = 0; q < t.columns.size(); ++q) {
      const auto& ratio = t.ratio[q];
      const double maxRatio = ratio.empty() ? 0.0 : *std::max_element(ratio.begin(), ratio.end());
      columns[t.columns[q]] = {
          {"first_alarm_s", optionalTime(o.firstAlarm[q])},
          {"alarms", o.alarmEvents[q]},
          {"max_ratio", finiteOrNull(maxRatio)},
          {"final_statistic", t.statistic[q].empty() ? nlohmann::json() : finiteOrNull(t.statistic[q].back())},
          {"final_threshold", t.threshold[q].empty() ? nlohmann::json() : finiteOrNull(t.threshold[q].back())}};
    }
    tests[toString(t.test)] = {
        {"verdict", o.verdict ? r.faults[*o.verdict] : "none"},
        {"alarm_time_s", optionalTime(o.verdictTime)},
        {"detection_time_s", optionalTime(o.detectionTime)},
        {"detection_events", o.detectionEvents},
        {"thresholds", thresholdsJson(t.test, r.options)},
        {"columns", columns}};
  }
  j["tests"] = tests;
  j["samples"] = r.time.size();
  j["seconds"] = r.seconds;
  return j;
}

namespace {

nlohmann::json pointJson(const CalibrationPoint& p) {
  return {{"scale", p.scale},
          {"threshold", p.threshold},
          {"false_alarms", p.falseAlarms},
          {"false_alarms_per_hour", p.falseAlarmsPerHour},
          {"false_alarms_per_hour_upper95", finiteOrNull(p.falseAlarmsPerHourUpper)},
          {"isolated_fraction", p.isolatedFraction},
          {"wrong_fraction", p.wrongFraction},
          {"median_delay_s", finiteOrNull(p.medianDelayS)},
          {"p95_delay_s", finiteOrNull(p.p95DelayS)}};
}

nlohmann::json perFault(const std::vector<std::string>& faults, const std::vector<double>& isolated,
                        const std::vector<double>& delay) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < faults.size() && i < isolated.size() && i < delay.size(); ++i)
    j[faults[i]] = {{"isolated_fraction", isolated[i]}, {"median_delay_s", finiteOrNull(delay[i])}};
  return j;
}

}  // namespace

nlohmann::json calibrationJson(const CalibrationResult& r) {
  nlohmann::json tests = nlohmann::json::object();
  for (const auto& t : r.tests) {
    nlohmann::json curve = nlohmann::json::array();
    for (const auto& p : t.curve) curve.push_back(pointJson(p));
    tests[toString(t.test)] = {
        {"met", t.met},
        {"column_scales", t.columnScales},
        {"thresholds", t.thresholds},
        {"calibrated", pointJson(t.point)},
        {"per_fault", perFault(r.faults, t.isolatedFraction, t.medianDelayS)},
        {"curve", curve}};
  }
  return {{"termination", toString(r.termination)},
          {"message", r.message},
          {"conditions", r.conditions},
          {"healthy_runs", r.healthyRuns},
          {"faulty_runs", r.faultyRuns},
          {"healthy_hours", r.healthyHours},
          {"noise_scale", r.noiseScale},
          {"decision", pointJson(r.decision)},
          {"decision_per_fault", perFault(r.faults, r.decisionIsolatedFraction, r.decisionMedianDelayS)},
          {"tests", tests},
          {"seconds", r.seconds}};
}

}  // namespace flexarm
