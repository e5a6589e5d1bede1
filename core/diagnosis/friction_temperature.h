#pragma once
// Viscous motor friction against temperature. Gearbox friction moves with temperature more
// than with wear, so a monitored log recorded warmer or colder than its reference must be
// compared at one temperature: f_m(T) = f_m0 (1 + alpha (T - T_ref)), alpha the relative
// change of f_m per degree. alpha is estimated from healthy logs at different temperatures
// (fitFrictionTemperature) or given. One model for the per-log diagnosis (chapter 7) and the
// plant's trends over days (core/fleet).
#include <string>
#include <vector>

#include "core/common/progress.h"

namespace flexarm {

struct FrictionTemperatureModel {
  double alpha = 0.0;       // 1/degC: relative change of f_m per degree
  double alphaStd = 0.0;    // its standard deviation (0 when given, not estimated)
  double referenceC = 20.0; // T_ref, degC: the temperature f_m0 refers to
  int logs = 0;             // healthy logs alpha was estimated from (0: given)

  // f_m0 of a value seen at temperatureC: f_m / (1 + alpha (T - T_ref)).
  double toReference(double fm, double temperatureC) const;
  // The value expected at temperatureC of f_m0: f_m0 (1 + alpha (T - T_ref)).
  double atTemperature(double fm0, double temperatureC) const;
  // alpha and T_ref finite and 1 + alpha (T - T_ref) > 0 over T_ref +- 40 degC, the span a
  // gearbox sees in service (so |alpha| < 2.5 %/degC).
  bool isValid(std::string* why = nullptr) const;
};

struct FrictionTemperatureFit {
  Termination termination = Termination::Failed;
  std::string message;      // how alpha was found, or why it could not be
  FrictionTemperatureModel model;
  double fm0 = 0.0, fm0Std = 0.0;  // f_m at T_ref
  double scatter = 1.0;     // residual scatter against the given std (reduced chi-square)
};

// Weighted least squares of f_m = f_m0 (1 + alpha (T - T_ref)) over healthy logs: one
// (temperature, f_m, std of f_m) per log; fmStd may be empty (equal weights) or hold positive
// values. The covariance is scaled by the residual scatter when that exceeds what the stds
// promise, so alphaStd stays honest when the logs scatter more than their own intervals say.
// Fewer than three logs, or temperatures spanning less than 2 degC, end Failed with alpha 0
// and a sentence saying so. Non-finite input throws std::invalid_argument.
FrictionTemperatureFit fitFrictionTemperature(const std::vector<double>& temperatureC,
                                              const std::vector<double>& fm,
                                              const std::vector<double>& fmStd,
                                              double referenceC);

}  // namespace flexarm
