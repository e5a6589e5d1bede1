#pragma once
// The diagnosis as a session stores it (part "diagnosis"): what the Diagnosis panel was asked
// (the monitored log, where theta_0 comes from, the seed's fault, the options with their
// thresholds, and the calibration the thresholds came from) and the summary of what it found
// (diagnosisResultJson). Replaying runs runDiagnosisRequest again on the logs as read and
// writes the report section: the verdict and its time, the thresholds and the false-alarm
// rate they were chosen for, each test's alarms, the decision table of Section 7.5.2 at the
// verdict, and the plots (estimates with their threshold bands, CUSUM against h, hypothesis
// statistics against their level, the alarm timeline).
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/diagnosis/diagnosis_request.h"
#include "core/session/report.h"
#include "core/session/session.h"
#include "core/session/session_part.h"

namespace flexarm {

struct DiagnosisSessionRequest {
  std::string log;           // the monitored log (a session log name; empty: the first)
  std::string referenceLog;  // the fault-free log; empty: theta_0 from the model
  std::string model;         // a model of the list; empty: `structure` with its nominal values
  std::string structure = "three-mass";
  std::optional<std::pair<std::string, double>> seedFault;
  DiagnosisOptions options;
  // Recompute the calibration when replayed (slow); else the thresholds in `options` are used
  // and `calibration` (a calibrationJson summary, or null) says where they came from.
  bool calibrate = false;
  CalibrationOptions calibrationOptions;
  nlohmann::json calibration;
  bool isValid(std::string* why) const;
};

nlohmann::json diagnosisOptionsToJson(const DiagnosisOptions& options);
std::optional<DiagnosisOptions> diagnosisOptionsFromJson(const nlohmann::json& j, std::string* why);
nlohmann::json diagnosisRequestToJson(const DiagnosisSessionRequest& request);
std::optional<DiagnosisSessionRequest> diagnosisRequestFromJson(const nlohmann::json& j,
                                                                std::string* why);

// The request a session part describes, with its logs and model looked up in the replay's
// context; nullopt with a sentence when a log or the model is missing.
std::optional<DiagnosisRequest> resolveDiagnosisRequest(const DiagnosisSessionRequest& request,
                                                        const ReplayContext& context,
                                                        const IdData** monitored, std::string* why);

// The report section of a diagnosis run (reports of sessions; the panel's export).
ReportSection diagnosisReportSection(const DiagnosisRun& run, const nlohmann::json& calibration);

// The session part "diagnosis": {"request": ..., "result": ...} (the result may be absent).
std::shared_ptr<const SessionPart> makeDiagnosisPart();

}  // namespace flexarm
