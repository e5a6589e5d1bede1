#include "core/compare/compare_json.h"

#include <cmath>

namespace flexarm {

using nlohmann::json;

namespace {

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json head(const char* termination, const char* code, const std::string& message) {
  return {{"schema", kCompareSchemaVersion}, {"termination", termination}, {"code", code}, {"message", message}};
}

}  // namespace

json fitBasisJson(const FitBasis& b) {
  const char* kind = b.observerHz > 0.0 ? "observer_prediction" : b.horizon > 0 ? "prediction" : "simulation";
  return {{"kind", kind},
          {"horizon", b.horizon > 0 ? json(b.horizon) : json(nullptr)},
          {"observer_hz", b.observerHz > 0.0 ? number(b.observerHz) : json(nullptr)},
          {"start", b.start == FitStart::LogStart ? "log" : "range"},
          {"effects", b.effects},
          {"means_removed", b.meansRemoved},
          {"rate_hz", number(b.rateHz)},
          {"data", b.data},
          {"range", b.range},
          {"text", fitBasisText(b)}};
}

json fitFigureJson(const FitFigure& f) {
  return {{"fit_percent", number(f.percent.seed52)},
          {"fit_percent_nrmse", number(f.percent.nrmse)},
          {"basis", fitBasisJson(f.basis)}};
}

json compareResultJson(const CompareResult& r) {
  json j = head(toString(r.termination), toString(r.code), r.message);
  j["data"] = r.dataName;
  j["data_note"] = r.dataNote;
  j["range"] = toString(r.range);
  j["range_fell_back"] = r.rangeFellBack;
  j["horizon"] = r.horizon;
  j["observer_hz"] = r.observerHz ? number(*r.observerHz) : json("auto");
  j["output"] = {{"name", r.outputName}, {"unit", r.outputUnit}};
  j["gear_ratio"] = r.measuredDeflection.size() ? number(r.gearRatio) : json(nullptr);
  json models = json::array();
  for (const auto& m : r.models) {
    json e = {{"name", m.name},
              {"status", toString(m.status)},
              {"message", m.message},
              {"decimation", m.decimation},
              {"rate_hz", m.sampleTime > 0.0 ? number(1.0 / m.sampleTime) : json(nullptr)}};
    if (m.fit) {
      const json f = fitFigureJson(*m.fit);
      for (auto it = f.begin(); it != f.end(); ++it) e[it.key()] = it.value();
    } else {
      e["fit_percent"] = nullptr;
      e["fit_percent_nrmse"] = nullptr;
      e["basis"] = nullptr;
    }
    e["deflection"] = nullptr;
    if (m.deflection)
      e["deflection"] = {{"fit_percent", number(m.deflection->figure.percent.seed52)},
                         {"fit_percent_nrmse", number(m.deflection->figure.percent.nrmse)},
                         {"rms_error_rad", number(m.deflection->rmsError)},
                         {"measured_rms_rad", number(m.deflection->measuredRms)},
                         {"gear_ratio", number(m.deflection->gearRatio)}};
    models.push_back(e);
  }
  j["models"] = models;
  j["seconds"] = number(r.seconds);
  return j;
}

json residualsResultJson(const ResidualsResult& r) {
  json j = head(toString(r.termination), toString(r.code), r.message);
  const ResidualAnalysis& a = r.analysis;
  j["model"] = r.modelName;
  j["data"] = r.dataName;
  j["data_note"] = r.dataNote;
  j["range"] = r.rangeText.empty() ? json(toString(r.range)) : json(r.rangeText);
  j["samples"] = r.samples;
  j["sample_time_s"] = number(r.sampleTime);
  j["errors"] = r.predictionErrors ? "one_step_prediction" : "output_error";
  const bool has = !a.lags.empty();
  auto numbers = [](const std::vector<double>& v) {
    json out = json::array();
    for (double x : v) out.push_back(number(x));
    return out;
  };
  j["lags"] = a.lags;
  j["autocorrelation"] = numbers(a.autocorrelation);
  j["autocorrelation_bound"] = has ? number(a.autocorrelationBound) : json(nullptr);
  j["cross_lags"] = a.crossLags;
  j["cross_correlation"] = numbers(a.crossCorrelation);
  j["cross_correlation_bound"] = has ? number(a.crossCorrelationBound) : json(nullptr);
  j["whiteness"] = has ? json{{"statistic", number(a.whitenessStatistic)},
                              {"threshold", number(a.whitenessThreshold)},
                              {"passed", a.white}}
                       : json(nullptr);
  j["independence"] = has ? json{{"statistic", number(a.independenceStatistic)},
                                 {"threshold", number(a.independenceThreshold)},
                                 {"passed", a.independent}}
                          : json(nullptr);
  j["verdict"] = a.verdict;
  j["seconds"] = number(r.seconds);
  return j;
}

json sensitivityResultJson(const SensitivityResult& r) {
  json j = head(toString(r.termination), toString(r.code), r.message);
  j["model"] = r.modelName;
  j["data"] = r.dataName;
  j["data_note"] = r.dataNote;
  j["range"] = r.rangeText;
  j["samples"] = r.samples;
  j["effects_left_out"] = r.effectsLeftOut;
  const AttractionResult& a = r.attraction;
  json params = json::array();
  for (const auto& p : a.parameters)
    params.push_back({{"name", p.name},
                      {"lower_factor", number(p.lowerFactor)},
                      {"upper_factor", number(p.upperFactor)},
                      {"lower_open", p.lowerOpen},
                      {"upper_open", p.upperOpen},
                      {"fits", p.fits}});
  j["attraction"] = {{"reference_loss", number(a.referenceLoss)},
                     {"fits", a.fits},
                     {"termination", toString(a.termination)},
                     {"message", a.message},
                     {"seconds", number(a.seconds)},
                     {"parameters", params}};
  j["monte_carlo"] = nullptr;
  if (r.monteCarlo) {
    const MonteCarloResult& m = *r.monteCarlo;
    j["monte_carlo"] = {{"runs", m.runs},
                        {"completed", m.completed},
                        {"successes", m.successes},
                        {"success_rate", number(m.successRate())},
                        {"reference_loss", number(m.referenceLoss)},
                        {"termination", toString(m.termination)},
                        {"message", m.message},
                        {"seconds", number(m.seconds)}};
  }
  j["seconds"] = number(r.seconds);
  return j;
}

}  // namespace flexarm
