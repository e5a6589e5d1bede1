#pragma once
// A discovery result as JSON: the one writer `flexarm discover --json`, the session part
// "discovery" (core/session/discovery_part.h) and the report's data use alike, so the same
// result gives the same bytes everywhere. One key per fact; effect parameters are a list in
// the order of effectParameters(effect), then the quantities derived from them. Numbers that
// are not finite are null. Fit % is the seed's (5.2) as core/ident/evaluation.h defines it
// (fitPercents: "fit_percent*"), beside MATLAB compare's NRMSE fit ("*_nrmse"); the result
// says so under "fit_percent_definition". The wall-clock time of the run is not part of it
// (two runs of the same request give the same bytes).
#include <nlohmann/json.hpp>

#include "core/discovery/discovery.h"

namespace flexarm {

// The version of the shape below; readers accept older ones they know.
constexpr int kDiscoveryJsonSchema = 2;

nlohmann::json discoveryResultJson(const DiscoveryResult& result);

// The parts, for readers and the report.
nlohmann::json discoveryScoreJson(const DiscoveryScore& s);
nlohmann::json effectEstimatesJson(const std::vector<EffectParameterEstimate>& ps);
nlohmann::json effectEstimateJson(const EffectParameterEstimate& p);
nlohmann::json effectSizeJson(const EffectSize& s);
nlohmann::json confirmationJson(const Confirmation& c);
nlohmann::json candidateJson(const CandidateFit& c);

// The definition of fit % the scores carry, in words (the seed's (5.2) through
// core/ident/evaluation.h's fitPercents).
const char* discoveryFitPercentDefinition();

}  // namespace flexarm
