#pragma once
// A fit as a session stores it: what the Fit panel was asked to estimate (a physical
// structure with its start values and free parameters, or a black-box structure (4.8) with
// its orders), the options (decimation, noise model, starts, iterations) and the ranges it
// used. Replaying the request on the session's data repeats the prediction-error fit
// (4.6)/(5.7) exactly: the same signals, the same starts, the same seed.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "core/common/progress.h"
#include "core/ident/blackbox.h"
#include "core/ident/closed_loop_pem.h"
#include "core/ident/pem.h"
#include "core/models/physical_models.h"
#include "core/session/session.h"
#include "core/session/session_part.h"
#include "core/signal/id_data.h"

namespace flexarm {

struct FitRequest {
  std::string name;  // the model list entry the fit produced, e.g. "three-mass estimate"
  // Physical: the start model (structure, output, start values, free flags). Null for a
  // black-box fit.
  std::shared_ptr<const PhysicalModel> start;
  PolyStructure structure = PolyStructure::Oe;  // black-box only
  PolyOrders orders;                            // black-box only
  int decimation = 1;                           // on top of the session's preprocessing
  NoiseModel noiseModel = NoiseModel::OutputError;
  int randomStarts = 0;  // > 0 adds two starts at the SPA notches and peaks as well
  unsigned seed = 1;
  int maxIterations = 100;
  // Physical output-error fits of logs with a reference channel: two-stage (consistent in
  // closed loop) or direct.
  ClosedLoopMethod closedLoop = ClosedLoopMethod::TwoStage;
  // The ranges the fit used (seconds); unset: the whole log / no validation.
  std::optional<SecondsRange> estimation, validation;

  bool physical() const { return start != nullptr; }
  bool isValid(std::string* why) const;
};

// A range in seconds as session JSON, [start, end] or null.
nlohmann::json secondsRangeToJson(const std::optional<SecondsRange>& r);
// Reads j[key] (absent or null: no range); false with a sentence unless [start, end] with
// start < end.
bool readSecondsRange(const nlohmann::json& j, const char* key, std::optional<SecondsRange>& out,
                      std::string* why);

nlohmann::json fitRequestToJson(const FitRequest& request);
// The request described by j; nullopt with a sentence for a malformed one.
std::optional<FitRequest> fitRequestFromJson(const nlohmann::json& j, std::string* why);

// Input u and output y of the whole data with the estimation data's means removed (Section
// 5.2), decimated behind the anti-alias FIR when decimation > 1, the output turned into the
// motor velocity (central differences) when velocityOutput and the log gives the angle.
// A black-box estimate stored with its request, so that a reopened session shows it without
// estimating again: {"parameters": [a.. b.. c.. d.. f..], "sample_time", "noise_variance",
// "covariance": rows or null}.
nlohmann::json polynomialEstimateToJson(const PolynomialModel& model);
// The estimate of a black-box request (its structure and orders) from j; nullopt with a
// sentence when j does not match the request.
std::optional<PolynomialModel> polynomialEstimateFromJson(const nlohmann::json& j, const FitRequest& request,
                                                          std::string* why);

struct FitSignals {
  Eigen::VectorXd u, y;
  Eigen::VectorXd r;  // the reference channel prepared alike; empty when the log has none
  SampleRange estimation;  // every sample when no estimation range is given
  SampleRange validation;  // empty without a validation range
  double sampleTime = 1.0;
  double startTime = 0.0;  // of the first sample (s)
  bool closedLoop = false;
  std::string note;  // how the data were prepared
};
// nullopt with a sentence when the data lack an input or output or the range is too short.
std::optional<FitSignals> fitSignals(const IdData& data, int decimation, bool velocityOutput,
                                     const std::optional<SecondsRange>& estimation,
                                     const std::optional<SecondsRange>& validation,
                                     std::string* why);

struct FitParameterRow {
  std::string name, unit;
  double value = 0.0, std = 0.0, lower = 0.0, upper = 0.0;  // 99 % interval
  bool free = false;
};

// A fit's results: the estimate, its table (value +- std, 99 % interval), fit % (5.2) on
// the estimation range (simulated from its first sample) and on the validation range
// (simulated from the log's first sample), and the simulated output of the whole log.
struct FitRun {
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  EstimateSummary summary;
  FitSignals data;  // the signals the fit used
  std::shared_ptr<const PhysicalModel> physical;  // physical estimate
  Eigen::MatrixXd covariance;                     // of physical->parameters()[freeIndices]
  Eigen::VectorXd K;                              // innovations gain (empty: output error)
  std::vector<int> freeIndices;
  std::shared_ptr<const PolynomialModel> polynomial;  // black-box estimate
  std::vector<FitParameterRow> parameters;
  double fitEstimation = 0.0;
  std::optional<double> fitValidation;
  Eigen::VectorXd simulated;  // of the whole log, from its first sample
  std::vector<double> notches, peaks;  // rad/s, from the estimate's frequency response (5.4)
  // Continuous or discrete frequency response with 99 % bands, from 2 pi / (N T) to pi / T.
  FrequencyResponse response;
};

// Runs the request on data (the session's preprocessed log). Data failures come back as a
// termination and a sentence; throws std::invalid_argument for an invalid request.
FitRun runFitRequest(const FitRequest& request, const IdData& data,
                     const ProgressCallback& progress = {});

// The session part "fits": each stored request replayed into a report section (parameter
// table, loss, fit %, notches and peaks, Bode plot with its 99 % band, compare plot on the
// validation range, residual tests), and an SPA section of the estimation data when the
// part asks for it.
std::shared_ptr<const SessionPart> makeFitsPart();

}  // namespace flexarm
