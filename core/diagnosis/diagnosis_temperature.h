#pragma once
// Diagnosis at the monitored log's temperature. Gearbox friction moves with temperature more
// than with wear, so a log recorded warmer than its fault-free reference shows another f_m
// with nothing broken. The friction model of friction_temperature.h,
// f_m(T) = f_m0 (1 + alpha (T - T_ref)), carries theta_0's f_m from the reference's
// temperature to the monitored log's before the tests compare, so that like is compared with
// like; the shift is reported beside the estimates.
//
// A log's temperature is the mean of its optional `temperature_c` channel (columns::
// kTemperature) or, without one, its metadata value `temperature_c: 31.5`.
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis/friction_temperature.h"
#include "core/diagnosis/reference.h"
#include "core/signal/id_data.h"

namespace flexarm {

struct LogTemperature {
  std::optional<double> celsius;  // none: the log says nothing of its temperature
  std::string source;             // "the temperature_c channel (mean of 48000 samples)", ...
  std::string problem;            // a value that cannot be a temperature, named (then no celsius)
};
// The temperature of a log: its temperature_c channel's mean, else its metadata value. A
// channel or value that is not a number between -50 and 250 degC is a problem naming the
// sample or the key, never a guess.
LogTemperature logTemperature(const IdData& log);

// What the temperature did to theta_0's f_m.
struct TemperatureCorrection {
  bool applied = false;                  // theta_0's f_m was moved
  std::optional<double> monitoredC, referenceC;
  FrictionTemperatureModel model;        // alpha and T_ref used (alpha 0: none known)
  double fmReference = 0.0;              // theta_0's f_m as fitted on the reference
  double fmExpected = 0.0;               // the same at the monitored log's temperature
  std::string message;                   // one sentence for the user
};

// theta_0 (and the plant the calibration simulates) with f_m carried from the reference's
// temperature to the monitored one by `model`. The model is the arm's friction, the plant's
// f_m: f_m0 = model.toReference(f_m, T_reference), then model.atTemperature(f_m0,
// T_monitored); theta_0's f_m, fitted through the diagnosis' predictor, moves by the same
// amount. Nothing changes, with a sentence saying why, when a temperature is unknown, alpha is
// 0 (not known) or the model has no f_m.
TemperatureCorrection correctForTemperature(DiagnosisReference& reference,
                                            const std::optional<double>& monitoredC,
                                            const std::optional<FrictionTemperatureModel>& model);

// alpha from healthy logs at different temperatures: the reference is made of each as the
// diagnosis makes it (referenceFromLog) and fitFrictionTemperature puts a line through the
// plants' f_m, weighted by theta_0's standard deviation of f_m on the same log. A log without
// a temperature, or whose fit fails, is a Failed result naming it.
FrictionTemperatureFit frictionFromHealthyLogs(const PhysicalModel& start,
                                               const std::vector<const IdData*>& logs,
                                               const std::vector<std::string>& names,
                                               const DiagnosisOptions& options, double referenceC,
                                               const ProgressCallback& progress = {});

}  // namespace flexarm
