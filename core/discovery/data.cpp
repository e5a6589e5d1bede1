// The data sets of a discovery run: the estimation log and the held-out data (the validation
// log, or the end of the estimation log when there is none), as series of the predictor.
#include <algorithm>
#include <cmath>

#include "core/discovery/discovery_internal.h"
#include "core/ident/fit_data.h"
#include "core/signal/preprocess.h"

namespace flexarm::discovery_detail {

namespace {

// A log whose output is the motor velocity (motor_velocity_rad_s, or an output channel in
// rad/s, as the physical models give it).
const Channel* velocityChannel(const IdData& data) {
  if (const Channel* v = data.channel(columns::kMotorVelocity)) return v;
  const Channel* out = data.output();
  return out && out->unit == "rad/s" ? out : nullptr;
}

}  // namespace

// The data set through the fit pipeline's preparation (core/ident/fit_data.h), the same
// steps every estimator runs: the channels (the input role, else the torque reference; the
// motor angle as the output), decimation behind the anti-alias FIR with the input held as its
// mean over each new period (the impulse of the torque the controller held at the log's
// rate, what the plant integrates), the means kept (friction and backlash act on the real
// velocity, the ripple on the real angle). The angle is differentiated here, at the fitting
// rate, exactly as the predicted angle is.
//
// A log whose output is the motor velocity is integrated to an angle from zero (trapezoids),
// and that angle is differentiated like a measured one, so the measured and the predicted
// velocity pass the same central differences. Only the ripple, which acts on the absolute
// angle, then sees an angle offset by the unknown start.
std::optional<NonlinearSeries> makeSeries(const IdData& data, double maxRateHz, std::string* why) {
  const Channel* in = data.input();
  if (!in) in = data.channel(columns::kTorqueRef);
  const Channel* angle = data.channel(columns::kMotorAngle);
  const Channel* velocity = angle ? nullptr : velocityChannel(data);
  const Channel* measured = angle ? angle : velocity;
  if (!in || !measured || in == measured) {
    *why = "the log needs the torque reference (input) and the motor angle " +
           std::string(columns::kMotorAngle) + " or the motor velocity " +
           std::string(columns::kMotorVelocity) + " (or an output in rad/s)";
    return std::nullopt;
  }
  FitDataOptions o;
  o.input = in->name;
  o.output = measured->name;
  o.reference = "";
  o.decimation = std::max(1, static_cast<int>(std::floor(data.sampleRateHz() / maxRateHz + 0.5)));
  o.decimatedInput = FitDataOptions::DecimatedInput::HeldMean;
  o.removeMeans = false;
  o.minimumSamples = 400;
  const PreparedData p = prepareFitData(data, o);
  if (!p.ok()) {
    *why = p.message;
    return std::nullopt;
  }
  NonlinearSeries s;
  s.resetAngle = true;
  s.averageTorque = true;
  s.Ts = p.sampleTime;
  s.startTime = p.startTime;
  s.u.assign(p.u.data(), p.u.data() + p.u.size());
  s.phi.assign(p.y.data(), p.y.data() + p.y.size());
  if (velocity) {  // the angle from the velocity, from zero
    double phi = 0.0, previous = s.phi.empty() ? 0.0 : s.phi[0];
    for (auto& x : s.phi) {
      const double v = x;
      phi += 0.5 * s.Ts * (previous + v);
      previous = v;
      x = phi;
    }
  }
  for (std::size_t k = 0; k < s.u.size(); ++k)
    if (!std::isfinite(s.u[k]) || !std::isfinite(s.phi[k])) {
      *why = "the log holds a non-finite value near sample " + std::to_string(k * static_cast<std::size_t>(o.decimation));
      return std::nullopt;
    }
  s.y = differentiate(s.phi, s.Ts);
  s.initialSpeed = s.y[0];
  return s;
}

std::vector<double> Context::pickVal(const std::vector<double>& full) const {
  if (valLog || full.empty()) return full;
  std::vector<double> out(heldOut.size());
  for (std::size_t i = 0; i < heldOut.size(); ++i) out[i] = full[heldOut[i]];
  return out;
}

std::vector<double> Context::pickEst(const std::vector<double>& full) const {
  if (est.fitSamples.empty() || full.empty()) return full;
  std::vector<double> out(est.fitSamples.size());
  for (std::size_t i = 0; i < est.fitSamples.size(); ++i) out[i] = full[est.fitSamples[i]];
  return out;
}

bool prepareContext(Context& ctx, const IdData& estimation, const IdData* validation, std::string* why) {
  const DiscoveryOptions& o = *ctx.options;
  std::string reason;
  auto est = makeSeries(estimation, o.maxRateHz, &reason);
  if (!est) {
    *why = "estimation data: " + reason;
    return false;
  }
  ctx.est = std::move(*est);
  if (validation) {
    auto val = makeSeries(*validation, o.maxRateHz, &reason);
    if (!val) {
      *why = "validation data: " + reason;
      return false;
    }
    if (std::abs(val->Ts - ctx.est.Ts) > 1e-9 * ctx.est.Ts) {
      *why = "the validation data's sample time differs from the estimation data's";
      return false;
    }
    ctx.valLog = std::move(*val);
    ctx.validationData = "the validation data";
  } else {
    // No validation data: the end of every second of the log is held out (the log stays
    // whole for the simulation), so every verdict is checked on samples its fit did not see
    // and both parts cover the whole experiment (a chirp's every frequency).
    const std::size_t N = ctx.est.y.size();
    const auto block = std::max<std::size_t>(20, static_cast<std::size_t>(std::lround(1.0 / ctx.est.Ts)));
    const auto held = static_cast<std::size_t>(std::lround(o.heldOutFraction * static_cast<double>(block)));
    for (std::size_t k = 0; k < N; ++k) (k % block >= block - held ? ctx.heldOut : ctx.est.fitSamples).push_back(k);
    if (ctx.heldOut.size() < 200 || ctx.est.fitSamples.size() < 400) {
      *why = "estimation data: too short to hold out " + number(100.0 * o.heldOutFraction, 2) +
             " % for the confirmation (" + std::to_string(N) + " samples at the fitting rate)";
      return false;
    }
    ctx.heldOutSplit = true;
    ctx.validationData = "the held-out last " + number(100.0 * o.heldOutFraction, 2) + " % of every second of the log";
  }
  ctx.estY = ctx.pickEst(ctx.est.y);
  ctx.valY = ctx.pickVal(ctx.valSeries().y);
  return true;
}

}  // namespace flexarm::discovery_detail
