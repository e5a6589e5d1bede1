// backlash: a dead zone of half-width b in the gear spring (arm side): the gear carries no
// torque (and no damping) while |delta| < b, then k (delta -+ b) (the seed's Section 3.2
// assumes no backlash). Symmetric about the spring's relaxed deflection: a gap whose middle
// is off zero is the same gap with a constant load, which the load observer carries.
#include <algorithm>
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class Backlash : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"b", "rad", 2e-4, "half-width of the dead zone in the gear spring (arm side)", ValueDomain::NonNegative,
             0.0, 1e300, true}};
  }
  std::string summary() const override { return "dead zone of half-width b in the gear spring (arm side)"; }
  bool needsGearSpring() const override { return true; }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    t.backlash = e.value(0);
    t.gearLaw = true;
  }
  // A gap wider than the gear travel the data show is a motor that never meets the arm: its
  // loss is flat in b and its interval does not exclude zero.
  std::vector<EffectSearchCoordinate> searchCoordinates(const Effect& e, const EffectSearchBounds& b) const override {
    const double range = std::max({b.gapRange, 3.0 * e.value(0), 1e-3 * parameters()[0].defaultValue});
    EffectSearchCoordinate c;
    c.map = EffectSearchCoordinate::Map::Log;
    c.scale = parameters()[0].defaultValue;
    c.lower = 1e-3 * range;
    c.upper = range;
    return {c};
  }
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    EffectSearchPlan plan;
    plan.starts.push_back(e0);
    plan.profileMain = true;
    return plan;
  }
  // The torque the gap takes out of the linear spring, motor side.
  double addedTorque(const Effect& e, const JointSignals& s) const override {
    const double b = e.value(0), d = s.gearDeflection;
    const double inGap = std::abs(d) < b ? s.gearStiffness * d + s.gearDamping * s.gearRate
                                         : s.gearStiffness * (d > 0.0 ? b : -b);
    return -inGap * s.ratio;
  }
  bool roughLoss() const override { return true; }
  double displayFactor() const override { return 1e3; }
  std::string displayUnit() const override { return "mrad"; }
  std::string signature() const override {
    return "the residual against the gear's dead zone (the response to the gear torque lost inside the gap)";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "backlash in the gear, a dead zone of half-width " + effect_text::plusMinus(p[0], 1e3) + " mrad (arm side)";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> backlashEffect() { return std::make_unique<Backlash>(); }

}  // namespace flexarm
