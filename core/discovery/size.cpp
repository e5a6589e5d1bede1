// An effect's size against the model it joins (issue: effects of no size were named): the
// torque it adds at each sample of the estimation log, as its definition says
// (EffectDefinition::addedTorque, motor side), beside the model's own viscous motor friction
// f_m phi_m' and gear spring torque (motor side), all RMS over the log as the predictor
// simulates it.
#include <cmath>

#include "core/discovery/discovery_internal.h"
#include "core/models/nonlinear_plant.h"

namespace flexarm::discovery_detail {

EffectSize effectSize(const Context& ctx, const ModelFit& fit, std::size_t index) {
  EffectSize z;
  if (!fit.ok() || index >= fit.effects.size()) return z;
  const Effect& e = fit.effects[index];
  const EffectDefinition& d = effectDefinition(e);
  if (d.structural()) return z;
  try {
    const NonlinearPlant plant(*fit.model, fit.effects);
    const double r = fit.model->value("r");
    double added = 0.0, friction = 0.0, spring = 0.0;
    std::size_t n = 0;
    bool torque = true;
    const PredictorVisitor visit = [&](std::size_t, const NonlinearPlant::State& x, double now, double applied) {
      const double t = d.addedTorque(e, plant.jointSignals(x, now, applied));
      if (!std::isfinite(t)) {
        torque = false;
        return;
      }
      const double fm = plant.motorFriction(x), sp = plant.gearTorque(x) * r;
      added += t * t;
      friction += fm * fm;
      spring += sp * sp;
      ++n;
    };
    std::vector<double> y;
    if (!predictOutput(plant, ctx.est, ctx.substeps, ctx.observer, PredictedOutput::DifferentiatedAngle, y, nullptr,
                       nullptr, &visit) ||
        !torque || n == 0)
      return z;
    z.torqueRms = std::sqrt(added / static_cast<double>(n));
    z.frictionRms = std::sqrt(friction / static_cast<double>(n));
    z.springRms = std::sqrt(spring / static_cast<double>(n));
  } catch (const std::invalid_argument&) {
  }
  return z;
}

std::string sizeText(const EffectSize& s) {
  if (!s.measured()) return "";
  return "it adds " + number(s.torqueRms) + " N m RMS on the motor side, " + number(100.0 * s.share(), 2) +
         " % of the model's friction (" + number(s.frictionRms) + " N m) and gear spring (" + number(s.springRms) +
         " N m) torques";
}

}  // namespace flexarm::discovery_detail
