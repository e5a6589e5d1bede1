#pragma once
// The sensitivity study of the seed's Section 5.3.3 on one physical model: how far each free
// parameter's initial value may move before the prediction-error fit (5.7) fails (the domain
// of attraction of Table 5.8, by interval halving), then Monte-Carlo fits from random initial
// values of all of them at once inside 20 % of those limits, with their success rate (the
// seed: 649 of 1000). A fit succeeds when its loss is less than 5 % above the loss of the
// refit from the model itself. The data are the estimation range prepared as the model's fit
// prepared them (modelDataOptions, core/ident/model_output.h). One request, one run, one
// result, used unchanged by `flexarm sensitivity`, the Fit panel's study, the session part
// "sensitivity" and the report.
#include <optional>
#include <string>

#include "core/common/progress.h"
#include "core/compare/compare.h"
#include "core/ident/sensitivity.h"

namespace flexarm {

// The most Monte-Carlo runs one study takes.
inline constexpr int kMaxSensitivityRuns = 100000;

struct SensitivityRequest {
  EvaluationData data;     // the estimation range is what the fits run on
  EvaluatedModel model;    // a physical model with free parameters
  AttractionOptions attraction;
  // Monte-Carlo starts after the domain of attraction; runs 0: the domain of attraction alone.
  MonteCarloOptions monteCarlo;
  bool isValid(std::string* why) const;
};

enum class SensitivityCode { Ok, NoData, NotPhysical, NoFreeParameters, ReferenceFailed, Cancelled };
const char* toString(SensitivityCode c);  // "ok", "no_data", "not_physical", ...

struct SensitivityResult {
  Termination termination = Termination::Failed;
  SensitivityCode code = SensitivityCode::NoData;
  std::string message;  // how it ended, or why it could not run (a sentence)
  std::string modelName, dataName, dataNote;
  std::string rangeText;  // "estimation 0.5-9 s"
  int samples = 0;
  double sampleTime = 0.0;
  // The model has effects: the study refits its linear part (the effects are left out).
  bool effectsLeftOut = false;
  AttractionResult attraction;
  std::optional<MonteCarloResult> monteCarlo;  // when the attraction search converged
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
  // The sentence a person reads: fits, limits found, the success rate.
  std::string summary() const;
};

// The domain of attraction takes the first half of the progress, the Monte-Carlo runs the
// second; Abort ends Cancelled with what was done. Data failures end Failed with a code; an
// invalid request throws std::invalid_argument.
SensitivityResult runSensitivityStudy(const SensitivityRequest& request, const ProgressCallback& progress = {});

}  // namespace flexarm
