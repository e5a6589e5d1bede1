#pragma once
// The steps of fitModel (fit.h) that live in their own files; not for use elsewhere.
#include "core/ident/fit.h"

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

// One experiment of prepared data over range as the nonlinear estimator sees it
// (nonlinearSeries of nonlinear_pem.h, the output the model gives: velocity or angle), and the
// estimator's options: on closed-loop data the predictor discovery uses (a load observer,
// the predicted angle differentiated as the logged one was).
NonlinearSeries nonlinearSeries(const FitResult& result, const PreparedData& data, SampleRange range);
NonlinearPemOptions nonlinearOptions(const FitOptions& options, const FitResult& result);

// Step 5: fit % on every experiment, residual tests, response, notches and peaks, warnings.
void evaluate(const FitOptions& options, FitResult& result);

}  // namespace flexarm::fit_detail
