// encoder_skew: the arm encoder's reading lags the motor encoder's by T_o seconds (either
// sign: which of the two drives samples first), so the measured deflection r phi_m - phi_a
// holds T_o phi_a' besides the gear's own. Seen only in a log with an arm encoder.
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class EncoderSkew : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"T_o", "s", 0.0, "time by which the arm encoder's reading lags the motor encoder's", ValueDomain::Signed,
             -1.0, 1.0, true}};
  }
  std::string summary() const override { return "the arm encoder reads T_o s late (with --outputs motor,arm)"; }
  bool needsArmEncoder() const override { return true; }
  void addToPlant(const Effect& e, PlantTerms& t) const override { t.encoderSkew = e.value(0); }
  std::vector<EffectSearchCoordinate> searchCoordinates(const Effect&, const EffectSearchBounds&) const override {
    EffectSearchCoordinate c;
    c.map = EffectSearchCoordinate::Map::Signed;
    c.scale = 1e-3;
    return {c};
  }
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    EffectSearchPlan plan;
    for (double t : {1e-3, -1e-3}) {
      Effect e = e0;
      e.values = {t};
      plan.starts.push_back(e);
    }
    return plan;
  }
  bool signedMagnitude() const override { return true; }
  double addedTorque(const Effect&, const JointSignals&) const override { return NAN; }
  double displayFactor() const override { return 1e3; }
  std::string displayUnit() const override { return "ms"; }
  std::string signature() const override {
    return "the deflection residual against the arm's speed (the response to T_o phi_a' in the arm encoder's reading)";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "a skew between the encoders: the arm encoder reads " + effect_text::plusMinus(p[0], 1e3) +
           " ms after the motor's";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> encoderSkewEffect() { return std::make_unique<EncoderSkew>(); }

}  // namespace flexarm
