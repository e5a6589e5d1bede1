#pragma once
// A diagnosis result as JSON, as `flexarm diagnose --json` prints it and sessions and reports
// keep it: the verdict and its time, the reference, the final estimates and, per test, its
// verdict, alarms and statistics summary (no per-sample traces).
#include <nlohmann/json.hpp>

#include "core/diagnosis/calibration.h"
#include "core/diagnosis/diagnosis.h"

namespace flexarm {

nlohmann::json diagnosisResultJson(const DiagnosisResult& result);

// A calibration: conditions, per test the chosen threshold with its false-alarm rate (and 95 %
// upper bound) and delays, the curve of false alarms per hour against median delay, and the
// decision at the chosen thresholds. Infinite delays (faults not isolated in time) are null.
nlohmann::json calibrationJson(const CalibrationResult& result);

}  // namespace flexarm
