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

// Step 5: fit % on every experiment, residual tests, response, notches and peaks, warnings.
void evaluate(const FitOptions& options, FitResult& result);

}  // namespace flexarm::fit_detail
