#include "core/discovery/discovery_json.h"

#include <cmath>

namespace flexarm {

namespace {

using nlohmann::json;

json num(double v) { return std::isfinite(v) ? json(v) : json(); }

json kinds(const std::vector<EffectKind>& ks) {
  json a = json::array();
  for (EffectKind k : ks) a.push_back(toString(k));
  return a;
}

json specs(const std::vector<Effect>& es) {
  json a = json::array();
  for (const Effect& e : es) a.push_back(toString(e));
  return a;
}

}  // namespace

const char* discoveryFitPercentDefinition() {
  return "fit_percent: the seed's (5.2), 100 (1 - |y - yhat| / |y|) on the motor velocity (core/ident/evaluation.h "
         "fitPercents); fit_percent_nrmse: MATLAB compare's NRMSE fit, 100 (1 - |y - yhat| / |y - mean(y)|)";
}

json discoveryScoreJson(const DiscoveryScore& s) {
  return {{"fit_percent", num(s.fitPercent)},
          {"fit_percent_validation", num(s.fitPercentValidation)},
          {"fit_percent_nrmse", num(s.fitPercentNrmse)},
          {"fit_percent_validation_nrmse", num(s.fitPercentValidationNrmse)},
          {"rms_estimation", num(s.rmsEstimation)},
          {"rms_validation", num(s.rmsValidation)}};
}

json effectEstimateJson(const EffectParameterEstimate& p) {
  return {{"name", p.name}, {"unit", p.unit},         {"value", num(p.value)},      {"std", num(p.std)},
          {"lower", num(p.lower)}, {"upper", num(p.upper)}, {"estimated", p.estimated}, {"derived", p.derived}};
}

json effectEstimatesJson(const std::vector<EffectParameterEstimate>& ps) {
  json a = json::array();
  for (const auto& p : ps) a.push_back(effectEstimateJson(p));
  return a;
}

json effectSizeJson(const EffectSize& s) {
  return {{"torque_rms", num(s.torqueRms)},
          {"friction_rms", num(s.frictionRms)},
          {"spring_rms", num(s.springRms)},
          {"share", num(s.share())}};
}

json confirmationJson(const Confirmation& c) {
  return {{"ran", c.ran},
          {"confirmed", c.confirmed},
          {"held_out_data", c.heldOutData},
          {"rms_before", num(c.rmsBefore)},
          {"rms_after", num(c.rmsAfter)},
          {"held_out_z", num(c.heldOutZ)},
          {"held_out_passes", c.heldOutPasses},
          {"test", c.test},
          {"value", num(c.value)},
          {"std", num(c.std)},
          {"z", num(c.z)},
          {"fitted", num(c.fitted)},
          {"unit", c.unit},
          {"rivals", c.rivals},
          {"specific_passes", c.specificPasses},
          {"text", c.text}};
}

json candidateJson(const CandidateFit& c) {
  return {{"effect", toString(c.kind)},
          {"spec", c.effect.values.empty() ? json() : json(toString(c.effect))},
          {"termination", toString(c.termination)},
          {"parameters", effectEstimatesJson(c.parameters)},
          {"magnitude", effectEstimateJson(c.magnitude)},
          {"size", effectSizeJson(c.size)},
          {"parameter_count", c.parameterCount},
          {"loss_est", num(c.lossEst)},
          {"aic", num(c.aic)},
          {"f", num(c.fStatistic)},
          {"f_threshold", num(c.fThreshold)},
          {"held_out_z", num(c.heldOutZ)},
          {"rho", num(c.rho)},
          {"survival_f", num(c.survivalF)},
          {"score", discoveryScoreJson(c.score)},
          {"interval_excludes_zero", c.intervalExcludesZero},
          {"matters", c.matters},
          {"significant", c.significant},
          {"confirmation", c.confirmation.ran ? confirmationJson(c.confirmation) : json()},
          {"reason", c.reason}};
}

json discoveryResultJson(const DiscoveryResult& r) {
  json j;
  j["schema"] = kDiscoveryJsonSchema;
  j["termination"] = toString(r.termination);
  j["message"] = r.message;
  j["effect"] = r.effect ? toString(*r.effect) : "none";
  j["effects"] = json::array();
  for (const auto& f : r.found)
    j["effects"].push_back({{"effect", toString(f.kind)},
                            {"spec", toString(f.effect)},
                            {"parameters", effectEstimatesJson(f.parameters)},
                            {"magnitude", effectEstimateJson(f.magnitude)},
                            {"size", effectSizeJson(f.size)},
                            {"evidence", f.evidence},
                            {"confirmed", f.confirmation.confirmed},
                            {"confirmation", confirmationJson(f.confirmation)},
                            {"before", discoveryScoreJson(f.before)},
                            {"after", discoveryScoreJson(f.after)}});
  j["also_tried"] = json::array();
  for (const auto& t : r.alsoTried)
    j["also_tried"].push_back({{"round", t.round},
                               {"effect", toString(t.kind)},
                               {"spec", t.effect.values.empty() ? json() : json(toString(t.effect))},
                               {"magnitude", effectEstimateJson(t.magnitude)},
                               {"size", effectSizeJson(t.size)},
                               {"reason", t.reason}});
  j["stop_reason"] = r.stopReason;
  j["tied"] = kinds(r.tied);
  j["evidence"] = r.evidence;
  j["validation_data"] = r.validationData;
  j["has_validation"] = r.hasValidation;
  j["held_out_split"] = r.heldOutSplit;
  j["fit_percent_definition"] = discoveryFitPercentDefinition();
  j["fit_basis"] = r.fitBasis;
  j["base"] = discoveryScoreJson(r.base);
  j["base"]["loss"] = num(r.baseLoss);
  j["base"]["aic"] = num(r.baseAic);
  j["base"]["parameter_count"] = r.baseParameterCount;
  j["augmented"] = discoveryScoreJson(r.augmented);
  j["augmented"]["effects"] = specs(r.augmentedEffects);
  j["best"] = r.best;
  j["candidates"] = json::array();
  for (const auto& c : r.candidates) j["candidates"].push_back(candidateJson(c));
  j["rounds"] = json::array();
  for (const auto& d : r.rounds) {
    json cands = json::array();
    for (const auto& c : d.candidates) cands.push_back(candidateJson(c));
    j["rounds"].push_back({{"effects", specs(d.effects)},
                           {"effect", d.effect ? toString(*d.effect) : "none"},
                           {"best", d.best},
                           {"decision", d.decision},
                           {"evidence", d.evidence},
                           {"tied", kinds(d.tied)},
                           {"score", discoveryScoreJson(d.score)},
                           {"aic", num(d.aic)},
                           {"candidates", cands}});
  }
  j["disagreement"] = {{"summary", r.disagreement.summary},
                       {"white", r.disagreement.tests.white},
                       {"independent", r.disagreement.tests.independent},
                       {"residual_peak_rad_s", num(r.disagreement.spectrumPeakRadS)},
                       {"correlation_sign_velocity", num(r.disagreement.correlationSignVelocity)},
                       {"rms_low_speed", num(r.disagreement.rmsLowSpeed)},
                       {"rms_high_speed", num(r.disagreement.rmsHighSpeed)},
                       {"resonances_rad_s", r.disagreement.resonancesRadS}};
  j["sample_time"] = num(r.sampleTime);
  return j;
}

}  // namespace flexarm
