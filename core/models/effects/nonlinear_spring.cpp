// nonlinear_spring: a gear spring that stiffens with its deflection, k delta (1 + beta
// delta^2) (the seed's Section 3.2 assumes a linear spring). beta >= 0: a gear's contact
// stiffens as it loads; a softening cubic spring loses its restoring torque at large
// deflections (the gear would turn through), which no gear does.
#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class NonlinearSpring : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"beta", "1/rad^2", 2e6, "stiffening of the gear spring: k delta (1 + beta delta^2)",
             ValueDomain::NonNegative, 0.0, 1e300, true}};
  }
  std::string summary() const override { return "gear spring k delta (1 + beta delta^2)"; }
  bool needsGearSpring() const override { return true; }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    t.stiffening = e.value(0);
    t.gearLaw = true;
  }
  // k beta delta^3, motor side.
  double addedTorque(const Effect& e, const JointSignals& s) const override {
    const double d = s.gearDeflection;
    return s.gearStiffness * e.value(0) * d * d * d * s.ratio;
  }
  // A response far from linear in beta: a few starts over a decade.
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    return startsOverADecade(e0, 0);
  }
  std::string signature() const override {
    return "the residual against the cubic gear torque (the response to k beta delta^3)";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "a stiffening gear spring, k delta (1 + beta delta^2) with beta = " + effect_text::plusMinus(p[0]) +
           " 1/rad^2";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> nonlinearSpringEffect() { return std::make_unique<NonlinearSpring>(); }

}  // namespace flexarm
