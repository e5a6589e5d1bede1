#pragma once
// Logs of a three-mass arm (3.21, Table 5.7 p6) with a stiffening gear spring and Coulomb
// friction, simulated open loop from a known truth, for the nonlinear grey-box fit's tests
// (core and command line).
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "core/models/nonlinear_plant.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"

namespace flexarm::testing {

constexpr double kNonlinearLogT = 0.0025;  // 400 Hz

// The truth's effects: beta = 2e6 1/rad^2, F_c = 0.05 N m with v_s = 0.1 rad/s (the defaults).
inline std::vector<Effect> nonlinearTruthEffects() {
  return {Effect::withDefaults(EffectKind::NonlinearSpring), Effect::withDefaults(EffectKind::CoulombFriction)};
}

// Excitation 0: white torque (0.5 N m); excitation 1: a random binary torque (0.6 N m) held
// for 7 samples.
inline std::vector<double> nonlinearExcitation(std::size_t n, int kind, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<double> u(n);
  std::normal_distribution<double> nd(0.0, 0.5);
  std::bernoulli_distribution coin(0.5);
  double level = 0.6;
  for (std::size_t t = 0; t < n; ++t) {
    if (kind == 0) {
      u[t] = nd(rng);
    } else {
      if (t % 7 == 0) level = coin(rng) ? 0.6 : -0.6;
      u[t] = level;
    }
  }
  return u;
}

// The truth with its effects simulated from rest (the torque held over each sample), the
// motor velocity logged with white noise of 1 % of its spread; torque as input, velocity as
// output, and the (noise-free) motor angle a FlexArm log carries.
inline IdData nonlinearLog(std::size_t n, int kind, unsigned seed) {
  const auto truth = makeModel("three-mass");
  const NonlinearPlant plant(*truth, nonlinearTruthEffects());
  const std::vector<double> u = nonlinearExcitation(n, kind, seed);
  TorqueResponseOptions to;
  to.substeps = 20;
  const TorqueResponse response = simulateTorque(plant, u, kNonlinearLogT, to);
  std::vector<double> y = response.motorVelocity;
  double mean = 0.0, sq = 0.0;
  for (double v : y) mean += v / static_cast<double>(n);
  for (double v : y) sq += (v - mean) * (v - mean) / static_cast<double>(n);
  std::mt19937 rng(seed + 1000);
  std::normal_distribution<double> noise(0.0, 0.01 * std::sqrt(sq));
  for (double& v : y) v += noise(rng);
  IdData d;
  d.sampleTime = kNonlinearLogT;
  d.setChannel({columns::kTorqueRef, "N m", ChannelRole::Input, u});
  d.setChannel({columns::kMotorVelocity, "rad/s", ChannelRole::Output, y});
  d.setChannel({columns::kMotorAngle, "rad", ChannelRole::None, response.motorAngle});
  return d;
}

}  // namespace flexarm::testing
