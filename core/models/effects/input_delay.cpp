// input_delay: the torque reference acts T_d seconds late (the seed's Section 3.2 takes the
// reference for the applied torque). T_d >= 0: a drive cannot act before it is told to.
#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class InputDelay : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"T_d", "s", 1e-3, "delay between the torque reference and the applied torque", ValueDomain::NonNegative,
             0.0, 1.0, true}};
  }
  std::string summary() const override { return "the torque acts T_d seconds late"; }
  void addToPlant(const Effect& e, PlantTerms& t) const override { t.inputDelay = e.value(0); }
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    return startsOverADecade(e0, 0);
  }
  double addedTorque(const Effect&, const JointSignals& s) const override { return s.torqueApplied - s.torqueNow; }
  bool roughLoss() const override { return true; }
  double displayFactor() const override { return 1e3; }
  std::string displayUnit() const override { return "ms"; }
  std::string signature() const override {
    return "the residual against the phase lag of a delay (the response to u(t - T_d) - u(t))";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "an input delay of " + effect_text::plusMinus(p[0], 1e3) +
           " ms between the torque reference and the applied torque";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> inputDelayEffect() { return std::make_unique<InputDelay>(); }

}  // namespace flexarm
