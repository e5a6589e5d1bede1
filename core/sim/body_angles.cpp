#include "core/sim/body_angles.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/models/nonlinear_plant.h"

namespace flexarm {
namespace {

// Index of the state named name in the model's state names, or -1.
int stateIndex(const PhysicalModel& m, const char* name) {
  const auto names = m.stateNames();
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

double valueAt(const std::vector<double>& v, std::size_t k) { return v.empty() ? 0.0 : v[k]; }

double largest(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace

const char* toString(MotorAngleSource s) {
  return s == MotorAngleSource::Measured ? "measured" : "simulated";
}

bool BodyAnglesOptions::isValid(std::string* why) const {
  if (substeps < 0 || substeps > 1000) {
    if (why) *why = "substeps must lie in 0..1000 (0 chooses them)";
    return false;
  }
  if (why) why->clear();
  return true;
}

std::size_t BodyAngles::sampleAt(double t) const {
  if (motor.empty()) return 0;
  const double pos = std::round((t - startTime) / sampleTime);
  return static_cast<std::size_t>(std::clamp(pos, 0.0, static_cast<double>(motor.size() - 1)));
}

BodyPose BodyAngles::at(std::size_t k) const {
  BodyPose p;
  if (k >= motor.size()) return p;
  p.motor = motor[k];
  p.gearInput = gearRatio * p.motor;
  p.gearDeflection = valueAt(gearDeflection, k);
  p.armDeflection = valueAt(armDeflection, k);
  p.parallelDeflection = valueAt(parallelDeflection, k);
  p.gear = p.gearInput - p.gearDeflection;  // (3.20): x1 = r phi_m - phi_g
  p.arm = p.gear - p.armDeflection;         // x2 = phi_g - phi_a
  p.parallel = p.gear - p.parallelDeflection;  // (3.23): x3 = phi_g - phi_p
  return p;
}

BodyPose BodyAngles::atTime(double t) const { return at(sampleAt(t)); }

BodyAngles simulateBodyAngles(const PhysicalModel& model, const std::vector<Effect>& effects,
                              const IdData& data, const BodyAnglesOptions& options,
                              const ProgressCallback& progress) {
  const auto started = std::chrono::steady_clock::now();
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("simulateBodyAngles: " + why);
  const NonlinearPlant plant(model, effects);  // throws for invalid effects
  const PhysicalModel& m = plant.model();
  BodyAngles out;
  out.structure = m.structureName();
  out.gearRatio = m.value("r");
  out.startTime = data.startTime;
  out.sampleTime = data.sampleTime;
  auto finish = [&](Termination t, std::string message) {
    out.termination = t;
    out.message = std::move(message);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return out;
  };
  const Channel* torque = data.channel(columns::kTorqueRef);
  if (!torque) torque = data.input();
  if (!torque || data.samples() == 0)
    return finish(Termination::Failed, "The log has no torque reference to simulate the model on.");
  if (!(data.sampleTime > 0.0) || !std::isfinite(data.sampleTime))
    return finish(Termination::Failed, "The log's sample time is not positive.");

  // The springs of the structure, by their state names in the seed's coordinates.
  const int gear = std::max(stateIndex(m, "r*phi_m - phi_g"), stateIndex(m, "r*phi_m - phi_a"));
  const int arm = stateIndex(m, "phi_g - phi_a");
  const int parallel = stateIndex(m, "phi_g - phi_p");
  out.springs = (gear >= 0) + (arm >= 0) + (parallel >= 0);
  const std::size_t N = data.samples();
  const Channel* measured = data.channel(columns::kMotorAngle);
  out.motorAngleSource = options.motorAngle == MotorAngleSource::Measured && measured
                             ? MotorAngleSource::Measured
                             : MotorAngleSource::Simulated;
  out.motor.resize(N);
  if (gear >= 0) out.gearDeflection.resize(N);
  if (arm >= 0) out.armDeflection.resize(N);
  if (parallel >= 0) out.parallelDeflection.resize(N);

  TorqueResponseOptions sim;
  sim.substeps = options.substeps > 0
                     ? options.substeps
                     : std::max(1, static_cast<int>(std::ceil(data.sampleTime / 2.5e-4 - 1e-9)));
  const std::size_t every = std::max<std::size_t>(1, N / 200);
  bool cancelled = false, diverged = false;
  std::size_t divergedAt = 0;
  simulateTorque(plant, torque->values, data.sampleTime, sim,
                 [&](std::size_t k, const NonlinearPlant::State& x, double) {
                   for (int i = 0; i < plant.states(); ++i)
                     if (!(std::abs(x[static_cast<std::size_t>(i)]) < 1e12)) {  // or NaN
                       diverged = true;
                       divergedAt = k;
                       return false;
                     }
                   out.motor[k] = out.motorAngleSource == MotorAngleSource::Measured
                                      ? measured->values[k]
                                      : plant.motorAngle(x);
                   if (gear >= 0) out.gearDeflection[k] = x[static_cast<std::size_t>(gear)];
                   if (arm >= 0) out.armDeflection[k] = x[static_cast<std::size_t>(arm)];
                   if (parallel >= 0)
                     out.parallelDeflection[k] = x[static_cast<std::size_t>(parallel)];
                   if (k % every == 0 &&
                       reportProgress(progress, static_cast<double>(k) / N, "simulating the masses")) {
                     cancelled = true;
                     return false;
                   }
                   return true;
                 });
  if (cancelled) {
    for (auto* v : {&out.motor, &out.gearDeflection, &out.armDeflection, &out.parallelDeflection})
      v->clear();
    return finish(Termination::Cancelled, "The simulation of the masses was cancelled.");
  }
  if (diverged) {
    for (auto* v : {&out.motor, &out.gearDeflection, &out.armDeflection, &out.parallelDeflection})
      v->clear();
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "The %s model diverged on the log's torque at %.4g s: the model is unstable "
                  "or its parameters are far from the arm's.",
                  out.structure.c_str(), data.timeAt(divergedAt));
    return finish(Termination::Diverged, buf);
  }
  out.maxGearDeflection = largest(out.gearDeflection);
  out.maxArmDeflection = largest(out.armDeflection);
  out.maxParallelDeflection = largest(out.parallelDeflection);
  return finish(Termination::Converged,
                "The " + out.structure + " model was simulated on the log's torque; the motor angle is " +
                    toString(out.motorAngleSource) + ".");
}

}  // namespace flexarm
