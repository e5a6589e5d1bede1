#pragma once
// The steps of fitModel (fit.h) that live in their own files; not for use elsewhere.
#include "core/ident/fit.h"
#include "core/ident/model_output.h"

namespace flexarm::fit_detail {

// The estimation ranges of every estimation experiment, one after another, and their sample
// counts (PemOptions / PolyEstimateOptions::experimentLengths).
struct JoinedEstimation {
  Eigen::VectorXd u, y;
  std::vector<Eigen::Index> lengths;
};
JoinedEstimation joinedEstimation(const FitResult& result);

// Step 2-4 for physical models: the closed-loop method (Auto's rule included), the starts and
// the estimator. Fills method, methodReason, controller fields, the estimate and its
// parameter rows; on a data failure sets termination and message and returns false.
bool fitPhysical(const FitOptions& options, FitResult& result, const ProgressCallback& progress);

// A warning for each free parameter of result that ended on one of its bounds (start: the
// model the search started from, whose bounds it kept).
void boundWarnings(const PhysicalModel& start, FitResult& result);

// Steps 2-4 for physical models with effects: the nonlinear grey-box estimator over every
// estimation experiment (nonlinear_pem.h). Fills the estimate, its effects and parameter rows.
void fitNonlinear(const FitOptions& options, FitResult& result, const ProgressCallback& progress);
// The estimate of the nonlinear estimator into result: summary, parameter rows, covariance,
// effects and warnings (start: the model the search started from).
void keepNonlinear(NonlinearPemResult&& estimate, const FitOptions& options, const PhysicalModel& start,
                   FitResult& result);

// One experiment of prepared data over range as the nonlinear estimator sees it
// (nonlinearSeries of nonlinear_pem.h, the output the model gives: velocity or angle), and the
// estimator's options: on closed-loop data the predictor discovery uses (a load observer,
// the predicted angle differentiated as the logged one was).
NonlinearSeries nonlinearSeries(const FitResult& result, const PreparedData& data, SampleRange range);
NonlinearPemOptions nonlinearOptions(const FitOptions& options, const FitResult& result);

// The estimate as the evaluations take it (model_output.h): model or black-box estimate,
// effects, the fit's rate and smooth signs' speed.
EvaluatedModel evaluatedModel(const FitOptions& options, const FitResult& result);

// Steps 2-4 of method idim / idim-iv: the inverse-dynamics estimate of the rigid part on the
// first estimation experiment (positions and torques with their means). False with
// termination and message set when the data cannot carry it.
bool fitIdim(const FitOptions& options, FitResult& result);

// Start values from inverse dynamics for a prediction-error fit (FitOptions::idimStart):
// appended to options.startValues when the start model's inertia is off by more than a factor
// of two; result.idim and result.idimNote say what was done.
void idimStart(FitOptions& options, FitResult& result);

// Step 5 on a log with an arm-side encoder: the deflection the physical estimate predicts
// against the measured one (FitResult::deflection).
void deflectionCheck(const FitOptions& options, FitResult& result);

// Whether a bound warning says the named parameter ended on its bound.
bool sitsOnBound(const FitResult& result, const std::string& name);

// Step 5 for physical fits: FitResult::plausibility.
void plausibilityChecks(const FitOptions& options, FitResult& result);

// Step 5, after the plausibility checks: FitParameter::determined and undetermined, and
// FitResult::undeterminedDirection.
void assessDeterminacy(const FitOptions& options, FitResult& result);

// Step 5: fit % on every experiment, residual tests, response, notches and peaks, warnings.
void evaluate(const FitOptions& options, FitResult& result);

}  // namespace flexarm::fit_detail
