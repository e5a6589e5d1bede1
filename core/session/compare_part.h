#pragma once
// Compare, the residual analysis and the sensitivity study in sessions and reports: each as a
// part that stores what was asked (which models of the list, which range, the horizon, the
// lags, the runs) and replays it through runCompare, runResiduals and runSensitivityStudy
// (core/compare) on the session's data, and one report section per result, the same the
// panels export.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/compare/compare.h"
#include "core/compare/residual_study.h"
#include "core/compare/sensitivity_study.h"
#include "core/session/report.h"
#include "core/session/session_part.h"

namespace flexarm {

// The data a replayed evaluation runs on: the context's data with the session's ranges, named
// by the session's first log.
EvaluationData evaluationDataOf(const ReplayContext& context);
// The session's model list as the evaluations take it (modelListOf, session_models.h).
std::vector<EvaluatedModel> evaluatedModelsOf(const Session& session);

// Part "compare": {"models": [names] (empty: every model of the list), "range": "validation" |
// "estimation", "horizon": 0 (simulation) or K, "observer_hz": absent (each model's fit's),
// 0 (simulation) or a bandwidth, "provenance"}.
struct CompareSessionRequest {
  std::vector<std::string> models;
  DataRange range = DataRange::Validation;
  int horizon = 0;
  std::optional<double> observerHz;
  bool isValid(std::string* why) const;
};
nlohmann::json compareRequestToJson(const CompareSessionRequest& request);
std::optional<CompareSessionRequest> compareRequestFromJson(const nlohmann::json& j, std::string* why);

// Part "residuals": {"model": name (empty: the list's last), "range", "lags", "level"}.
struct ResidualsSessionRequest {
  std::string model;
  DataRange range = DataRange::Estimation;
  ResidualOptions options;
  bool isValid(std::string* why) const;
};
nlohmann::json residualsRequestToJson(const ResidualsSessionRequest& request);
std::optional<ResidualsSessionRequest> residualsRequestFromJson(const nlohmann::json& j, std::string* why);

// Part "sensitivity": {"model": name (empty: the list's last physical model), "runs", "seed",
// "result": sensitivityResultJson of what was found (shown when the data differ)}.
struct SensitivitySessionRequest {
  std::string model;
  int runs = 100;
  unsigned seed = 1;
  bool isValid(std::string* why) const;
};
nlohmann::json sensitivityRequestToJson(const SensitivitySessionRequest& request);
std::optional<SensitivitySessionRequest> sensitivityRequestFromJson(const nlohmann::json& j, std::string* why);

// The report sections: what was compared and how (every figure with its basis), the fit %
// table, the deflection table, the plot of the measured against each model's output; the
// correlations with their bounds and the two tests; the domain of attraction (Table 5.8) and
// the Monte-Carlo success rate. Their values are the JSON writers' (without run times).
ReportSection compareReportSection(const CompareResult& result);
ReportSection residualsReportSection(const ResidualsResult& result);
ReportSection sensitivityReportSection(const SensitivityResult& result);

std::shared_ptr<const SessionPart> makeComparePart();
std::shared_ptr<const SessionPart> makeResidualsPart();
std::shared_ptr<const SessionPart> makeSensitivityPart();

}  // namespace flexarm
