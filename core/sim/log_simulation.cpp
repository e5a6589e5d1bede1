#include "core/sim/log_simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "core/ident/evaluation.h"
#include "core/models/nonlinear_plant.h"
#include "core/signal/preprocess.h"

namespace flexarm {

bool LogSimulationOptions::isValid(std::string* why) const {
  if (substeps < 0 || substeps > 1000) {
    if (why) *why = "substeps must be in 0..1000";
    return false;
  }
  return true;
}

namespace {

Eigen::Map<const Eigen::VectorXd> view(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

std::optional<double> LogSimulationResult::fitPercentOver(const SampleRange& range) const {
  if (!ok() || range.empty() || range.end > measured.size()) return std::nullopt;
  return flexarm::fitPercent(view(measured), view(simulated), static_cast<Eigen::Index>(range.begin),
                             static_cast<Eigen::Index>(range.end));
}

LogSimulationResult simulateAgainstLog(const PhysicalModel& model, const std::vector<Effect>& effects,
                                       const IdData& data, const LogSimulationOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("simulateAgainstLog: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  LogSimulationResult r;
  auto finish = [&r, t0](Termination t, std::string message) {
    r.termination = t;
    r.message = std::move(message);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  };
  const Channel* torque = data.channel(columns::kTorqueRef);
  if (!torque) torque = data.input();
  const Channel* velocity = data.channel(columns::kMotorVelocity);
  const Channel* angle = data.channel(columns::kMotorAngle);
  if (!torque || (!velocity && !angle) || data.samples() < 2 || !(data.sampleTime > 0.0))
    return finish(Termination::Failed, "the log needs a torque reference and a motor angle or velocity");
  try {
    const NonlinearPlant plant(model, effects);
    TorqueResponseOptions o;
    o.substeps = options.substeps > 0 ? options.substeps
                                      : std::max(2, static_cast<int>(std::ceil(data.sampleTime / 2.5e-4)));
    r.simulated = simulateTorque(plant, torque->values, data.sampleTime, o).motorVelocity;
  } catch (const std::invalid_argument& e) {
    return finish(Termination::Failed, std::string("the simulation failed: ") + e.what());
  }
  r.measured = velocity ? velocity->values : differentiate(angle->values, data.sampleTime);
  if (r.simulated.size() != r.measured.size())
    return finish(Termination::Failed, "the simulation did not cover the log");
  if (!std::all_of(r.simulated.begin(), r.simulated.end(), [](double v) { return std::isfinite(v); }))
    return finish(Termination::Diverged, "the simulated motor velocity diverges (an unstable model?)");
  r.time.resize(r.measured.size());
  for (std::size_t i = 0; i < r.time.size(); ++i) r.time[i] = data.timeAt(i);
  r.fitPercent = flexarm::fitPercent(view(r.measured), view(r.simulated));
  return finish(Termination::Converged, "simulated " + std::to_string(r.time.size()) + " samples");
}

}  // namespace flexarm
