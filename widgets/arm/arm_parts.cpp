#include "widgets/arm/arm_parts.h"

namespace flexarm {

const std::vector<ArmPart>& allArmParts() {
  static const std::vector<ArmPart> parts = {
      ArmPart::Motor,     ArmPart::GearInput, ArmPart::GearSpring,     ArmPart::GearOutput,
      ArmPart::ArmSpring, ArmPart::Arm,       ArmPart::ParallelSpring, ArmPart::ParallelMass};
  return parts;
}

const char* toString(ArmPart p) {
  switch (p) {
    case ArmPart::Motor: return "motor";
    case ArmPart::GearInput: return "gear_input";
    case ArmPart::GearSpring: return "gear_spring";
    case ArmPart::GearOutput: return "gear_output";
    case ArmPart::ArmSpring: return "arm_spring";
    case ArmPart::Arm: return "arm";
    case ArmPart::ParallelSpring: return "parallel_spring";
    case ArmPart::ParallelMass: return "parallel_mass";
  }
  return "?";
}

std::optional<ArmPart> armPartFromString(std::string_view s) {
  for (ArmPart p : allArmParts())
    if (s == toString(p)) return p;
  return std::nullopt;
}

std::optional<ArmPart> armPartForParameter(std::string_view structure, std::string_view name) {
  const bool twoMass = structure == "two-mass" || structure == "two-mass-theta";
  if (name == "J_m" || name == "f_m" || name == "k_T") return ArmPart::Motor;
  if (name == "J_a") return ArmPart::Arm;
  if (name == "k_g" || name == "d_g") return ArmPart::GearSpring;
  if (name == "J_g") return ArmPart::GearOutput;
  if (name == "k_a" || name == "d_a") return twoMass ? ArmPart::GearSpring : ArmPart::ArmSpring;
  if (name == "k_p" || name == "d_p") return ArmPart::ParallelSpring;
  if (name == "J_p") return ArmPart::ParallelMass;
  return std::nullopt;
}

}  // namespace flexarm
