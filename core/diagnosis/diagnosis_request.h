#pragma once
// A diagnosis as a front end asks for it, in one call: which log is monitored, where theta_0
// comes from (a fault-free log, or a model believed fault-free), the seed's way of making a
// fault if wanted, the options, and a calibration of the thresholds if wanted. The command
// line, the Diagnosis panel and the session part "diagnosis" all run it through
// runDiagnosisRequest, unchanged.
#include <memory>
#include <optional>
#include <string>

#include "core/common/progress.h"
#include "core/diagnosis/calibration.h"
#include "core/diagnosis/diagnosis.h"

namespace flexarm {

struct DiagnosisRequest {
  DiagnosisOptions options;
  // theta_0: fitted on the fault-free log (when given), else the model (as given: the
  // diagnosis fits theta_0 on a fault-free run of it simulated like the monitored log).
  std::shared_ptr<const IdData> referenceLog;
  std::shared_ptr<const PhysicalModel> model;  // the start of the fit, or the model itself
  // The seed's fault (Section 7.5): theta_0 of a monitored parameter times a factor.
  std::optional<std::pair<std::string, double>> seedFault;
  // Calibrate the thresholds on the simulator before diagnosing (calibration.h).
  bool calibrate = false;
  CalibrationOptions calibration;
  bool isValid(std::string* why) const;
};

struct DiagnosisRun {
  Termination termination = Termination::Failed;
  std::string message;  // a sentence: how it ended or what failed
  // Failed because the request asks for more work than the budget allows for this log (too
  // many calibration runs), not because the data or an estimator failed.
  bool badRequest = false;
  DiagnosisReference reference;
  std::optional<CalibrationResult> calibration;
  DiagnosisResult result;  // with the calibrated options when calibrated
  bool ok() const { return termination == Termination::Converged; }
};

// Reference (fit), calibration if asked, then the diagnosis of `log`. Progress: the reference
// and calibration take the first part, the diagnosis the rest. Data failures end as Failed (or
// Diverged when an estimator left its bounds) with a sentence; invalid requests throw
// std::invalid_argument.
DiagnosisRun runDiagnosisRequest(const DiagnosisRequest& request, const IdData& log,
                                 const ProgressCallback& progress = {});

// Where the default thresholds come from and the false-alarm rate they were calibrated for,
// in one sentence (reports and the command line print it beside the thresholds).
std::string defaultThresholdsProvenance();
// Where the thresholds of `options` come from: the sentence above when they are the calibrated
// defaults; else which ones were set by hand and that their false-alarm rate and isolation
// were not measured (the calibration's figures do not carry over to other thresholds).
std::string thresholdsProvenance(const DiagnosisOptions& options);

}  // namespace flexarm
