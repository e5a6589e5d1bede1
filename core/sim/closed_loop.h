#pragma once
// Closed-loop simulation of one robot axis as in the seed's Figure 5.1: a physical model with
// any effects, under a cascaded controller (P position loop, PI velocity loop) running at the
// controller rate, with torque-reference noise, a load disturbance on the arm and an encoder
// of finite resolution on the motor angle. The excitation is added to the position reference
// phi_ref; the log holds what the seed measured: phi_ref, the torque reference u (before the
// torque noise) and the measured motor angle (plus, on request, the true motor velocity and
// arm acceleration), and its metadata the controller (controller_rate_hz, controller_kp,
// controller_kv, controller_ti).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"
#include "core/sim/excitation.h"

namespace flexarm {

// u = k_v (e_v + (1/T_i) int e_v), e_v = k_p (phi_ref - phi_m,meas) - phi_m',est, with
// phi_m',est the backward difference of the measured angle.
struct ControllerOptions {
  double rateHz = 2000.0;  // controller sample rate (the seed's S4C: 0.5 ms)
  double kp = 40.0;        // position gain, 1/s
  double kv = 0.3;         // velocity gain, N m s/rad
  double ti = 0.05;        // integral time of the velocity loop, s (0: no integral action)
  bool isValid(std::string* why) const;
};

struct DisturbanceOptions {
  double torqueNoiseStd = 0.02;     // N m, white, added to the torque reference at each tick
  double loadTorqueStd = 2.0;       // N m on the arm, low-pass noise (first order)
  double loadBandwidthHz = 2.0;     // corner of the load noise
  double loadStepNm = 0.0;          // N m on the arm from loadStepTimeS on
  double loadStepTimeS = 0.0;
  long encoderCountsPerRev = 65536; // motor encoder resolution; 0: ideal (no quantization)
  bool isValid(std::string* why) const;
};

// A parameter of the model that steps to a new value at a given time while the log runs: an
// abrupt multiplicative fault (the seed's Section 7.1), e.g. k_T up 20 % at 20 s. The state
// (angles and velocities) is continuous across the step.
struct ParameterStep {
  std::string name;    // a parameter of the model, e.g. "k_T", "J_a", "f_m"
  double value = 0.0;  // its value from timeS on (within the parameter's bounds)
  double timeS = 0.0;  // seconds from the start of the log, >= 0
};

struct SimulationOptions {
  ControllerOptions controller;
  DisturbanceOptions disturbance;
  ExcitationOptions excitation;
  static constexpr double kMaxSamples = 4e6;   // of the log (33 min at 2 kHz)
  static constexpr double kMaxTicks = 2e7;     // controller periods
  static constexpr double kMaxDurationS = 1e5;  // seconds of one simulation
  double durationS = 20.0;
  double logRateHz = 2000.0;        // must divide the controller rate
  double referenceVelocity = 0.0;   // rad/s of the motor: phi_ref = v t + excitation
  int substeps = 10;                // Runge-Kutta steps per controller period
  std::uint64_t seed = 1;
  bool logMotorVelocity = false;    // adds motor_velocity_rad_s (true velocity)
  bool logArmAcceleration = false;  // adds arm_accel_rad_s2 (true acceleration)
  bool logGear = false;             // adds gear_deflection_rad and gear_torque_nm
  // A given position reference phi_ref (rad, motor side), sampled every referenceSampleTime s
  // from t = 0 and interpolated linearly at the controller rate (held after its last sample),
  // in place of the excitation and the reference velocity: to run the loop of a log again
  // with the log's own reference. Empty: the excitation.
  std::vector<double> referenceSignal;
  double referenceSampleTime = 0.0;
  // Parameters that change during the run, applied in time order at the first controller
  // tick at or after their time. Empty: the model is the same throughout.
  std::vector<ParameterStep> parameterSteps;
  bool isValid(std::string* why) const;
};

struct SimulationResult {
  IdData data;
  Termination termination = Termination::Failed;
  std::string message;
  std::size_t controllerTicks = 0;
  double seconds = 0.0;
};

// Simulates the closed loop from rest. Deterministic for a given seed. An unstable loop ends
// with Termination::Diverged and a message; invalid options or effects, or a parameter step
// naming a parameter the model lacks or a value outside its bounds, throw
// std::invalid_argument. A log with parameter steps says so in its metadata
// (parameter_steps: NAME=VALUE@TIME ...).
SimulationResult simulateClosedLoop(const PhysicalModel& model, const std::vector<Effect>& effects,
                                    const SimulationOptions& options,
                                    const ProgressCallback& progress = {});

// The controller a log was recorded under, from its metadata (controller_rate_hz,
// controller_kp, controller_kv, controller_ti, as simulateClosedLoop writes them): what the
// indirect closed-loop fit closes around the model. nullopt with a sentence naming the
// missing or malformed key, or the invalid controller.
// "k_T=1.2@20": a parameter step as the command line and the metadata write it; nullopt with
// a sentence for malformed text.
std::optional<ParameterStep> parseParameterStep(const std::string& text, std::string* why);
std::string toString(const ParameterStep& step);

std::optional<ControllerOptions> controllerFromMetadata(const IdData& data, std::string* why);

}  // namespace flexarm
