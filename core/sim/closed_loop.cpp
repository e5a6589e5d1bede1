#include "core/sim/closed_loop.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <utility>

#include "core/common/text.h"
#include "core/models/nonlinear_plant.h"
#include "core/sim/random.h"

namespace flexarm {

namespace {
bool failWith(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}
bool finitePositive(double v) { return v > 0.0 && std::isfinite(v); }
}  // namespace

bool ControllerOptions::isValid(std::string* why) const {
  if (!finitePositive(rateHz)) return failWith(why, "controller rate must be > 0");
  if (!(kp >= 0.0) || !(kv > 0.0) || !(ti >= 0.0))
    return failWith(why, "controller gains: kp >= 0, kv > 0, ti >= 0");
  if (why) why->clear();
  return true;
}

bool DisturbanceOptions::isValid(std::string* why) const {
  if (!(torqueNoiseStd >= 0.0) || !(loadTorqueStd >= 0.0))
    return failWith(why, "noise levels must be >= 0");
  if (!finitePositive(loadBandwidthHz)) return failWith(why, "load bandwidth must be > 0");
  if (!std::isfinite(loadStepNm) || !(loadStepTimeS >= 0.0))
    return failWith(why, "load step must be finite and start at t >= 0");
  if (encoderCountsPerRev < 0 || armEncoderCountsPerRev < 0) return failWith(why, "encoder counts must be >= 0");
  if (why) why->clear();
  return true;
}

bool SimulationOptions::isValid(std::string* why) const {
  if (!controller.isValid(why) || !disturbance.isValid(why) || !excitation.isValid(why))
    return false;
  if (!finitePositive(durationS) || durationS > kMaxDurationS)
    return failWith(why, "duration must be in (0, 1e5] s");
  if (!finitePositive(logRateHz)) return failWith(why, "log rate must be > 0");
  const double ratio = controller.rateHz / logRateHz;
  if (ratio < 1.0 - 1e-9 || std::abs(ratio - std::round(ratio)) > 1e-9)
    return failWith(why, "the log rate must divide the controller rate");
  if (substeps < 1 || substeps > 10000) return failWith(why, "substeps must be in 1..10000");
  // Memory and time grow with the samples and controller ticks: bounded before allocating.
  if (durationS * logRateHz > kMaxSamples)
    return failWith(why, "the log would have " + std::to_string(std::llround(durationS * logRateHz)) +
                             " samples (duration x log rate), more than the " +
                             std::to_string(static_cast<long long>(kMaxSamples)) +
                             " one simulation writes; shorten the duration or lower the rate");
  if (durationS * controller.rateHz > kMaxTicks)
    return failWith(why, "the simulation would run " +
                             std::to_string(std::llround(durationS * controller.rateHz)) +
                             " controller ticks (duration x controller rate), more than " +
                             std::to_string(static_cast<long long>(kMaxTicks)) +
                             "; shorten the duration or lower the controller rate");
  if (!std::isfinite(referenceVelocity)) return failWith(why, "reference velocity must be finite");
  if (!(velocityFeedForward >= 0.0 && velocityFeedForward <= 2.0))
    return failWith(why, "the velocity feed-forward must be a fraction in [0, 2]");
  if (!(velocityFilterHz >= 0.0) || !std::isfinite(velocityFilterHz))
    return failWith(why, "the velocity filter's corner must be a finite frequency >= 0");
  if (!referenceSignal.empty() && !(referenceSampleTime > 0.0 && std::isfinite(referenceSampleTime)))
    return failWith(why, "a given reference signal needs a sample time > 0");
  for (double v : referenceSignal)
    if (!std::isfinite(v)) return failWith(why, "the given reference signal holds a non-finite value");
  for (const auto& s : parameterSteps)
    if (s.name.empty() || !std::isfinite(s.value) || !(s.timeS >= 0.0) || !std::isfinite(s.timeS))
      return failWith(why, "a parameter step needs a name, a finite value and a time >= 0");
  if (why) why->clear();
  return true;
}

namespace {

// The plant before any step, then after each step in time order (the steps accumulate).
struct PlantSchedule {
  std::vector<std::unique_ptr<NonlinearPlant>> plants;
  std::vector<double> startTimes;  // plants[i] runs from startTimes[i] on
};

PlantSchedule schedulePlants(const PhysicalModel& model, const std::vector<Effect>& effects,
                             std::vector<ParameterStep> steps) {
  PlantSchedule s;
  s.plants.push_back(std::make_unique<NonlinearPlant>(model, effects));
  s.startTimes.push_back(0.0);
  std::stable_sort(steps.begin(), steps.end(),
                   [](const ParameterStep& a, const ParameterStep& b) { return a.timeS < b.timeS; });
  auto changed = model.clone();
  for (const auto& step : steps) {
    if (model.indexOf(step.name) < 0)
      throw std::invalid_argument("parameter step: the " + model.structureName() +
                                  " model has no parameter " + inQuotes(step.name));
    changed->setParameter(step.name, step.value);  // throws outside the bounds
    s.plants.push_back(
        std::make_unique<NonlinearPlant>(dynamic_cast<const PhysicalModel&>(*changed), effects));
    s.startTimes.push_back(step.timeS);
  }
  return s;
}

}  // namespace

SimulationResult simulateClosedLoop(const PhysicalModel& model, const std::vector<Effect>& effects,
                                    const SimulationOptions& o, const ProgressCallback& progress) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("simulateClosedLoop: " + why);
  const auto start = std::chrono::steady_clock::now();
  const PlantSchedule schedule = schedulePlants(model, effects, o.parameterSteps);
  std::size_t segment = 0;
  const NonlinearPlant* active = schedule.plants.front().get();
  const double Tc = 1.0 / o.controller.rateHz;
  const std::size_t decimation = static_cast<std::size_t>(std::llround(o.controller.rateHz / o.logRateHz));
  const std::size_t samples = static_cast<std::size_t>(std::llround(o.durationS * o.logRateHz));
  const std::size_t ticks = samples * decimation;
  SimulationResult result;

  // Separate streams: the excitation must not change when the noise settings change.
  const bool given = !o.referenceSignal.empty();
  const std::vector<double> excitation =
      given ? std::vector<double>{} : makeExcitation(o.excitation, Tc, ticks, o.seed);
  auto givenReference = [&o](double t) {
    const double pos = t / o.referenceSampleTime;
    const std::size_t i = static_cast<std::size_t>(pos);
    if (i + 1 >= o.referenceSignal.size()) return o.referenceSignal.back();
    const double f = pos - static_cast<double>(i);
    return (1.0 - f) * o.referenceSignal[i] + f * o.referenceSignal[i + 1];
  };
  Random noise(o.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull);

  std::vector<double> applied(ticks, 0.0);  // torque reference + noise, per tick
  const double delay = active->inputDelay();
  auto torqueAt = [&applied, Tc, delay](double t) {
    const double tau = (t - delay) / Tc;
    return tau < 0.0 ? 0.0 : applied[static_cast<std::size_t>(tau)];
  };

  IdData& d = result.data;
  d.sampleTime = 1.0 / o.logRateHz;
  std::vector<double> logAngle(samples), logTorque(samples), logRef(samples), logVel, logAcc,
      logGearD, logGearT, logArm;
  if (o.logArmAngle) logArm.resize(samples);
  if (o.logMotorVelocity) logVel.resize(samples);
  if (o.logArmAcceleration) logAcc.resize(samples);
  if (o.logGear) {
    logGearD.resize(samples);
    logGearT.resize(samples);
  }

  const double quantum =
      o.disturbance.encoderCountsPerRev > 0 ? 2.0 * M_PI / o.disturbance.encoderCountsPerRev : 0.0;
  auto measure = [quantum](double angle) {
    return quantum > 0.0 ? quantum * std::nearbyint(angle / quantum) : angle;
  };
  const double armQuantum = o.disturbance.armEncoderCountsPerRev > 0
                                ? 2.0 * M_PI / static_cast<double>(o.disturbance.armEncoderCountsPerRev)
                                : 0.0;
  // The velocity filter's pole at the controller rate (0: no filter).
  const double velocityPole = o.velocityFilterHz > 0.0 ? std::exp(-2.0 * M_PI * o.velocityFilterHz * Tc) : 0.0;
  double filteredVelocity = 0.0, previousReference = 0.0;
  const double loadPole = std::exp(-2.0 * M_PI * o.disturbance.loadBandwidthHz * Tc);
  // Scale of the first-order noise so that its stationary standard deviation is loadTorqueStd.
  const double loadGain = o.disturbance.loadTorqueStd * std::sqrt(1.0 - loadPole * loadPole);

  NonlinearPlant::State x{};
  double integral = 0.0, previousAngle = 0.0, loadNoise = 0.0;
  const double h = Tc / o.substeps;
  const double bound = 1e6;  // rad or rad/s: the loop has run away
  for (std::size_t k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) * Tc;
    while (segment + 1 < schedule.plants.size() && t >= schedule.startTimes[segment + 1] - 1e-9 * Tc)
      active = schedule.plants[++segment].get();
    const NonlinearPlant& plant = *active;
    const double reference = given ? givenReference(t) : o.referenceVelocity * t + excitation[k];
    const double angle = measure(plant.motorAngle(x));
    const double rawVelocity = k == 0 ? 0.0 : (angle - previousAngle) / Tc;
    previousAngle = angle;
    filteredVelocity = velocityPole * filteredVelocity + (1.0 - velocityPole) * rawVelocity;
    const double velocity = o.velocityFilterHz > 0.0 ? filteredVelocity : rawVelocity;
    const double feedForward = k == 0 ? 0.0 : o.velocityFeedForward * (reference - previousReference) / Tc;
    previousReference = reference;
    const double ev = o.controller.kp * (reference - angle) + feedForward - velocity;
    integral += ev * Tc;
    const double u =
        o.controller.kv * (ev + (o.controller.ti > 0.0 ? integral / o.controller.ti : 0.0));
    applied[k] = u + o.disturbance.torqueNoiseStd * noise.normal();
    loadNoise = loadPole * loadNoise + loadGain * noise.normal();
    const double load =
        loadNoise + (t >= o.disturbance.loadStepTimeS ? o.disturbance.loadStepNm : 0.0);
    if (k % decimation == 0) {
      const std::size_t i = k / decimation;
      logAngle[i] = angle;
      logTorque[i] = u;
      logRef[i] = reference;
      if (o.logMotorVelocity) logVel[i] = plant.motorVelocity(x);
      if (o.logArmAcceleration) logAcc[i] = plant.armAcceleration(x, torqueAt(t + 1e-6 * h), load);
      if (o.logArmAngle) {
        const double arm = plant.armAngle(x);
        logArm[i] = armQuantum > 0.0 ? armQuantum * std::nearbyint(arm / armQuantum) : arm;
      }
      if (o.logGear) {
        logGearD[i] = plant.gearDeflection(x);
        logGearT[i] = plant.gearTorque(x);
      }
    }
    for (int s = 0; s < o.substeps; ++s) plant.step(x, t + s * h, h, torqueAt, load);
    bool finite = true;
    for (int i = 0; i < plant.states(); ++i)
      finite = finite && std::isfinite(x[static_cast<std::size_t>(i)]) &&
               std::abs(x[static_cast<std::size_t>(i)]) < bound;
    if (!finite) {
      result.termination = Termination::Diverged;
      result.message = "the closed loop is unstable: the state left every sensible range at t = " +
                       std::to_string(t) + " s (check the controller gains and the parameters)";
      result.data = IdData{};
      result.controllerTicks = k + 1;
      return result;
    }
    if (k % 4096 == 0 && reportProgress(progress, static_cast<double>(k) / ticks, "simulate")) {
      result.termination = Termination::Cancelled;
      result.message = "cancelled";
      result.data = IdData{};
      result.controllerTicks = k + 1;
      return result;
    }
  }

  auto add = [&d](const char* name, ChannelRole role, std::vector<double>& v) {
    d.setChannel(Channel{name, unitFromColumnName(name), role, std::move(v)});
  };
  add(columns::kMotorAngle, ChannelRole::Output, logAngle);
  add(columns::kTorqueRef, ChannelRole::Input, logTorque);
  add(columns::kAngleRef, ChannelRole::Reference, logRef);
  if (o.logMotorVelocity) add(columns::kMotorVelocity, ChannelRole::None, logVel);
  if (o.logArmAcceleration) add(columns::kArmAccel, ChannelRole::None, logAcc);
  if (o.logArmAngle) add(columns::kArmAngle, ChannelRole::None, logArm);
  if (o.logGear) {
    add("gear_deflection_rad", ChannelRole::None, logGearD);
    add("gear_torque_nm", ChannelRole::None, logGearT);
  }
  std::string effectList;
  for (const auto& e : effects) effectList += (effectList.empty() ? "" : " ") + toString(e);
  d.setMeta("generator", "FlexArm simulator (closed loop, Figure 5.1)");
  d.setMeta("model", model.structureName());
  d.setMeta("effects", effectList.empty() ? "none" : effectList);
  d.setMeta("excitation", given ? "given reference signal" : toString(o.excitation.kind));
  d.setMeta("seed", std::to_string(o.seed));
  if (!o.parameterSteps.empty()) {
    std::string steps;
    for (const auto& s : o.parameterSteps) steps += (steps.empty() ? "" : " ") + toString(s);
    d.setMeta("parameter_steps", steps);
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", model.value("r"));
  d.setMeta("gear_ratio", buf);
  // The controller, so that the loop can be closed around a model (the indirect method).
  const std::pair<const char*, double> controller[] = {{"controller_rate_hz", o.controller.rateHz},
                                                       {"controller_kp", o.controller.kp},
                                                       {"controller_kv", o.controller.kv},
                                                       {"controller_ti", o.controller.ti}};
  for (const auto& [key, value] : controller) {
    std::snprintf(buf, sizeof buf, "%.12g", value);
    d.setMeta(key, buf);
  }
  const std::pair<const char*, double> extra[] = {{"controller_velocity_feedforward", o.velocityFeedForward},
                                                  {"controller_velocity_filter_hz", o.velocityFilterHz}};
  for (const auto& [key, value] : extra)
    if (value != 0.0) {
      std::snprintf(buf, sizeof buf, "%.12g", value);
      d.setMeta(key, buf);
    }
  result.termination = Termination::Converged;
  result.message = "simulated " + std::to_string(samples) + " samples";
  result.controllerTicks = ticks;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::optional<ParameterStep> parseParameterStep(const std::string& text, std::string* why) {
  const auto eq = text.find('=');
  const auto at = text.find('@', eq == std::string::npos ? 0 : eq);
  auto number = [](const std::string& t, double& v) {
    char* end = nullptr;
    v = std::strtod(t.c_str(), &end);
    return !t.empty() && end == t.c_str() + t.size() && std::isfinite(v);
  };
  ParameterStep s;
  if (eq == std::string::npos || eq == 0 || at == std::string::npos ||
      !number(text.substr(eq + 1, at - eq - 1), s.value) || !number(text.substr(at + 1), s.timeS) ||
      s.timeS < 0.0) {
    if (why) *why = "a parameter step is NAME=VALUE@SECONDS (e.g. k_T=1.2@20), not " + inQuotes(text);
    return std::nullopt;
  }
  s.name = text.substr(0, eq);
  return s;
}

std::string toString(const ParameterStep& step) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "=%.12g@%.12g", step.value, step.timeS);
  return step.name + buf;
}

std::optional<ControllerOptions> controllerFromMetadata(const IdData& data, std::string* why) {
  ControllerOptions c;
  const std::pair<const char*, double*> keys[] = {{"controller_rate_hz", &c.rateHz},
                                                  {"controller_kp", &c.kp},
                                                  {"controller_kv", &c.kv},
                                                  {"controller_ti", &c.ti}};
  for (const auto& [key, target] : keys) {
    const std::string text = data.meta(key);
    char* end = nullptr;
    const double v = text.empty() ? NAN : std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
      if (why)
        *why = std::string("the log's metadata key ") + key +
               (text.empty() ? " is missing" : " is not a number") +
               " (logs written by flexarm simulate carry controller_rate_hz, controller_kp, "
               "controller_kv and controller_ti)";
      return std::nullopt;
    }
    // Beyond any controller: a 10 MHz loop, gains of 1e12 (the simulation would overflow).
    const double limit = target == &c.rateHz ? 1e7 : 1e12;
    if (std::abs(v) > limit) {
      if (why) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "the log's metadata key %s is %.6g, beyond any controller (at most %.0g)", key,
                      v, limit);
        *why = buf;
      }
      return std::nullopt;
    }
    *target = v;
  }
  std::string bad;
  if (!c.isValid(&bad)) {
    if (why) *why = "the controller in the log's metadata: " + bad;
    return std::nullopt;
  }
  for (const char* key : {"controller_velocity_feedforward", "controller_velocity_filter_hz"})
    if (!data.meta(key).empty() && std::strtod(data.meta(key).c_str(), nullptr) != 0.0) {
      if (why)
        *why = std::string("the log's controller has ") +
               (std::string(key) == "controller_velocity_feedforward" ? "velocity feed-forward" : "a velocity filter") +
               " (metadata " + key + "), which the cascade of Figure 5.1 the indirect fit closes does not have";
      return std::nullopt;
    }
  return c;
}

}  // namespace flexarm
