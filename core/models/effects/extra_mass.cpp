// extra_mass: one more mass on a spring at the arm's end (rigid -> two-mass -> three-mass ->
// four-mass; addMass, core/models/physical_models.h): the part `fraction` of the outermost
// inertia moved to a new mass resonating at omega on its own spring.
#include <algorithm>
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

class ExtraMass : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override {
    return {{"omega", "rad/s", 250.0, "resonance frequency of the added mass on its spring", ValueDomain::Positive, 0.0,
             1e300, true},
            {"fraction", "1", 0.3, "part of the outermost mass moved to the added mass", ValueDomain::Fraction, 0.0,
             1.0, true}};
  }
  std::string summary() const override {
    return "one more mass: the fraction of the outer mass on a spring resonating at omega";
  }
  bool structural() const override { return true; }
  std::unique_ptr<PhysicalModel> structure(const PhysicalModel& m, const Effect& e, std::string* why) const override {
    auto bigger = addMass(m, e.value(1), e.value(0));
    if (!bigger && why) *why = "extra_mass: the " + m.structureName() + " model is the largest structure";
    return bigger;
  }
  void addToPlant(const Effect&, PlantTerms&) const override {}
  // The new mode lies within a band around the model's resonance that the data inform (0.25
  // to 6 times it): far below it a mass on a very soft spring would stand for a motor running
  // free of the arm, which is not a mass the arm has.
  std::vector<EffectSearchCoordinate> searchCoordinates(const Effect& e, const EffectSearchBounds& b) const override {
    EffectSearchCoordinate w;
    w.index = 0;
    w.map = EffectSearchCoordinate::Map::Log;
    w.scale = parameters()[0].defaultValue;
    const double r = std::max(b.resonanceRadS, 1e-3);
    w.lower = std::min(0.25 * r, 0.5 * e.value(0));
    w.upper = std::max(6.0 * r, 2.0 * e.value(0));
    EffectSearchCoordinate f;
    f.index = 1;
    f.map = EffectSearchCoordinate::Map::Fraction;
    f.scale = parameters()[1].defaultValue;
    return {w, f};
  }
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds& b) const override {
    EffectSearchPlan plan;
    const double w0 = b.resonanceRadS;
    std::vector<double> omegas = {0.5 * w0, 0.8 * w0, 1.3 * w0, 2.0 * w0};
    if (b.residualPeakRadS > 1.2 * w0) omegas.push_back(b.residualPeakRadS);
    for (double om : omegas) {
      Effect e = e0;
      e.values = {om, 0.25};
      plan.starts.push_back(e);
    }
    return plan;
  }
  int mainParameter() const override { return 1; }
  double displayFactor() const override { return 100.0; }
  std::string displayUnit() const override { return "%"; }
  std::string signature() const override {
    return "the residual against the resonance shift of an added mass at omega";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    return "an extra mass: " + effect_text::plusMinus(p[1], 100.0) +
           " % of the outermost inertia on a spring resonating at " + effect_text::number(p[0].value) + " +- " +
           effect_text::number(p[0].std, 2) + " rad/s";
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> extraMassEffect() { return std::make_unique<ExtraMass>(); }

}  // namespace flexarm
