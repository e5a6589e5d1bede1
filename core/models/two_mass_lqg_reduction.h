#pragma once
// Reduction of a physical model of Chapter 3 to the two-mass form of Chapter 8 (Figure 8.1,
// (8.1)-(8.6)): gear ratio 1 with the arm side scaled to the motor side, as Section 8.1 says
// ("the gear box ratio r is set to 1, which can be achieved by scaling the arm inertia").
// Arm-side inertias, stiffnesses and dampings are multiplied by r^2; the chapter-8 input u is
// the motor torque k_T u of the physical model; the physical models have no arm friction, so
// f_a = 0.
#include <optional>
#include <string>
#include <string_view>

#include "core/common/progress.h"
#include "core/models/physical_models.h"
#include "core/models/two_mass_lqg.h"

namespace flexarm {

// How a model with more than two masses becomes two masses. A two-mass model ((3.13) or
// (5.5)) is converted exactly whatever the method.
enum class TwoMassReduction {
  // Lumps every mass after the motor into one arm mass (J_a = r^2 sum J) and joins the
  // springs in series: 1/k = sum 1/k_i, damping from the series compliance at low frequency,
  // d = k^2 sum d_i / k_i^2 (clamped at 0). Keeps the total inertia and the static stiffness.
  MergeMasses,
  // Keeps the total inertia J_tot = J_m + r^2 sum J and matches the first antiresonance w_z
  // and resonance w_p of the motor-velocity response (3.14): J_m = J_tot w_z^2 / w_p^2,
  // J_a = J_tot - J_m, k = J_a w_z^2, d = 2 zeta_z sqrt(k J_a) (zeta_z of the first notch).
  MatchFirstMode,
};
const char* toString(TwoMassReduction r);  // "merge-masses", "match-first-mode"
std::optional<TwoMassReduction> twoMassReductionFromString(std::string_view s);

struct TwoMassReductionOptions {
  TwoMassReduction method = TwoMassReduction::MatchFirstMode;
  bool isValid(std::string* why = nullptr) const;
};

struct TwoMassReductionResult {
  Termination termination = Termination::Failed;
  std::string message;  // how the model was reduced, or why it cannot be
  double seconds = 0.0;
  TwoMassLqgParameters parameters;
  bool ok() const { return termination == Termination::Converged; }
};

// The Chapter-8 parameters (Table 8.1 form) of a physical model. A rigid model (no spring),
// a model whose reduction gives non-physical values, or one without a lightly damped first
// mode (MatchFirstMode) is reported in the result.
TwoMassReductionResult reduceToTwoMass(const PhysicalModel& model,
                                       const TwoMassReductionOptions& options = {});

}  // namespace flexarm
