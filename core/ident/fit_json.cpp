#include "core/ident/fit_json.h"

#include <cmath>

namespace flexarm {

using nlohmann::json;

namespace {

json finiteOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// Every experiment of a list: its file, its range (s, first and last sample), its samples and
// its fit % both ways.
json experimentsJson(const std::vector<FitValidation>& list, const std::vector<std::string>& names, bool validation) {
  json a = json::array();
  for (std::size_t i = 0; i < list.size(); ++i) {
    const PreparedData& d = list[i].data;
    const SampleRange& range = validation ? d.validation : d.estimation;
    const std::size_t given = list[i].given;
    a.push_back({{"log", given < names.size() ? names[given] : std::string()},
                 {"range_s", {d.timeAt(range.begin), d.timeAt(range.end - 1)}},
                 {"samples", range.size()},
                 {"fit_percent", fitPercentJson(list[i].fitPercent)},
                 {"fit_percent_nrmse", fitPercentJson(list[i].fitPercentNrmse)}});
  }
  return a;
}

// The effects with their estimated values: {"name", "spec" (for --effect), "parameters":
// {NAME: {"value", "std", "lower", "upper", "free", "unit"}}}.
json effectsJson(const FitResult& fit) {
  json effects = json::array();
  for (const auto& e : fit.effects) {
    json values = json::object();
    for (const auto& p : fit.parameters)
      if (p.effect == toString(e.kind))
        values[p.name] = {{"value", p.value}, {"std", p.std}, {"lower", p.lower},
                          {"upper", p.upper}, {"free", p.free}, {"unit", p.unit}};
    effects.push_back({{"name", toString(e.kind)}, {"spec", toString(e)}, {"parameters", values}});
  }
  return effects;
}

json controllerJson(const FitResult& fit) {
  if (!fit.controller) return nullptr;
  return {{"rate_hz", fit.controller->rateHz},
          {"kp", fit.controller->kp},
          {"kv", fit.controller->kv},
          {"ti", fit.controller->ti},
          {"torque_fit_percent", fitPercentJson(fit.controllerFitPercent)},
          {"source", fit.controllerSource}};
}

// Inverse dynamics (the method's result, or the start it gave): its parameter rows, its
// filters and the torque it explains.
json idimJson(const FitResult& fit) {
  if (!fit.idim) return nullptr;
  const IdimResult& e = *fit.idim;
  json rows = json::object();
  for (const auto& p : e.parameters)
    rows[p.name] = {{"value", p.value}, {"std", p.std}, {"lower", p.lower}, {"upper", p.upper}, {"unit", p.unit}};
  return {{"parameters", rows},
          {"cutoff_hz", e.cutoffHz},
          {"decimation", e.decimation},
          {"samples", e.samples},
          {"relative_error_percent", e.relativeError},
          {"torque_fit_percent", e.torqueFitPercent},
          {"condition_number", e.conditionNumber},
          {"message", e.message}};
}

// A state-space fit's subspace start: the singular values, every order tried and the one chosen.
json subspaceJson(const FitResult& fit) {
  if (!fit.subspace) return nullptr;
  const SubspaceEstimate& e = *fit.subspace;
  json orders = json::array();
  for (const auto& o : e.orders)
    orders.push_back({{"order", o.order},
                      {"loss", finiteOrNull(o.loss)},
                      {"mdl", finiteOrNull(o.mdl)},
                      {"stable_predictor", o.stablePredictor}});
  return {{"method", toString(e.method)},
          {"ok", e.ok},
          {"message", e.message},
          {"horizon", e.horizon},
          {"singular_values", e.singularValues},
          {"orders", orders},
          {"chosen_order", e.chosenOrder},
          {"order_reason", e.orderReason}};
}

// The deflection check: the fit's own keys, of the deflection r phi_m - phi_a.
json deflectionJson(const FitResult& fit) {
  if (!fit.deflection) return nullptr;
  const DeflectionCheck& c = *fit.deflection;
  return {{"fit_percent", fitPercentJson(c.fitPercent)},
          {"fit_percent_validation", fitPercentJson(c.fitPercentValidation)},
          {"fit_percent_nrmse", fitPercentJson(c.fitPercentNrmse)},
          {"fit_percent_validation_nrmse", fitPercentJson(c.fitPercentValidationNrmse)},
          {"rms_estimation", finiteOrNull(c.rmsEstimation)},
          {"rms_validation", finiteOrNull(c.rmsValidation)},
          {"measured_rms", finiteOrNull(c.measuredRms)},
          {"gear_ratio", c.gearRatio},
          {"skew_s", c.skewSeconds},
          {"skew_std_s", c.skewStd},
          {"fit_percent_without_skew", fitPercentJson(c.fitPercentWithoutSkew)}};
}

// The residual tests (99 %) on the first validation experiment, else the estimation range.
json residualsJson(const FitResult& fit) {
  if (!fit.residuals) return nullptr;
  const ResidualAnalysis& a = *fit.residuals;
  return {{"on", fit.residualsOnValidation ? "validation" : "estimation"},
          {"white", a.white},
          {"independent", a.independent},
          {"whiteness_statistic", finiteOrNull(a.whitenessStatistic)},
          {"whiteness_threshold", finiteOrNull(a.whitenessThreshold)},
          {"independence_statistic", finiteOrNull(a.independenceStatistic)},
          {"independence_threshold", finiteOrNull(a.independenceThreshold)},
          {"verdict", a.verdict}};
}

}  // namespace

json fitPercentJson(const std::optional<double>& percent) { return percent ? finiteOrNull(*percent) : json(nullptr); }

void addFitParameters(json& j, const std::vector<FitParameter>& rows) {
  json values = json::object(), stds = json::object(), table = json::array();
  for (const auto& p : rows) {
    values[p.name] = p.value;
    stds[p.name] = p.std;
    json q = {{"name", p.name},
              {"unit", p.unit},
              {"value", finiteOrNull(p.value)},
              {"std", finiteOrNull(p.std)},
              {"lower", finiteOrNull(p.lower)},
              {"upper", finiteOrNull(p.upper)},
              {"free", p.free},
              {"determined", p.determined},
              {"undetermined", p.determined ? json(nullptr) : json(p.undetermined)}};
    if (!p.effect.empty()) q["effect"] = p.effect;
    table.push_back(q);
  }
  j["parameters"] = values;
  j["std"] = stds;
  j["parameter_rows"] = table;
}

json fitResultJson(const FitResult& fit, const FitLogNames& logs) {
  json j = {{"format", kFitJsonFormat},
            {"version", kFitJsonVersion},
            {"status", toString(fit.status)},
            {"termination", toString(fit.termination)},
            {"message", fit.message},
            {"model", fit.modelName()}};
  if (fit.status != FitStatus::Ok) return j;
  const auto& s = fit.summary;
  std::size_t samples = 0;  // of every estimation experiment
  for (const auto& e : fit.estimation) samples += e.data.estimation.size();
  json codes = json::array();
  for (std::size_t i = 0; i < fit.warnings.size(); ++i) codes.push_back(toString(fit.warningCode(i)));
  j.update({{"idim", idimJson(fit)},
            {"idim_start", fit.idimNote},
            {"deflection", deflectionJson(fit)},
            {"plausibility", fit.plausibility},
            {"effects", effectsJson(fit)},
            {"fit_percent", fitPercentJson(fit.fitEstimation)},
            {"fit_percent_validation", fitPercentJson(fit.fitValidation())},
            {"fit_percent_nrmse", fitPercentJson(fit.fitEstimationNrmse)},
            {"fit_percent_validation_nrmse", fitPercentJson(fit.fitValidationNrmse())},
            {"fit_percent_experiments", experimentsJson(fit.estimation, logs.estimation, false)},
            {"fit_percent_validation_experiments", experimentsJson(fit.validation, logs.validation, true)},
            {"warnings", fit.warnings},
            {"warning_codes", codes},
            {"loss", s.loss},
            {"fpe", s.fpe},
            {"aic", s.aic},
            {"notches_rad_s", fit.notches},
            {"peaks_rad_s", fit.peaks},
            {"iterations", s.iterations},
            {"seconds", fit.seconds},
            {"sample_time_s", fit.data.sampleTime},
            {"samples_estimation", samples},
            {"samples_validation", fit.validation.empty() ? 0 : fit.validation.front().data.validation.size()},
            {"data", fit.data.note()},
            {"closed_loop", fit.data.closedLoop},
            {"closed_loop_method", fit.method ? json(toString(*fit.method)) : json(nullptr)},
            {"closed_loop_description", fit.methodDescription},
            {"closed_loop_reason", fit.methodReason},
            {"controller", controllerJson(fit)},
            {"reference_fit_percent", fitPercentJson(fit.referenceFitPercent)},
            {"covariance", toString(fit.covarianceKind)},
            {"subspace", subspaceJson(fit)},
            {"residuals", residualsJson(fit)}});
  addFitParameters(j, fit.parameters);
  j["undetermined_direction"] = fit.undeterminedDirection.empty() ? json(nullptr) : json(fit.undeterminedDirection);
  return j;
}

}  // namespace flexarm
