#pragma once
// Compare, residual analysis and sensitivity study results as JSON, as `flexarm compare |
// residuals | sensitivity --json` print them and sessions and reports keep them: one key per
// fact, the same in every output, non-finite numbers as null. No per-sample traces.
#include <nlohmann/json.hpp>

#include "core/compare/compare.h"
#include "core/compare/residual_study.h"
#include "core/compare/sensitivity_study.h"

namespace flexarm {

// The schema version every writer below puts under "schema".
inline constexpr int kCompareSchemaVersion = 1;

// {"kind": "simulation" | "prediction" | "observer_prediction", "horizon" (null for a
// simulation), "observer_hz" (null without), "start": "log" | "range", "effects",
// "means_removed", "rate_hz", "data", "range", "text" (fitBasisText)}.
nlohmann::json fitBasisJson(const FitBasis& basis);
// {"fit_percent" (5.2), "fit_percent_nrmse", "basis"}.
nlohmann::json fitFigureJson(const FitFigure& figure);

// {"schema", "termination", "code", "message", "data", "data_note", "range", "range_fell_back",
// "horizon", "output": {"name", "unit"}, "gear_ratio" (null without the arm-side encoder),
// "models": [{"name", "status", "message", "decimation", "rate_hz", "fit_percent",
// "fit_percent_nrmse", "basis", "deflection": {"fit_percent", "fit_percent_nrmse",
// "rms_error_rad", "measured_rms_rad", "gear_ratio"} or null}], "seconds"}.
nlohmann::json compareResultJson(const CompareResult& result);

// {"schema", "termination", "code", "message", "model", "data", "data_note", "range",
// "samples", "sample_time_s", "errors": "one_step_prediction" | "output_error", "lags",
// "autocorrelation", "autocorrelation_bound", "cross_lags", "cross_correlation",
// "cross_correlation_bound", "whiteness": {"statistic", "threshold", "passed"},
// "independence": {...}, "verdict", "seconds"}.
nlohmann::json residualsResultJson(const ResidualsResult& result);

// {"schema", "termination", "code", "message", "model", "data", "data_note", "range",
// "samples", "effects_left_out", "attraction": {"reference_loss", "fits", "termination",
// "message", "seconds", "parameters": [{"name", "lower_factor", "upper_factor", "lower_open",
// "upper_open", "fits"}]}, "monte_carlo": {"runs", "completed", "successes", "success_rate",
// "reference_loss", "termination", "message", "seconds"} or null, "seconds"}.
nlohmann::json sensitivityResultJson(const SensitivityResult& result);

}  // namespace flexarm
