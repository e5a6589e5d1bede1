#pragma once
// The parts of the drawn arm that can be named and highlighted (e.g. by a diagnosis that
// isolated a fault), and which part a physical model's parameter belongs to. No Qt, no VTK.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class ArmPart {
  Motor,           // J_m, f_m, k_T: the motor with its rotor
  GearInput,       // the gearbox input, turning by r phi_m
  GearSpring,      // k_g, d_g (two-mass: k_a, d_a): the gearbox's flexibility
  GearOutput,      // J_g: the mass after the gearbox (three- and four-mass)
  ArmSpring,       // k_a, d_a of the three- and four-mass models
  Arm,             // J_a: the arm
  ParallelSpring,  // k_p, d_p (four-mass)
  ParallelMass,    // J_p (four-mass)
};
const std::vector<ArmPart>& allArmParts();
const char* toString(ArmPart p);  // "motor", "gear_input", "gear_spring", ...
std::optional<ArmPart> armPartFromString(std::string_view s);

// The part that parameter `name` of a model of `structure` ("rigid", "two-mass", ...,
// as makeModel names them) describes; nullopt for r and for unknown names. k_T, the motor's
// torque constant, and f_m belong to the motor; in the two-mass model k_a and d_a are the
// gear spring (its only spring).
std::optional<ArmPart> armPartForParameter(std::string_view structure, std::string_view name);

}  // namespace flexarm
