#pragma once
// Compare: the measured output against the output of several models on the validation (or
// estimation) range, each with its fit % (5.2) and MATLAB compare's NRMSE fit, as the seed's
// Figure 5.11; on a log with an arm-side encoder also the deflection r phi_m - phi_a each
// physical model predicts from the torque against the one the encoders measure. One request,
// one run, one result, used unchanged by `flexarm compare`, the Compare panel, the session
// part "compare" and the report.
//
// Each model runs on the data as its fit prepared them (modelDataOptions,
// core/ident/model_output.h: its rate, the velocity from the angle, the means). Its output is
// the simulation (horizon 0, the default) or the k-step prediction y(t | t - k) (horizon k), on
// the validation range from the log's first sample (no start-up transient inside it) and on
// the estimation range from the range's first sample (what the estimator saw): the figures
// the fit reports (core/ident/fit.h, FitValidation), so the same model on the same range gives
// the same number in the Fit panel, here, in sessions and in reports.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/evaluation.h"
#include "core/ident/model_output.h"
#include "core/signal/id_data.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

// Which range of the data a comparison, a residual analysis or a study runs on.
enum class DataRange { Estimation, Validation };
const char* toString(DataRange r);  // "estimation", "validation"
std::optional<DataRange> dataRangeFromString(std::string_view s);

// The data an evaluation runs on: the log as the analysis sees it (preprocessed), its ranges
// in seconds and its name for the labels.
struct EvaluationData {
  std::shared_ptr<const IdData> log;
  std::optional<SecondsRange> estimation, validation;  // unset estimation: the whole log
  std::string name;  // the log's file name, "chirp.csv"
};

// The longest prediction horizon a comparison takes (samples).
inline constexpr int kMaxCompareHorizon = 100000;

struct CompareRequest {
  EvaluationData data;
  std::vector<EvaluatedModel> models;
  DataRange range = DataRange::Validation;
  // 0: simulation (infinite horizon); k >= 1: k-step prediction (a black-box model's noise
  // model predicts; an output-error model predicts what it simulates).
  int horizon = 0;
  // The load observer a model with effects is predicted through (one step ahead, Hz): unset,
  // the one its fit predicts through (fitObserverHz: 4 Hz on a closed-loop log, the predictor
  // the nonlinear fit and discovery minimise); 0, none (the open-loop simulation); > 0, that
  // bandwidth. Models without effects are always simulated (or predicted by horizon).
  std::optional<double> observerHz;
  // The deflection check of every physical model on a log with an arm-side encoder.
  bool deflection = true;
  bool isValid(std::string* why) const;
};

// How one model of a comparison ended.
enum class CompareStatus { Compared, RateMismatch, Diverged, Failed };
const char* toString(CompareStatus s);  // "compared", "rate_mismatch", "diverged", "failed"

struct ComparedModel {
  std::string name;
  CompareStatus status = CompareStatus::Failed;
  std::string message;  // why it was not compared (a clause)
  int decimation = 1;
  double sampleTime = 0.0, startTime = 0.0;  // of its samples; startTime: the range's first
  Eigen::VectorXd output;                    // the model's output over the range
  std::optional<FitFigure> fit;
  std::optional<DeflectionFit> deflection;
  bool compared() const { return status == CompareStatus::Compared; }
};

// What stopped a comparison before any model ran.
enum class CompareCode { Ok, NoData, Cancelled };
const char* toString(CompareCode c);  // "ok", "no_data", "cancelled"

struct CompareResult {
  Termination termination = Termination::Failed;
  CompareCode code = CompareCode::NoData;
  std::string message;  // how it ended, or why it could not run
  DataRange range = DataRange::Validation;  // the range compared on
  bool rangeFellBack = false;  // validation asked for, none set: the estimation range
  int horizon = 0;
  std::optional<double> observerHz;  // as asked (unset: each model's fit's)
  std::string dataName, dataNote;  // the log, and the preparation steps at the log's rate
  std::string outputName, outputUnit;
  bool velocity = false;  // the output compared is the motor velocity from the angle
  // The measured output over the range at the log's rate.
  double sampleTime = 0.0, startTime = 0.0;
  Eigen::VectorXd measured;
  // The deflection the encoders measure over the range (about its mean, rad), with the gear
  // ratio used (the log's, else the first physical model's); empty without an arm-side encoder.
  Eigen::VectorXd measuredDeflection;
  double gearRatio = 0.0;
  std::vector<ComparedModel> models;  // in request order
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
  // "the validation data", "the estimation data (no validation range set)".
  std::string rangeText() const;
  // The sentences a person reads: what is compared and how, one line per model.
  std::vector<std::string> lines() const;
};

// Runs every model of the request (progress per model; Abort ends Cancelled with the models
// done so far). Data failures (no input or output, a range outside the log) end Failed with a
// sentence; an invalid request throws std::invalid_argument.
CompareResult runCompare(const CompareRequest& request, const ProgressCallback& progress = {});

// The range's label for fit % bases: "validation 9-17.5 s".
std::string rangeLabel(DataRange kind, const PreparedData& d, SampleRange range);

}  // namespace flexarm
