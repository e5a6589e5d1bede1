#pragma once
// The registry of effects: one definition per effect, each in its own file of
// core/models/effects/ (listed in core/models/effects/effect_list.h). A definition holds
// everything FlexArm knows about its effect:
//   - its parameters (names, units, bounds, defaults, meanings; effects.h),
//   - its plant term: the torque it adds on the motor, in the gear or on the arm, or what it
//     changes in the plant (the gear spring's law, the input delay, the arm encoder's lag, the
//     structure), read by core/models/nonlinear_plant.cpp,
//   - how discovery searches it (coordinates, starts, values chosen on a grid),
//   - its confirmation signature (what core/discovery/confirmation.cpp regresses on), its size
//     against the model, its null value,
//   - its description and help line.
// The plant, `fit --effect`, `simulate --effect`, discovery and every help list read from it:
// adding an effect is its file, its line in effect_list.h and a test.
#include <cmath>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/models/effects.h"
#include "core/models/physical_models.h"

namespace flexarm {

// The signals of the joint at one instant a term may depend on (motor side: phi_m in rad,
// phi_m' in rad/s; arm side: phi_a, phi_a', the gear deflection delta = r phi_m - phi_g and
// its rate, rad and rad/s).
struct JointSignals {
  double motorAngle = 0.0, motorVelocity = 0.0;
  double armAngle = 0.0, armVelocity = 0.0;
  double gearDeflection = 0.0, gearRate = 0.0;
  double smoothingSpeed = 0.1;  // motor speed (rad/s) of the smooth signs tanh(phi_m'/v_s)
  double ratio = 1.0;           // r
  // For an effect's size against the model (EffectDefinition::addedTorque): the linear gear
  // spring's stiffness and damping, and the motor torque (k_T u, N m) the reference asks for
  // now and the one applied (after an input delay).
  double gearStiffness = 0.0, gearDamping = 0.0;
  double torqueNow = 0.0, torqueApplied = 0.0;
};
// Signals that cost a sum over the state to form; a term says which it reads.
enum JointSignalNeed : unsigned { kNeedsArmAngle = 1u, kNeedsGearState = 2u };

// Where a torque acts: on the motor (motor side, N m, as the motor's own friction does), in
// the gear (added to the gear spring's torque, arm side, acting on both ends as the spring
// does) or on the arm (arm side, where the load acts).
enum class TorqueSite { Motor, Gear, Arm };

// A torque term of the plant: a function of the joint's signals.
class TorqueTerm {
 public:
  virtual ~TorqueTerm() = default;
  virtual double torque(const JointSignals& s) const = 0;
  virtual unsigned needs() const { return 0u; }  // JointSignalNeed bits
};

// What the effects of one plant set up in it (NonlinearPlant reads this once).
struct PlantTerms {
  double inputDelay = 0.0;   // s: the torque reference acts this late
  double encoderSkew = 0.0;  // s: the arm encoder reads this late
  double backlash = 0.0;     // half-width of the gear's dead zone (rad, arm side)
  double stiffening = 0.0;   // beta of k delta (1 + beta delta^2) (1/rad^2)
  bool gearLaw = false;      // the gear spring is not linear (dead zone and/or stiffening)
  double smoothingSpeed = 0.0;  // > 0: an effect sets the smooth signs' speed (coulomb's v_s)
  struct Term {
    TorqueSite site = TorqueSite::Motor;
    std::shared_ptr<const TorqueTerm> term;
  };
  std::vector<Term> torques;
};

// An estimated effect parameter (or a quantity derived from them) with its standard
// deviation and interval at the level of the fit.
struct EffectParameterEstimate {
  std::string name, unit;
  double value = 0.0;
  double std = 0.0;
  double lower = 0.0, upper = 0.0;
  bool estimated = true;  // false: held, or chosen by a grid (e.g. ripple order n)
  bool derived = false;   // a function of the parameters (a ripple harmonic's amplitude)
};

// A quantity an effect is read by that is a function of its values (a harmonic's amplitude
// and phase from its sine and cosine coefficients); its interval follows by the delta method.
struct DerivedQuantity {
  std::string name, unit;
  std::function<double(const std::vector<double>&)> value;
};

// How discovery searches one value of an effect.
struct EffectSearchCoordinate {
  enum class Map { Log, NonNegative, Signed, Fraction };
  int index = 0;
  Map map = Map::NonNegative;
  double scale = 1.0;               // typical size (the search's unit)
  double lower = 0.0, upper = 0.0;  // Log: bounds of the value (0: none)
};

// What the data say about the size of the effects' values (core/discovery/disagreement.cpp).
struct EffectSearchBounds {
  double gapRange = 1e-3;         // the widest backlash gap the data can show (rad, arm side)
  double resonanceRadS = 100.0;   // the current model's highest resonance
  double residualPeakRadS = 0.0;  // the residual's largest spectral line above 5 rad/s
};

// The starts of a candidate's search: a short fit from each, the best refitted in full.
struct EffectSearchPlan {
  std::vector<Effect> starts;
  // The main value is profiled on a logarithmic grid up to its upper bound instead (a loss
  // far from smooth in it: each contact of a gap moves with it).
  bool profileMain = false;
  // The short fits move only this effect's coordinates (its response is linear in them and
  // the rest of the model is already fitted: the ripple's coefficients for each order n).
  bool screenOwnOnly = false;
};

class EffectDefinition {
 public:
  virtual ~EffectDefinition() = default;
  EffectKind kind() const { return kind_; }
  const char* name() const { return name_; }

  // Parameters. parameters(): at the default size; an effect of a variable number of terms
  // gives the list for `count` values and says which counts it takes.
  virtual std::vector<EffectParameterInfo> parameters() const = 0;
  virtual std::vector<EffectParameterInfo> parameters(std::size_t count) const;
  virtual bool takesCount(std::size_t count) const;
  // The effect with one more term (nullopt: it has a fixed number of values).
  virtual std::optional<Effect> withOneMoreTerm(const Effect&) const { return std::nullopt; }
  // A physical check beyond each value's domain and bounds ("" when fine).
  virtual std::string check(const Effect&) const { return ""; }
  // One line for the help lists: what the term is ("F_c tanh(phi_m'/v_s) on the motor").
  virtual std::string summary() const = 0;

  // Plant. A gear effect needs a model with a gear spring; an arm-encoder effect is seen only
  // in a log with an arm encoder; a structural one changes the model (nullptr otherwise, or
  // with a sentence when the model cannot take it).
  virtual bool needsGearSpring() const { return false; }
  virtual bool needsArmEncoder() const { return false; }
  virtual bool structural() const { return false; }
  virtual std::unique_ptr<PhysicalModel> structure(const PhysicalModel&, const Effect&, std::string* why) const;
  virtual void addToPlant(const Effect& e, PlantTerms& terms) const = 0;

  // Discovery.
  virtual bool discoveryCandidate() const { return true; }
  // Effects this one holds as a special case (asymmetric_coulomb holds coulomb_friction):
  // never in one model together; the pair's fit is this one's.
  virtual std::vector<EffectKind> holds() const { return {}; }
  virtual std::vector<EffectSearchCoordinate> searchCoordinates(const Effect& e, const EffectSearchBounds& b) const;
  virtual int gridValues(const Effect&) const { return 0; }  // values chosen on a grid (parameters)
  virtual EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds& b) const;
  // A value the response moves with in small jumps at the integration grid (a dead zone, a
  // delay): searched with a step of about 1 % of its size, its interval promising too much.
  virtual bool roughLoss() const { return false; }
  // The effect's size: its main value, or a function of its values; 0 is its null value (no
  // effect). The interval of this size must exclude 0 for the effect to be named.
  virtual int mainParameter() const { return 0; }
  virtual std::string magnitudeName() const;
  virtual double magnitude(const Effect& e) const { return e.value(mainParameter()); }
  // The effect scaled to size m (its shape kept).
  virtual Effect withMagnitude(const Effect& e, double m) const;
  // A size that takes either sign (a skew, a difference): its interval excludes 0 on either
  // side; else it must lie above 0.
  virtual bool signedMagnitude() const { return false; }
  virtual std::vector<DerivedQuantity> derivedQuantities(const Effect&) const { return {}; }
  // The torque the effect adds at one instant, motor side (N m; an arm-side torque T counts as
  // r T at the motor, phi_a = r phi_m): its size against the model's own friction and spring torques. NaN for an
  // effect that is no torque (a structure, an encoder's lag). By default the sum of its plant
  // terms.
  virtual double addedTorque(const Effect& e, const JointSignals& s) const;
  // How the size is printed: factor and unit (mrad, ms, %).
  virtual double displayFactor() const { return 1.0; }
  virtual std::string displayUnit() const;
  // The confirmation's specific test, in words: what its signature is.
  virtual std::string signature() const = 0;
  // The effect in words with its estimates (effectParameters order, then the derived ones).
  virtual std::string describe(const std::vector<EffectParameterEstimate>& p) const = 0;

 private:
  friend const EffectDefinition& effectDefinition(EffectKind);
  EffectKind kind_ = EffectKind::CoulombFriction;
  const char* name_ = "";
};

const EffectDefinition& effectDefinition(EffectKind k);
inline const EffectDefinition& effectDefinition(const Effect& e) { return effectDefinition(e.kind); }

// Helpers the definitions share.
// Starts with value `index` at each factor times its default (a response far from linear in
// it: a few starts over a decade).
EffectSearchPlan startsOverADecade(const Effect& e0, int index, std::initializer_list<double> factors = {0.2, 0.5, 1.2});
namespace effect_text {
std::string number(double v, int digits = 3);
std::string plusMinus(const EffectParameterEstimate& p, double factor = 1.0);
}  // namespace effect_text

// The definitions, one per file of core/models/effects/ (effect_list.h names them).
#define FLEXARM_EFFECT(kind, name, factory) std::unique_ptr<EffectDefinition> factory();
#include "core/models/effects/effect_list.h"
#undef FLEXARM_EFFECT

}  // namespace flexarm
