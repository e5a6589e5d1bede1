// gravity: the weight of an arm whose axis is not vertical, -m g l sin(phi_a + phi_0) on the
// arm: mgl >= 0 its size, phi_0 (either sign) the arm angle's offset from the vertical (the
// log's zero is the encoder's, not the plumb line's). It acts on the absolute arm angle.
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class GravityTorque : public TorqueTerm {
 public:
  GravityTorque(double size, double phase) : size_(size), phase_(phase) {}
  double torque(const JointSignals& s) const override { return -size_ * std::sin(s.armAngle + phase_); }
  unsigned needs() const override { return kNeedsArmAngle; }

 private:
  double size_, phase_;
};

class Gravity : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"mgl", "N m", 100.0, "gravity torque amplitude m g l on the arm: mgl sin(phi_a + phi_0)",
             ValueDomain::NonNegative, 0.0, 1e300, true},
            {"phi_0", "rad", 0.0,
             "phase of the gravity torque: the arm angle (from the log's zero) plus phi_0 is the angle from the "
             "vertical",
             ValueDomain::Signed, -1e300, 1e300, false}};
  }
  std::string summary() const override { return "-mgl sin(phi_a + phi_0) on the arm"; }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    if (e.value(0) != 0.0) t.torques.push_back({TorqueSite::Arm, std::make_shared<GravityTorque>(e.value(0), e.value(1))});
  }
  std::vector<EffectSearchCoordinate> searchCoordinates(const Effect&, const EffectSearchBounds&) const override {
    EffectSearchCoordinate size, phase;
    size.scale = 100.0;
    phase.index = 1;
    phase.map = EffectSearchCoordinate::Map::Signed;
    phase.scale = 1.0;
    return {size, phase};
  }
  // The phase on a grid of four quarters (the loss is periodic in it).
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    EffectSearchPlan plan;
    for (double phase : {0.0, 0.5 * M_PI, M_PI, -0.5 * M_PI}) {
      Effect e = e0;
      e.values = {20.0, phase};
      plan.starts.push_back(e);
    }
    return plan;
  }
  std::string signature() const override {
    return "the residual against sin and cos of the arm angle (the response to -mgl sin(phi_a + phi_0))";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "gravity on the arm, mgl = " + effect_text::plusMinus(p[0]) + " N m at phi_0 = " +
           effect_text::plusMinus(p[1]) + " rad";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> gravityEffect() { return std::make_unique<Gravity>(); }

}  // namespace flexarm
