#pragma once
// Residual analysis of one model on one range (Ljung's model validation, SITB's resid): the
// autocorrelation of its errors and their cross-correlation with the input, with 99 % bounds
// and the whiteness and independence tests (core/ident/residuals.h). The errors are the
// one-step prediction errors (4.5) of a black-box estimate and the output errors y - G u of a
// physical model (residualsOf, core/ident/model_output.h), on the data as the model's fit
// prepared them. One request, one run, one result, used unchanged by `flexarm residuals`, the
// Residuals panel, the session part "residuals" and the report.
#include <optional>
#include <string>

#include "core/common/progress.h"
#include "core/compare/compare.h"
#include "core/ident/residuals.h"

namespace flexarm {

struct ResidualsRequest {
  EvaluationData data;
  EvaluatedModel model;
  DataRange range = DataRange::Estimation;
  ResidualOptions options;  // the largest lag M and the level of the bounds and tests
  bool isValid(std::string* why) const;
};

// Why there is no analysis, or Ok.
enum class ResidualsCode { Ok, NoData, NoRange, RateMismatch, NoResiduals, TooShort, Cancelled };
const char* toString(ResidualsCode c);  // "ok", "no_data", "no_range", "rate_mismatch", ...

struct ResidualsResult {
  Termination termination = Termination::Failed;
  ResidualsCode code = ResidualsCode::NoData;
  std::string message;  // how it ended, or why there is no analysis (a sentence)
  std::string modelName, dataName, dataNote;
  DataRange range = DataRange::Estimation;
  std::string rangeText;  // "validation 9-17.5 s"
  int samples = 0;
  double sampleTime = 0.0;  // of the samples the lags count
  int decimation = 1;
  // Errors of a black-box estimate are its one-step prediction errors; of a physical model
  // its output errors.
  bool predictionErrors = false;
  ResidualAnalysis analysis;  // empty lags when there is none
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
  // The sentence a person reads: the tests' outcomes with their statistics, or why none.
  std::string summary() const;
};

// Data failures end Failed with a code and a sentence; an invalid request throws
// std::invalid_argument.
ResidualsResult runResiduals(const ResidualsRequest& request, const ProgressCallback& progress = {});

}  // namespace flexarm
