// coulomb_friction: a friction torque of constant size against the motor's motion,
// -F_c tanh(phi_m'/v_s) on the motor (the seed's Section 3.2 leaves it out: viscous friction
// only). tanh is a smooth sign; v_s is the motor speed below which it rounds off.
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class CoulombTorque : public TorqueTerm {
 public:
  CoulombTorque(double size, double speed) : size_(size), speed_(speed) {}
  double torque(const JointSignals& s) const override { return -size_ * std::tanh(s.motorVelocity / speed_); }

 private:
  double size_, speed_;
};

class CoulombFriction : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"F_c", "N m", 0.05, "Coulomb friction torque on the motor", ValueDomain::NonNegative, 0.0, 1e300, true},
            {"v_s", "rad/s", 0.1, "motor speed of the smooth sign: F_c tanh(phi_m'/v_s)", ValueDomain::Positive, 0.0,
             1e300, false}};
  }
  std::string summary() const override { return "F_c tanh(phi_m'/v_s) against the motor's motion"; }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    t.smoothingSpeed = e.value(1);
    if (e.value(0) != 0.0) t.torques.push_back({TorqueSite::Motor, std::make_shared<CoulombTorque>(e.value(0), e.value(1))});
  }
  std::string signature() const override {
    return "the residual against the sign of the motor velocity (the response to a torque -F_c sign(phi_m'))";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "Coulomb friction of " + effect_text::plusMinus(p[0]) + " N m on the motor side";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> coulombFrictionEffect() { return std::make_unique<CoulombFriction>(); }

}  // namespace flexarm
