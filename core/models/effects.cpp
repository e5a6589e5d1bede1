#include "core/models/effects.h"

#include <charconv>
#include <cmath>

namespace flexarm {

namespace {
struct KindName {
  EffectKind kind;
  const char* name;
};
constexpr KindName kKindNames[] = {
    {EffectKind::CoulombFriction, "coulomb_friction"}, {EffectKind::Backlash, "backlash"},
    {EffectKind::NonlinearSpring, "nonlinear_spring"}, {EffectKind::InputDelay, "input_delay"},
    {EffectKind::TorqueRipple, "torque_ripple"},       {EffectKind::ExtraMass, "extra_mass"},
    {EffectKind::ArmFriction, "arm_friction"},         {EffectKind::AsymmetricCoulomb, "asymmetric_coulomb"},
    {EffectKind::Gravity, "gravity"},                  {EffectKind::EncoderSkew, "encoder_skew"},
};

bool parseNumber(std::string_view s, double& out) {
  const auto res = std::from_chars(s.data(), s.data() + s.size(), out);
  return res.ec == std::errc() && res.ptr == s.data() + s.size() && std::isfinite(out);
}
}  // namespace

const char* toString(EffectKind k) {
  for (const auto& kn : kKindNames)
    if (kn.kind == k) return kn.name;
  return "coulomb_friction";
}

std::optional<EffectKind> effectKindFromString(std::string_view s) {
  for (const auto& kn : kKindNames)
    if (s == kn.name) return kn.kind;
  return std::nullopt;
}

const std::vector<EffectKind>& allEffectKinds() {
  static const std::vector<EffectKind> kAll = {
      EffectKind::CoulombFriction, EffectKind::Backlash,     EffectKind::NonlinearSpring,
      EffectKind::InputDelay,      EffectKind::TorqueRipple, EffectKind::ExtraMass,
      EffectKind::ArmFriction,     EffectKind::AsymmetricCoulomb, EffectKind::Gravity,
      EffectKind::EncoderSkew};
  return kAll;
}

const std::vector<EffectKind>& seedEffectKinds() {
  static const std::vector<EffectKind> kSeed(allEffectKinds().begin(), allEffectKinds().begin() + 6);
  return kSeed;
}

const std::vector<EffectParameterInfo>& effectParameters(EffectKind k) {
  static const std::vector<EffectParameterInfo> kCoulomb = {
      {"F_c", "N m", 0.05, "Coulomb friction torque on the motor"},
      {"v_s", "rad/s", 0.1, "motor speed of the smooth sign: F_c tanh(phi_m'/v_s)"}};
  static const std::vector<EffectParameterInfo> kBacklash = {
      {"b", "rad", 2e-4, "half-width of the dead zone in the gear spring (arm side)"}};
  static const std::vector<EffectParameterInfo> kSpring = {
      {"beta", "1/rad^2", 2e6, "stiffening of the gear spring: k delta (1 + beta delta^2)"}};
  static const std::vector<EffectParameterInfo> kDelay = {
      {"T_d", "s", 1e-3, "delay between the torque reference and the applied torque"}};
  static const std::vector<EffectParameterInfo> kRipple = {
      {"A", "N m", 0.05, "amplitude of the ripple torque A sin(n phi_m)"},
      {"n", "1/rev", 6.0, "ripple periods per motor revolution"}};
  static const std::vector<EffectParameterInfo> kMass = {
      {"omega", "rad/s", 250.0, "resonance frequency of the added mass on its spring"},
      {"fraction", "1", 0.3, "part of the outermost mass moved to the added mass"}};
  static const std::vector<EffectParameterInfo> kArm = {
      {"f_a", "N m s/rad", 50.0, "viscous friction on the arm side of the gear"},
      {"F_a", "N m", 0.0, "Coulomb friction on the arm side: F_a tanh(phi_a'/(r v_s))"}};
  static const std::vector<EffectParameterInfo> kAsymmetric = {
      {"F_c+", "N m", 0.05, "Coulomb friction on the motor while it turns forwards"},
      {"F_c-", "N m", 0.05, "Coulomb friction on the motor while it turns backwards"}};
  static const std::vector<EffectParameterInfo> kGravity = {
      {"mgl", "N m", 100.0, "gravity torque amplitude m g l on the arm: mgl sin(phi_a + phi_0)"},
      {"phi_0", "rad", 0.0, "phase of the gravity torque: the arm angle (from the log's zero) plus phi_0 is the angle from the vertical"}};
  static const std::vector<EffectParameterInfo> kSkew = {
      {"T_o", "s", 0.0, "time by which the arm encoder's reading lags the motor encoder's"}};
  switch (k) {
    case EffectKind::ArmFriction: return kArm;
    case EffectKind::AsymmetricCoulomb: return kAsymmetric;
    case EffectKind::Gravity: return kGravity;
    case EffectKind::EncoderSkew: return kSkew;
    case EffectKind::CoulombFriction: return kCoulomb;
    case EffectKind::Backlash: return kBacklash;
    case EffectKind::NonlinearSpring: return kSpring;
    case EffectKind::InputDelay: return kDelay;
    case EffectKind::TorqueRipple: return kRipple;
    case EffectKind::ExtraMass: return kMass;
  }
  return kCoulomb;
}

Effect Effect::withDefaults(EffectKind k) {
  Effect e;
  e.kind = k;
  const auto& params = effectParameters(k);
  for (std::size_t i = 0; i < params.size(); ++i) e.values[i] = params[i].defaultValue;
  return e;
}

bool Effect::isValid(std::string* why) const {
  auto fail = [why](std::string s) {
    if (why) *why = std::move(s);
    return false;
  };
  const auto& params = effectParameters(kind);
  for (std::size_t i = 0; i < params.size(); ++i)
    if (!std::isfinite(values[i]))
      return fail(std::string(toString(kind)) + ": " + params[i].name + " is not finite");
  const std::string name = toString(kind);
  switch (kind) {
    case EffectKind::CoulombFriction:
      if (values[0] < 0.0) return fail(name + ": F_c must be >= 0");
      if (values[1] <= 0.0) return fail(name + ": v_s must be > 0");
      break;
    case EffectKind::Backlash:
      if (values[0] < 0.0) return fail(name + ": b must be >= 0");
      break;
    case EffectKind::NonlinearSpring:
      if (values[0] < 0.0) return fail(name + ": beta must be >= 0 (a stiffening spring)");
      break;
    case EffectKind::InputDelay:
      if (values[0] < 0.0 || values[0] > 1.0) return fail(name + ": T_d must be in [0, 1] s");
      break;
    case EffectKind::TorqueRipple:
      if (values[0] < 0.0) return fail(name + ": A must be >= 0");
      if (values[1] <= 0.0) return fail(name + ": n must be > 0");
      break;
    case EffectKind::ExtraMass:
      if (values[0] <= 0.0) return fail(name + ": omega must be > 0");
      if (!(values[1] > 0.0 && values[1] < 1.0)) return fail(name + ": fraction must be in (0, 1)");
      break;
    case EffectKind::ArmFriction:
      if (values[0] < 0.0 || values[1] < 0.0) return fail(name + ": f_a and F_a must be >= 0");
      break;
    case EffectKind::AsymmetricCoulomb:
      if (values[0] < 0.0 || values[1] < 0.0) return fail(name + ": F_c+ and F_c- must be >= 0");
      break;
    case EffectKind::Gravity:
      if (values[0] < 0.0) return fail(name + ": mgl must be >= 0 (phi_0 turns the direction)");
      break;
    case EffectKind::EncoderSkew:
      if (values[0] < -1.0 || values[0] > 1.0) return fail(name + ": T_o must be in [-1, 1] s");
      break;
  }
  if (why) why->clear();
  return true;
}

std::optional<Effect> parseEffect(std::string_view spec, std::string* why) {
  const auto colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const auto kind = effectKindFromString(name);
  if (!kind) {
    if (why) {
      *why = "unknown effect '" + std::string(name) + "' (expected one of";
      for (EffectKind k : allEffectKinds()) *why += std::string(" ") + toString(k);
      *why += ")";
    }
    return std::nullopt;
  }
  Effect e = Effect::withDefaults(*kind);
  if (colon != std::string_view::npos) {
    std::string_view rest = spec.substr(colon + 1);
    const std::size_t count = effectParameters(*kind).size();
    for (std::size_t i = 0;; ++i) {
      const auto comma = rest.find(',');
      const std::string_view field = rest.substr(0, comma);
      if (i >= count) {
        if (why) *why = std::string(name) + " takes at most " + std::to_string(count) + " values";
        return std::nullopt;
      }
      if (!parseNumber(field, e.values[i])) {
        if (why) *why = std::string(name) + ": '" + std::string(field) + "' is not a number";
        return std::nullopt;
      }
      if (comma == std::string_view::npos) break;
      rest = rest.substr(comma + 1);
    }
  }
  if (!e.isValid(why)) return std::nullopt;
  return e;
}

std::string toString(const Effect& e) {
  std::string s = toString(e.kind);
  const auto& params = effectParameters(e.kind);
  char buf[40];
  for (std::size_t i = 0; i < params.size(); ++i) {
    // Shortest text that reads back to the same double.
    const auto res = std::to_chars(buf, buf + sizeof buf, e.values[i]);
    s += (i == 0 ? ":" : ",");
    s.append(buf, res.ptr);
  }
  return s;
}

}  // namespace flexarm
