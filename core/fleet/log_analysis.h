#pragma once
// The chapter 6-7 analysis of one daily log of a fleet's axis against the axis' fault-free
// reference: the recursive estimates of the monitored parameters (k_T, J_a, f_m) with their
// std, the tests and the verdict (core/diagnosis, called unchanged), reduced to what the
// store keeps and the trends use.
//
// The reference is fitted once per axis (theta_0, P(0) and lambda_0 on the reference log,
// core/diagnosis/reference.h) and kept as JSON, so that every engine (a thread here, a task on
// a cluster node) diagnoses with the same numbers.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/diagnosis/diagnosis_options.h"
#include "core/diagnosis/reference.h"

namespace flexarm {

struct FleetAnalysisOptions {
  std::string model = "three-mass";  // the physical model's structure (makeModel)
  DiagnosisOptions diagnosis;        // the chapter-7 defaults
  // A log's value of a parameter: the mean of its recursive estimate over the last part of the
  // log (the estimator starts at theta_0 and needs a few seconds to reach a changed value).
  double settledFraction = 0.5;
  bool isValid(std::string* why) const;
};

// One monitored parameter of one log, in the model's form (J_a, not J_a^-1).
struct FleetEstimate {
  std::string name;         // k_T, J_a, f_m
  double value = 0.0;       // mean of the estimate over the settled part
  double std = 0.0;         // larger of sigma (7.8) at the end and the spread over that part
  double reference = 0.0;   // theta_0's value
};

struct FleetLogResult {
  std::string sha256;       // of the log's bytes
  std::string referenceSha256;
  bool ok = false;          // false: the log could not be analysed (message says why)
  std::string message;
  std::string verdict = "none";      // none, k_T, J_a, f_m (the decision of Section 7.5.2)
  std::optional<double> verdictTimeS;
  std::vector<FleetEstimate> estimates;
  double seconds = 0.0;
  const FleetEstimate* estimate(const std::string& name) const;
};

// theta_0 of an axis from its reference log (output-error fit, P(0), lambda_0; no plant fit:
// the fleet does not calibrate). A log that cannot be used gives a Failed reference with a
// sentence.
DiagnosisReference fleetReference(const std::string& logPath, const FleetAnalysisOptions& options);

// The reference as JSON and back (theta_0 as a model, predictor, sigma_0, lambda_0, P(0),
// source); doubles round-trip exactly. nullopt with a sentence for malformed JSON.
nlohmann::json referenceToJson(const DiagnosisReference& reference);
std::optional<DiagnosisReference> referenceFromJson(const nlohmann::json& j, std::string* why);

// Reads and diagnoses one log against the reference (ok() required). Nothing throws for bad
// data: an unreadable or unusable log is a result with ok false and the reader's message.
FleetLogResult analyseFleetLog(const std::string& logPath, const DiagnosisReference& reference,
                               const FleetAnalysisOptions& options);

// Whether a result is one FlexArm could have written: checksums of 64 hex digits, a known
// verdict (none, model_mismatch or one of its parameters), and for an analysed log every estimate named, finite, with a finite std > 0 (a std
// of 0 would claim the log decided the value exactly). Checked on what a Slurm task sends
// back, on what the store is given and on what it gives back; false with a sentence.
bool isValidFleetLogResult(const FleetLogResult& r, std::string* why);

nlohmann::json fleetLogResultJson(const FleetLogResult& r);
std::optional<FleetLogResult> fleetLogResultFromJson(const nlohmann::json& j, std::string* why);

}  // namespace flexarm
