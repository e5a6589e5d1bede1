// asymmetric_coulomb: Coulomb friction of one size while the motor turns forwards and another
// backwards (EMPS's (12)), -F_c+- tanh(phi_m'/v_s) on the motor, both against the motion
// (>= 0). It holds coulomb_friction as the case F_c+ = F_c-, so discovery names it only when
// the difference F_c+ - F_c- is not zero.
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class AsymmetricTorque : public TorqueTerm {
 public:
  AsymmetricTorque(double plus, double minus) : plus_(plus), minus_(minus) {}
  double torque(const JointSignals& s) const override {
    const double t = std::tanh(s.motorVelocity / s.smoothingSpeed);
    return -(t > 0.0 ? plus_ : minus_) * t;
  }

 private:
  double plus_, minus_;
};

class AsymmetricCoulomb : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"F_c+", "N m", 0.05, "Coulomb friction on the motor while it turns forwards", ValueDomain::NonNegative,
             0.0, 1e300, true},
            {"F_c-", "N m", 0.05, "Coulomb friction on the motor while it turns backwards", ValueDomain::NonNegative,
             0.0, 1e300, true}};
  }
  std::string summary() const override {
    return "Coulomb friction F_c+ tanh(phi_m'/v_s) forwards, F_c- backwards, on the motor";
  }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    if (e.value(0) != 0.0 || e.value(1) != 0.0)
      t.torques.push_back({TorqueSite::Motor, std::make_shared<AsymmetricTorque>(e.value(0), e.value(1))});
  }
  std::vector<EffectSearchCoordinate> searchCoordinates(const Effect&, const EffectSearchBounds&) const override {
    EffectSearchCoordinate plus, minus;
    plus.scale = minus.scale = 0.05;
    minus.index = 1;
    return {plus, minus};
  }
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    EffectSearchPlan plan;
    Effect e = e0;
    e.values = {0.025, 0.025};
    plan.starts.push_back(e);
    return plan;
  }
  std::vector<EffectKind> holds() const override { return {EffectKind::CoulombFriction}; }
  std::string magnitudeName() const override { return "F_c+ - F_c-"; }
  double magnitude(const Effect& e) const override { return e.value(0) - e.value(1); }
  Effect withMagnitude(const Effect& e, double m) const override {
    Effect out = e;
    const double mean = 0.5 * (e.value(0) + e.value(1));
    out.values = {std::max(0.0, mean + 0.5 * m), std::max(0.0, mean - 0.5 * m)};
    return out;
  }
  bool signedMagnitude() const override { return true; }
  std::vector<DerivedQuantity> derivedQuantities(const Effect&) const override {
    return {{"F_c+ - F_c-", "N m", [](const std::vector<double>& v) { return v[0] - v[1]; }}};
  }
  std::string signature() const override {
    return "the residual against the sign of the motor velocity, each direction apart (the response to a torque "
           "-F_c+- sign(phi_m'))";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "Coulomb friction of " + effect_text::plusMinus(p[0]) + " N m forwards and " + effect_text::plusMinus(p[1]) +
           " N m backwards on the motor side";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> asymmetricCoulombEffect() { return std::make_unique<AsymmetricCoulomb>(); }

}  // namespace flexarm
