#pragma once
// The angle of every mass of a physical model along a log (Table 3.1: phi_m, phi_g, phi_a,
// phi_p) and the spring deflections between them: the model's states (3.13), (3.19)-(3.20)
// and (3.22)-(3.23) simulated on the log's torque reference, with the motor angle phi_m as
// the extra integrator state. What the 3D arm view plays; no drawing here.
#include <cstddef>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"

namespace flexarm {

// Where the motor angle the bodies turn about comes from.
enum class MotorAngleSource {
  // The log's measured motor angle; the deflections are the simulated ones. An open-loop
  // simulation of a closed-loop log drifts in angle (the loop's corrections and the load are
  // not in the torque alone) but not in the deflections, which only the accelerations excite.
  Measured,
  // The simulated motor angle (used whenever the log has no motor angle).
  Simulated,
};
const char* toString(MotorAngleSource s);  // "measured", "simulated"

struct BodyAnglesOptions {
  MotorAngleSource motorAngle = MotorAngleSource::Measured;
  int substeps = 0;  // Runge-Kutta steps per sample; 0: as many as make steps <= 0.25 ms
  bool isValid(std::string* why) const;
};

// The pose of the arm at one sample, in radians. Arm-side angles (after the gear) are
// gearInput = r phi_m, gear = phi_g, arm = phi_a, parallel = phi_p; the motor angle phi_m is
// on the motor side. For the rigid model every arm-side angle is r phi_m; for the two-mass
// model phi_g is phi_a (its one spring joins the gear input to the arm).
struct BodyPose {
  double motor = 0.0;       // phi_m
  double gearInput = 0.0;   // r phi_m
  double gear = 0.0;        // phi_g
  double arm = 0.0;         // phi_a
  double parallel = 0.0;    // phi_p (four-mass; else phi_g)
  double gearDeflection = 0.0;      // r phi_m - phi_g (two-mass: r phi_m - phi_a)
  double armDeflection = 0.0;       // phi_g - phi_a (three- and four-mass)
  double parallelDeflection = 0.0;  // phi_g - phi_p (four-mass)
};

struct BodyAngles {
  std::string structure;   // of the simulated model (after an extra_mass effect)
  int springs = 0;         // 0 rigid, 1 two-mass, 2 three-mass, 3 four-mass
  double gearRatio = 0.0;  // r
  double startTime = 0.0;
  double sampleTime = 1.0;
  MotorAngleSource motorAngleSource = MotorAngleSource::Simulated;
  std::vector<double> motor;               // phi_m at every sample
  std::vector<double> gearDeflection;      // empty for the rigid model
  std::vector<double> armDeflection;       // three- and four-mass only
  std::vector<double> parallelDeflection;  // four-mass only
  // Largest |deflection| over the log, rad (0 where the model has no such spring).
  double maxGearDeflection = 0.0, maxArmDeflection = 0.0, maxParallelDeflection = 0.0;
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;

  std::size_t samples() const { return motor.size(); }
  BodyPose at(std::size_t k) const;
  // The pose at the sample nearest to time t (clamped to the log).
  BodyPose atTime(double t) const;
  std::size_t sampleAt(double t) const;
};

// Simulates the model (with its effects) from rest on the log's torque reference (the
// torque_ref_nm channel, else the input channel) held over each sample. A diverging
// simulation ends with Termination::Diverged, a cancelled one with Cancelled, a log without
// torque with Failed, each with a sentence; invalid options or effects throw
// std::invalid_argument.
BodyAngles simulateBodyAngles(const PhysicalModel& model, const std::vector<Effect>& effects,
                              const IdData& data, const BodyAnglesOptions& options = {},
                              const ProgressCallback& progress = {});

}  // namespace flexarm
