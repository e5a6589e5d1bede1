#pragma once
// Random Monte-Carlo scenarios for studies of the diagnosis beyond one log: arms whose
// parameters scatter around a nominal model, noise levels, excitations (kind and amplitude)
// and seeds drawn at random, each arm run once fault-free and once per monitored parameter
// with a fault stepping in, and diagnosed against theta_0 fitted on a fault-free run of its
// own (monteCarlo in calibration.h runs them).
#include <cstdint>
#include <string>
#include <vector>

#include "core/diagnosis/calibration.h"
#include "core/sim/excitation.h"

namespace flexarm {

struct ScenarioOptions {
  int arms = 20;               // each gives one fault-free run and one run per fault
  double durationS = 20.0;     // of the runs with a fault and of the reference runs
  double healthyDurationS = 0.0;  // of the fault-free runs (0: durationS)
  double faultTimeLowS = 8.0, faultTimeHighS = 12.0;  // the step time, uniform
  double faultSize = 0.2;      // the monitored quantity rises by this part
  double truthSpread = 0.15;   // each parameter of the nominal arm times U(1 - s, 1 + s)
  double noiseLow = 0.5, noiseHigh = 1.5;    // scale of the simulator's torque and load noise
  std::vector<ExcitationKind> excitations = {ExcitationKind::Multisine, ExcitationKind::Prbs};
  // rad on the motor side, around the designed experiment of the chapter-6/7 logs (0.2 rad)
  double amplitudeLow = 0.1, amplitudeHigh = 0.3;
  double rateHz = 2000.0;      // log rate (the controller's; the diagnosis decimates to 200 Hz)
  std::uint64_t seed = 1;
  bool isValid(std::string* why) const;
};

// The runs: for each arm first the fault-free run, then one per monitored parameter, all with
// the arm's own reference run (fitted when monteCarlo runs them).
std::vector<MonteCarloRun> randomScenarios(const PhysicalModel& nominal,
                                           const std::vector<std::string>& monitored,
                                           const ScenarioOptions& options);

}  // namespace flexarm
