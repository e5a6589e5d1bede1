#pragma once
// Closed-loop logs of the simulator (Figure 5.1) for the fit pipeline's tests.
#include <algorithm>
#include <cstdint>
#include <memory>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/models/physical_models.h"
#include "core/sim/closed_loop.h"

namespace flexarm::testing {

// A closed-loop log of the two-mass arm (Table 5.2) at 2 kHz, the chirp of Section 5.1, the
// simulator's noise; without the controller in its metadata unless keepController.
inline std::shared_ptr<IdData> twoMassLog(double durationS, std::uint64_t seed, bool keepController = false,
                                          const ControllerOptions& controller = {}) {
  SimulationOptions o;
  o.durationS = durationS;
  o.seed = seed;
  o.controller = controller;
  const SimulationResult sim = simulateClosedLoop(*makeModel("two-mass"), {}, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  auto d = std::make_shared<IdData>(sim.data);
  if (!keepController)
    d->metadata.erase(std::remove_if(d->metadata.begin(), d->metadata.end(),
                                     [](const auto& kv) { return kv.first.rfind("controller_", 0) == 0; }),
                      d->metadata.end());
  return d;
}

inline Eigen::VectorXd column(const IdData& d, const char* name) {
  const auto& v = d.channel(name)->values;
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace flexarm::testing
