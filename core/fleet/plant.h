#pragma once
// A simulated plant for tests and demonstrations: robots whose axes each run a short daily
// test routine (a designed multisine experiment, Section 6.6.2, in the closed loop of Figure
// 5.1), logged once a day for a number of days, with the manifest that lists them and a truth
// file that says what happened to each axis:
//  - every axis: its own arm (Table 5.7 p6 with J_m, J_a, k_g, k_a, f_m drawn within
//    +-spread), the cell's temperature swinging about its mean (weekly, up to +-swing degC)
//    and the motor friction following it, f_m = f_m0 (1 + alpha (T - T_ref));
//  - wearing axes: f_m rising linearly from a start day (gearbox wear);
//  - reloaded axes: J_a stepping up from a start day (a heavier tool or payload);
//  - faulty axes: k_T stepping up from a start day (the seed's torque-constant fault).
#include <cstdint>
#include <string>

#include "core/common/progress.h"

namespace flexarm {

struct FleetSimulationOptions {
  int robots = 4;
  int axes = 1;                 // per robot
  int days = 30;
  std::uint64_t seed = 1;
  std::string startDate = "2026-03-01";  // the first day; logs at 06:00 UTC
  double durationS = 12.0;      // of each daily log
  double logRateHz = 1000.0;    // (the controller runs at 2 kHz)
  double amplitudeRad = 0.2;    // of the multisine, motor side
  double spread = 0.1;          // axes' parameters within +- this fraction of p6
  double temperatureMeanC = 25.0, temperatureSwingC = 10.0;
  double alpha = 0.01;          // f_m's relative change per degC
  int wear = 1, loads = 1, faults = 1;  // axes with each change (distinct axes)
  double wearPerDay = 0.02;     // f_m's relative rise per day
  double loadChange = 0.25;     // J_a's relative step
  double faultSize = 0.2;       // k_T's relative step
  int jobs = 0;                 // threads (0: one per core)
  bool isValid(std::string* why) const;
};

struct FleetSimulationResult {
  Termination termination = Termination::Failed;
  std::string message;
  std::string manifest, truth;  // the files written
  int logs = 0;
  double seconds = 0.0;
};

// Writes DIR/manifest.csv, DIR/truth.json and DIR/ROBOT/axN/DATE.csv. The same options give
// the same bytes. Invalid options throw std::invalid_argument; a failed write or simulation is
// Failed with a sentence.
FleetSimulationResult simulateFleet(const std::string& dir, const FleetSimulationOptions& options,
                                    const ProgressCallback& progress = {});

}  // namespace flexarm
