#include "core/diagnosis/diagnosis_request.h"

#include <cstdio>

#include <algorithm>
#include <stdexcept>

namespace flexarm {

namespace {

ProgressCallback share(const ProgressCallback& progress, double from, double to) {
  if (!progress) return {};
  return [progress, from, to](double f, const std::string& stage) {
    return progress(from + (to - from) * std::clamp(f, 0.0, 1.0), stage);
  };
}

}  // namespace

bool DiagnosisRequest::isValid(std::string* why) const {
  if (!model) {
    if (why) *why = "a diagnosis needs a model (the fit's start, or theta_0 itself)";
    return false;
  }
  if (!options.isValid(why)) return false;
  for (const auto& name : options.parameters)
    if (model->indexOf(name) < 0) {
      if (why) *why = "the " + model->structureName() + " model has no parameter '" + name + "' to monitor";
      return false;
    }
  if (seedFault && (std::find(options.parameters.begin(), options.parameters.end(), seedFault->first) ==
                        options.parameters.end() ||
                    !(seedFault->second > 0.0))) {
    if (why) *why = "the seed's fault needs a monitored parameter and a factor > 0";
    return false;
  }
  if (calibrate && !calibration.isValid(why)) return false;
  if (why) why->clear();
  return true;
}

DiagnosisRun runDiagnosisRequest(const DiagnosisRequest& request, const IdData& log,
                                 const ProgressCallback& progress) {
  std::string why;
  if (!request.isValid(&why)) throw std::invalid_argument("diagnosis: " + why);
  DiagnosisRun run;
  auto fail = [&run](Termination t, const std::string& message) {
    run.termination = t;
    run.message = message;
    return run;
  };
  const double referenceShare = request.calibrate ? 0.1 : 0.3;
  const double calibrationShare = request.calibrate ? 0.8 : 0.0;
  run.reference = request.referenceLog
                      ? referenceFromLog(*request.model, *request.referenceLog, request.options, {},
                                         share(progress, 0.0, referenceShare))
                      : referenceFromModel(*request.model, log, request.options, {},
                                           share(progress, 0.0, referenceShare));
  if (run.reference.termination == Termination::Cancelled) return fail(Termination::Cancelled, "cancelled");
  if (!run.reference.ok()) return fail(Termination::Failed, run.reference.message);
  if (request.seedFault)
    run.reference = withSeedFault(run.reference, request.options, request.seedFault->first,
                                  request.seedFault->second);
  DiagnosisOptions options = request.options;
  if (request.calibrate) {
    run.calibration = calibrate(run.reference, log, options, request.calibration,
                                share(progress, referenceShare, referenceShare + calibrationShare));
    if (run.calibration->termination == Termination::Cancelled) return fail(Termination::Cancelled, "cancelled");
    if (run.calibration->badRequest) {
      run.badRequest = true;
      return fail(Termination::Failed, "the calibration is refused: " + run.calibration->message);
    }
    if (run.calibration->termination != Termination::Converged)
      return fail(Termination::Failed, "the calibration failed: " + run.calibration->message);
    options = run.calibration->calibrated;
  }
  run.result = diagnose(run.reference, log, options,
                        share(progress, referenceShare + calibrationShare, 1.0));
  run.termination = run.result.termination;
  run.message = run.result.message;
  return run;
}

std::string defaultThresholdsProvenance() {
  // The figures are those of bench/results/diagnosis.txt (60 arms, 240 runs).
  return "the seed's design values (3 sigma, alpha_1 = 3, alpha_2 = 20, level 1) scaled per "
         "parameter as calibrated by bench/montecarlo_diagnosis (see DiagnosisOptions); in its "
         "study of 240 simulated runs the decision at these thresholds raised no false alarm in "
         "0.3 h of fault-free runs (at most 10 false alarms per hour at 95 %) and isolated 99 % "
         "of 20 % faults within 5 s, median delay 0.85 s";
}

std::string thresholdsProvenance(const DiagnosisOptions& o) {
  const DiagnosisOptions d;
  std::vector<std::string> changed;
  auto number = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  auto check = [&](const char* name, double value, double standard) {
    if (value != standard) changed.push_back(std::string(name) + " = " + number(value));
  };
  check("k (classical)", o.classicalK, d.classicalK);
  check("k (robust)", o.robustK, d.robustK);
  check("alpha_1", o.cusumAlpha1, d.cusumAlpha1);
  check("alpha_2", o.cusumAlpha2, d.cusumAlpha2);
  check("hypothesis threshold", o.hypothesisThreshold, d.hypothesisThreshold);
  check("joint k", o.jointK, d.jointK);
  check("settle", o.settleS, d.settleS);
  check("confirm", o.confirmS, d.confirmS);
  if (o.window != d.window || (o.window == HypothesisWindow::Sliding && o.windowS != d.windowS))
    changed.push_back("the hypothesis window");
  if (o.classicalScales != d.classicalScales || o.robustScales != d.robustScales || o.cusumScales != d.cusumScales)
    changed.push_back("the per-parameter factors");
  if (o.parameters != d.parameters || o.inverted != d.inverted) changed.push_back("the monitored parameters");
  if (o.tests != d.tests || o.decision != d.decision) changed.push_back("the tests");
  if (changed.empty()) return defaultThresholdsProvenance();
  std::string list;
  for (std::size_t i = 0; i < changed.size(); ++i) list += (i ? ", " : "") + changed[i];
  return "set by hand (" + list +
         "), not the calibrated design values: their false-alarm rate and isolation were not "
         "measured (--calibrate measures them on this reference)";
}

}  // namespace flexarm
