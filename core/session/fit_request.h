#pragma once
// A fit as a session stores it: the options of the fit pipeline (core/ident/fit.h) without
// their data, a name, and the ranges it used. Replaying the request runs the pipeline on the
// session's analysed log: the same options on the same data give the same numbers as the Fit
// panel and `flexarm fit`.
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/common/progress.h"
#include "core/ident/fit.h"
#include "core/ident/fit_experiments.h"
#include "core/session/provenance.h"
#include "core/session/session.h"
#include "core/session/session_part.h"
#include "core/signal/id_data.h"

namespace flexarm {

// What a fit computed, kept with its request so that a report on other data shows these
// numbers instead of recomputing: the parameter table, loss, fit % and notches and peaks.
struct StoredFit {
  std::vector<FitParameter> parameters;
  double loss = 0.0;
  std::optional<double> fitEstimation, fitValidation;
  std::vector<double> notches, peaks;
};
StoredFit storedFitOf(const FitResult& result);
// The keys of fitResultJson (core/ident/fit_json.h) it has: {"format", "version",
// "parameters", "std", "parameter_rows", "loss", "fit_percent", "fit_percent_validation", "notches_rad_s",
// "peaks_rad_s"}; read back from those, or from a session written before version 2 of the fit
// schema ("parameters" a list of rows, "fit_estimation_percent", "fit_validation_percent").
nlohmann::json storedFitToJson(const StoredFit& fit);
std::optional<StoredFit> storedFitFromJson(const nlohmann::json& j, std::string* why);

struct FitRequest {
  std::string name;  // the model list entry the fit produced, e.g. "three-mass estimate"
  // Model, preparation and estimator; its experiments are left empty (see fitOptionsOf).
  FitOptions options;
  // The ranges the fit used (seconds); unset: the session's ranges, else the whole log / no
  // validation.
  std::optional<SecondsRange> estimation, validation;
  // More experiments beyond the analysed log's ranges (files and ranges, fit_experiments.h),
  // read when the request runs; absent in sessions written before them: none.
  std::vector<ExperimentSource> experiments;
  // The data the fit ran on and what it computed; absent in sessions written before them.
  std::optional<Provenance> provenance;
  std::optional<StoredFit> stored;

  bool physical() const { return options.model.kind == FitModelKind::Physical; }
  bool isValid(std::string* why) const;
};

// The pipeline's options for the request on data: one estimation experiment over its range
// and, with a validation range, one validation experiment on the same log.
FitOptions fitOptionsOf(const FitRequest& request, std::shared_ptr<const IdData> data);
// The request of options run on one log (its first estimation and validation experiments'
// ranges) and more experiments: the same options without their data, no name, provenance or
// result yet. fitOptionsOf of it on the same log gives the options back.
FitRequest fitRequestOf(const FitOptions& options, const std::vector<ExperimentSource>& more);

// {"name", "kind": "physical" | "black-box", "decimation", "max_iterations", "estimation_s",
// "validation_s", physical: "start" (a model with its effects), "effects_free" (per effect,
// [first value free, second value free]; absent without effects), "noise_model", "closed_loop" ("auto", "direct",
// "two-stage", "indirect"; absent in sessions written before it: "direct"), "random_starts",
// "seed", optional "start_values" {name: value} and "bounds" {name: [lower, upper], null an
// open end}; black-box: "structure", "orders"; "experiments" [{"log", "range_s": [A, B] or
// null, "validation"}] when there are more; "provenance" and "result" (StoredFit) when known}.
nlohmann::json fitRequestToJson(const FitRequest& request);
// The request described by j; nullopt with a sentence for a malformed one.
std::optional<FitRequest> fitRequestFromJson(const nlohmann::json& j, std::string* why);

// A black-box estimate stored with its request, so that a reopened session shows it without
// estimating again: {"parameters": [a.. b.. c.. d.. f..], "sample_time", "noise_variance",
// "covariance": rows or null}.
nlohmann::json polynomialEstimateToJson(const PolynomialModel& model);
// The estimate of a black-box request (its structure and orders) from j; nullopt with a
// sentence when j does not match the request.
std::optional<PolynomialModel> polynomialEstimateFromJson(const nlohmann::json& j, const FitRequest& request,
                                                          std::string* why);

// Runs the request on data (the session's preprocessed log) and its more experiments (read
// here, by their paths) through the fit pipeline. Data
// failures come back as a termination and a sentence; throws std::invalid_argument for an
// invalid request.
FitResult runFitRequest(const FitRequest& request, const IdData& data, const ProgressCallback& progress = {});

// The session part "fits": each stored request replayed into a report section (parameter
// table, loss, fit %, notches and peaks, Bode plot with its 99 % band, compare plot on the
// validation range, residual tests), and an SPA section of the estimation data when the
// part asks for it.
std::shared_ptr<const SessionPart> makeFitsPart();

}  // namespace flexarm
