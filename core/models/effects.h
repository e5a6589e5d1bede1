#pragma once
// Effects the real arm has and the linear models of chapter 3 leave out (the seed's Section
// 3.2 assumptions: viscous friction only, no backlash, linear springs, the torque reference
// is the applied torque). Each is a named term that can be switched on in any model; the
// names are product API, used unchanged on the command line and in JSON.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class EffectKind {
  CoulombFriction,  // "coulomb_friction": -F_c tanh(phi_m'/v_s) on the motor
  Backlash,         // "backlash": dead zone of half-width b in the gear spring (arm side, rad)
  NonlinearSpring,  // "nonlinear_spring": gear spring k delta (1 + beta delta^2)
  InputDelay,       // "input_delay": the torque acts T_d seconds late
  TorqueRipple,     // "torque_ripple": A sin(n phi_m) on the motor, n periods per revolution
  ExtraMass,        // "extra_mass": one more mass (rigid -> two-mass -> ... -> four-mass)
  // Effects of large robots, on the arm side of the gear and between the encoders:
  ArmFriction,        // "arm_friction": -f_a phi_a' - F_a tanh(phi_a'/(r v_s)) on the arm
  AsymmetricCoulomb,  // "asymmetric_coulomb": Coulomb friction F_c+ moving forwards, F_c-
                      // backwards, on the motor (EMPS's (12))
  Gravity,            // "gravity": -m g l sin(phi_a + phi_0) on the arm (an axis that is not
                      // vertical)
  EncoderSkew,        // "encoder_skew": the arm encoder reads T_o seconds after the motor's
};
const char* toString(EffectKind k);
std::optional<EffectKind> effectKindFromString(std::string_view s);
const std::vector<EffectKind>& allEffectKinds();
// The six effects of the seed's Section 3.2 assumptions (coulomb_friction ... extra_mass),
// the ones discovery looks for.
const std::vector<EffectKind>& seedEffectKinds();

struct EffectParameterInfo {
  std::string name;  // e.g. "F_c"
  std::string unit;  // e.g. "N m"
  double defaultValue = 0.0;
  std::string meaning;
};
// The parameters of an effect in order: the first is the one `NAME:VALUE` sets.
const std::vector<EffectParameterInfo>& effectParameters(EffectKind k);

struct Effect {
  EffectKind kind = EffectKind::CoulombFriction;
  std::array<double, 2> values{};  // in the order of effectParameters(kind); unused are 0

  // An effect with its default parameters.
  static Effect withDefaults(EffectKind k);
  double value(int i) const { return values[static_cast<std::size_t>(i)]; }
  // True when the values are finite and physical (e.g. F_c >= 0, 0 < mass fraction < 1).
  bool isValid(std::string* why) const;
};

// Parses "NAME", "NAME:V1" or "NAME:V1,V2" (unset values keep their defaults). On failure
// returns nullopt and says why.
std::optional<Effect> parseEffect(std::string_view spec, std::string* why);
// "NAME:V1,V2" with every value, parseable by parseEffect.
std::string toString(const Effect& e);

}  // namespace flexarm
