#include "core/diagnosis/simulate_like.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/diagnosis/reference.h"

namespace flexarm {

std::optional<LogConditions> logConditions(const IdData& log, std::string* why) {
  LogConditions c;
  SimulationOptions& o = c.simulation;
  std::string missing;
  if (auto controller = controllerFromMetadata(log, &missing)) {
    o.controller = *controller;
    c.note = "the log's controller (metadata)";
  } else {
    c.note = "the controller of Figure 5.1 (the log does not name its own)";
  }
  o.logRateHz = log.sampleRateHz();
  const double ratio = o.controller.rateHz / o.logRateHz;
  if (ratio < 1.0 - 1e-9 || std::abs(ratio - std::round(ratio)) > 1e-6 * ratio) {
    if (why)
      *why = "the log's rate (" + std::to_string(o.logRateHz) +
             " Hz) does not divide its controller's rate, so it cannot be simulated again";
    return std::nullopt;
  }
  o.logRateHz = o.controller.rateHz / std::round(ratio);
  o.durationS = static_cast<double>(log.samples()) * log.sampleTime;
  if (!(o.durationS <= SimulationOptions::kMaxDurationS)) {
    if (why) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "the log lasts %.4g s (a time step of %.4g s), longer than the %.0f s the simulator runs, "
                    "so it cannot be simulated again",
                    o.durationS, log.sampleTime, SimulationOptions::kMaxDurationS);
      *why = buf;
    }
    return std::nullopt;
  }
  if (log.samples() < 10) {
    if (why) *why = "the log is too short to be simulated again";
    return std::nullopt;
  }
  if (const Channel* r = log.withRole(ChannelRole::Reference)) {
    o.referenceSignal = r->values;
    o.referenceSampleTime = log.sampleTime;
    c.note += ", its own position reference";
  } else {
    o.excitation.kind = ExcitationKind::Multisine;
    c.note += ", a multisine reference (6.50) (the log has no reference channel)";
  }
  return c;
}

SimulationOptions runOptions(const LogConditions& conditions, double noiseScale, std::uint64_t seed,
                             const std::vector<ParameterStep>& steps, double durationS) {
  SimulationOptions o = conditions.simulation;
  o.disturbance.torqueNoiseStd *= noiseScale;
  o.disturbance.loadTorqueStd *= noiseScale;
  o.seed = seed;
  o.parameterSteps = steps;
  if (durationS > 0.0) o.durationS = durationS;
  return o;
}

double matchNoiseScale(const PhysicalModel& plant, const PhysicalModel& start,
                       const LogConditions& conditions, DiagnosisPredictor predictor,
                       double targetMeanSquare, std::string* note) {
  auto meanSquare = [&](double scale) -> double {
    const auto run = simulateClosedLoop(plant, {}, runOptions(conditions, scale, 1));
    if (run.termination != Termination::Converged) return NAN;
    auto s = diagnosisSignals(run.data, predictor, nullptr);
    if (!s) return NAN;
    const NominalFit fit = fitNominalModel(start, *s, false, 60);
    return fit.termination == Termination::Converged ? fit.loss : NAN;
  };
  const double quiet = meanSquare(0.0), loud = meanSquare(1.0);
  if (!(targetMeanSquare > 0.0) || !std::isfinite(quiet) || !std::isfinite(loud) || loud <= quiet) {
    if (note) *note = "the simulator's default noise (the log's noise level could not be matched)";
    return 1.0;
  }
  const double scale = std::sqrt(std::max(0.0, targetMeanSquare - quiet) / (loud - quiet));
  if (note) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "torque and load noise %.3g times the simulator's defaults (theta_0's output "
                  "error RMS %.3g as on the fault-free log)",
                  scale, std::sqrt(targetMeanSquare));
    *note = buf;
  }
  return scale;
}

}  // namespace flexarm
