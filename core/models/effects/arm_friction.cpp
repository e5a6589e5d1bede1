// arm_friction: friction on the arm side of the gear (the output bearing of a large robot's
// axis), -f_a phi_a' - F_a tanh(phi_a'/(r v_s)) on the arm: viscous and Coulomb, both against
// the arm's motion (f_a, F_a >= 0), its smooth sign at the motor's speed v_s through the gear.
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class ArmFrictionTorque : public TorqueTerm {
 public:
  ArmFrictionTorque(double viscous, double coulomb) : viscous_(viscous), coulomb_(coulomb) {}
  double torque(const JointSignals& s) const override {
    double t = -viscous_ * s.armVelocity;
    if (coulomb_ != 0.0) t -= coulomb_ * std::tanh(s.armVelocity / (s.ratio * s.smoothingSpeed));
    return t;
  }

 private:
  double viscous_, coulomb_;
};

class ArmFriction : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"f_a", "N m s/rad", 50.0, "viscous friction on the arm side of the gear", ValueDomain::NonNegative, 0.0,
             1e300, true},
            {"F_a", "N m", 0.0, "Coulomb friction on the arm side: F_a tanh(phi_a'/(r v_s))", ValueDomain::NonNegative,
             0.0, 1e300, false}};
  }
  std::string summary() const override { return "-f_a phi_a' - F_a tanh(phi_a'/(r v_s)) on the arm"; }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    if (e.value(0) != 0.0 || e.value(1) != 0.0)
      t.torques.push_back({TorqueSite::Arm, std::make_shared<ArmFrictionTorque>(e.value(0), e.value(1))});
  }
  std::string signature() const override {
    return "the residual against the arm's speed (the response to a torque -f_a phi_a' on the arm)";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "viscous friction on the arm side of " + effect_text::plusMinus(p[0]) + " N m s/rad";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> armFrictionEffect() { return std::make_unique<ArmFriction>(); }

}  // namespace flexarm
