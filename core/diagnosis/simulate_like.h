#pragma once
// Simulated runs of an arm under the conditions of a given log: its controller (from the
// metadata, else the seed's Figure 5.1 cascade), its sample rate and length, and its own
// position reference (else the multisine (6.50)), with the simulator's noise sources (torque
// noise, load torque) scaled to the log's own noise level. The reference from a model and the
// Monte-Carlo calibration run the arm this way.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis/diagnosis_data.h"
#include "core/models/physical_models.h"
#include "core/sim/closed_loop.h"

namespace flexarm {

struct LogConditions {
  SimulationOptions simulation;  // controller, rate, duration, reference; seed and noise at defaults
  std::string note;              // what was taken from the log and what was assumed, in words
};

// The conditions of a log. nullopt with a sentence when the log cannot be run again (its rate
// does not divide its controller's rate, or it is too short).
std::optional<LogConditions> logConditions(const IdData& log, std::string* why);

// The options of one run: the log's conditions with the torque and load noise multiplied by
// noiseScale, the seed, a duration (0: the log's) and the parameter steps of a fault.
SimulationOptions runOptions(const LogConditions& conditions, double noiseScale, std::uint64_t seed,
                             const std::vector<ParameterStep>& steps = {}, double durationS = 0.0);

// The noise scale at which a simulated run of the plant looks as noisy to the diagnosis as the
// fault-free log did: lambda_0, the mean squared output error of the predictor fitted to the
// run (as theta_0 is fitted to the log, starting from `start`), matches targetMeanSquare. Runs
// at scale 1 and 0 (quantisation only) and the quadratic growth in between. 1 when the level
// cannot be matched (a sentence in *note says why).
double matchNoiseScale(const PhysicalModel& plant, const PhysicalModel& start,
                       const LogConditions& conditions, DiagnosisPredictor predictor,
                       double targetMeanSquare, std::string* note);

}  // namespace flexarm
