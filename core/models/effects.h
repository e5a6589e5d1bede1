#pragma once
// Effects the real arm has and the linear models of chapter 3 leave out (the seed's Section
// 3.2 assumptions: viscous friction only, no backlash, linear springs, the torque reference
// is the applied torque), and those of large robots. Each is a named term that can be switched
// on in any model; the names are product API, used unchanged on the command line and in JSON.
//
// Every effect lives in one file of core/models/effects/ (its parameters, plant term, search
// starts, confirmation signature, description and help line: core/models/effect_registry.h);
// the list of them is core/models/effects/effect_list.h. This header is what the rest of
// FlexArm needs to name, parse and print effects.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class EffectKind {
#define FLEXARM_EFFECT(kind, name, factory) kind,
#include "core/models/effects/effect_list.h"
#undef FLEXARM_EFFECT
};
const char* toString(EffectKind k);
std::optional<EffectKind> effectKindFromString(std::string_view s);
// Every effect, in the order of effect_list.h.
const std::vector<EffectKind>& allEffectKinds();
// The six effects of the seed's Section 3.2 assumptions (coulomb_friction ... extra_mass).
const std::vector<EffectKind>& seedEffectKinds();

// What values a parameter can take (physics: a friction is never negative, a phase or a
// sine/cosine coefficient takes either sign, a mass fraction lies in (0, 1)).
enum class ValueDomain { NonNegative, Positive, Signed, Fraction };

struct EffectParameterInfo {
  std::string name;  // e.g. "F_c"
  std::string unit;  // e.g. "N m"
  double defaultValue = 0.0;
  std::string meaning;
  ValueDomain domain = ValueDomain::NonNegative;
  double lower = 0.0, upper = 1e300;  // bounds of a valid value (isValid)
  bool freeInFit = false;  // fitted by `fit --effect` unless --fix/--free say otherwise
};

struct Effect {
  EffectKind kind = EffectKind::CoulombFriction;
  // In the order of effectParameters(*this): an effect with a variable number of terms (the
  // ripple's harmonics) has as many values as its terms need.
  std::vector<double> values;

  // An effect with its default parameters.
  static Effect withDefaults(EffectKind k);
  double value(int i) const { return values[static_cast<std::size_t>(i)]; }
  // True when the values are finite, as many as the effect takes, and physical (e.g.
  // F_c >= 0, 0 < mass fraction < 1).
  bool isValid(std::string* why) const;
};

// The parameters of an effect at its default size, in order: the first is the one
// `NAME:VALUE` sets.
const std::vector<EffectParameterInfo>& effectParameters(EffectKind k);
// The parameters of this effect (an effect with more terms than its default has more).
std::vector<EffectParameterInfo> effectParameters(const Effect& e);

// Parses "NAME", "NAME:V1" or "NAME:V1,V2,..." (unset values keep their defaults; an effect
// with a variable number of terms takes more). On failure returns nullopt and says why.
std::optional<Effect> parseEffect(std::string_view spec, std::string* why);
// "NAME:V1,V2,..." with every value, parseable by parseEffect.
std::string toString(const Effect& e);

// The help lines of every effect as `fit --effect` and `simulate --effect` list them:
// "  NAME:P1,P2   meaning (defaults)", each wrapped at `width` columns after an indent of
// `indent` spaces for the meaning. One function for every help list.
std::string effectHelpLines(int nameColumn = 29, int width = 92);
// The names of every effect, "a, b, c" (for messages).
std::string effectNames();

}  // namespace flexarm
