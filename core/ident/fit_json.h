#pragma once
// A fit result as JSON: the one writer behind `flexarm fit --json`, the report's data of a
// session's fit ("fit" in its section) and the numbers a session stores with a fit request.
// One key per fact in all of them (schema "flexarm-fit", version kFitJsonVersion):
//   format, version, status (FitStatus), termination, message, iterations, model
//   parameters {NAME: value}, std {NAME: std}, parameter_rows [{name, unit, value, std, lower,
//     upper, free, effect (an effect's parameter only)}] at the fit's level (99 %)
//   effects [{name, spec, parameters {NAME: {value, std, lower, upper, free, unit}}}]
//   loss, fpe, aic, covariance (white | sandwich: the covariance (4.37) or the one that allows
//     coloured errors)
//   fit_percent, fit_percent_validation: the seed's (5.2) on the estimation data (every
//     estimation experiment together) and the first validation experiment; *_nrmse: MATLAB
//     compare's NRMSE fit of the same errors; null when undefined (an unstable G)
//   fit_percent_experiments, fit_percent_validation_experiments [{log, range_s [first, last],
//     samples, fit_percent, fit_percent_nrmse}]
//   notches_rad_s, peaks_rad_s, warnings [sentence], warning_codes [FitWarning], plausibility
//   sample_time_s, samples_estimation, samples_validation, data (how they were prepared)
//   closed_loop, closed_loop_method, closed_loop_description, closed_loop_reason, controller,
//     reference_fit_percent; idim, idim_start; deflection; residuals; seconds (the run's time)
//   subspace (state-space fits, else null): {method, ok, message, horizon, singular_values,
//     orders [{order, loss, mdl, stable_predictor}], chosen_order, order_reason}
// Version 1 was the command line's alone; version 2 adds format, version, status,
// parameter_rows, warning_codes and residuals, and sessions and reports took its names
// (fit_estimation_percent -> fit_percent, fit_validation_percent -> fit_percent_validation,
// their _nrmse twins likewise, a stored "parameters" list -> parameter_rows).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/ident/fit.h"

namespace flexarm {

inline constexpr const char* kFitJsonFormat = "flexarm-fit";
inline constexpr int kFitJsonVersion = 2;

// The file of each experiment of a fit in FitOptions order (so of FitResult::estimation and
// validation), as the JSON names them ("log"); a missing one is written "".
struct FitLogNames {
  std::vector<std::string> estimation, validation;
};

// The whole result. A fit that gave no estimate (status other than ok) has format, version,
// status, termination, message and model only.
nlohmann::json fitResultJson(const FitResult& result, const FitLogNames& logs = {});

// The pieces a stored fit keeps (core/session/fit_request.h), written by the same code:
// "parameters", "std" and "parameter_rows" of rows into j; a fit % as a number or null.
void addFitParameters(nlohmann::json& j, const std::vector<FitParameter>& rows);
nlohmann::json fitPercentJson(const std::optional<double>& percent);

}  // namespace flexarm
