#pragma once
// A physical model (with its effects) simulated against a log: the Model panel's "Simulate
// against log" and the session report's model section run this one call. The plant (3.13)/
// (3.21) is integrated open loop from the log's torque reference (its input when it has no
// torque reference channel), from rest, and its motor velocity is compared with the log's
// (or with the central differences of the logged motor angle, Section 5.2) by fit % (5.2).
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"

namespace flexarm {

struct LogSimulationOptions {
  // Runge-Kutta steps per sample; 0: enough for a step of at most 0.25 ms (and at least 2).
  int substeps = 0;
  bool isValid(std::string* why) const;
};

struct LogSimulationResult {
  Termination termination = Termination::Failed;
  std::string message;  // how it ended, or why there is no simulation
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
  std::vector<double> time;       // s, of every sample of the log
  std::vector<double> measured;   // motor velocity of the log, rad/s
  std::vector<double> simulated;  // the model's motor velocity, rad/s
  double fitPercent = 0.0;        // (5.2) over the whole log
  // Fit % (5.2) over the log's samples [range.begin, range.end); nullopt when the range does
  // not lie inside the log or there is no simulation.
  std::optional<double> fitPercentOver(const SampleRange& range) const;
};

// Data failures (no torque or motor channel, a simulation that fails) end as Failed with a
// sentence; invalid options throw std::invalid_argument.
LogSimulationResult simulateAgainstLog(const PhysicalModel& model, const std::vector<Effect>& effects,
                                       const IdData& data, const LogSimulationOptions& options = {});

}  // namespace flexarm
