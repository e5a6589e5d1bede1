#pragma once
// The physical models of one robot axis from the seed's chapter 3: rigid (3.10), two-mass
// (3.13), three-mass (3.21) and four-mass with the extra parallel mass (3.22), plus the
// alternative parameterization (5.5) of the two-mass model. Input: motor torque reference u,
// applied as k_T u (k_T is the static gain of chapters 6-7). Output: motor velocity, or the
// motor angle (one more state), optionally with the arm acceleration as a second output.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/models/parametric_model.h"

namespace flexarm {

// What the first output of a physical model is.
enum class ModelOutput { MotorVelocity, MotorAngle };
const char* toString(ModelOutput o);  // "motor-velocity", "motor-angle"
std::optional<ModelOutput> modelOutputFromString(std::string_view s);

struct ModelOptions {
  ModelOutput output = ModelOutput::MotorVelocity;  // MotorAngle appends the state phi_m
  bool armAcceleration = false;  // adds the arm acceleration as a second output row
  bool isValid(std::string* why) const;
};

// Where the physics sits in the state vector; the nonlinear effects and the simulator use it.
struct ModelTopology {
  int coreStates = 0;           // states in the seed's coordinates (no motor-angle state)
  int motorVelocityState = 0;   // index of phi_m' in the core states
  int armVelocityState = -1;    // index of phi_a' (-1 for the rigid model: phi_a' = r phi_m')
  int gearDeflectionState = -1; // index of r phi_m - phi_g (or r phi_m - phi_a); -1 if rigid
  std::string motorInertia = "J_m";
  std::string armInertia = "J_a";
  std::string gearStiffness;    // "k_a" (two-mass) or "k_g"; empty for rigid
  std::string gearDamping;      // "d_a" (two-mass) or "d_g"; empty for rigid
};

// A physical model: named parameters with units, bounds and free/fixed flags; matrices in the
// seed's state coordinates; exact analytic derivatives for every parameter (forward-mode
// differentiation of the closed-form matrix entries).
class PhysicalModel : public ParametricModel {
 public:
  const std::vector<ParameterInfo>& parameters() const override { return params_; }
  // Throws std::invalid_argument for an unknown name, a non-finite value or one outside the
  // parameter's bounds.
  void setParameter(const std::string& name, double value) override;
  void setFree(const std::string& name, bool isFree) override;
  // Sets the bounds a fit searches within (lower <= upper, not NaN); the value is left as it
  // is. Throws std::invalid_argument for an unknown name or bounds that are no interval.
  void setBounds(const std::string& name, double lower, double upper);
  StateSpace stateSpace() const override;
  StateSpaceDerivative derivative(int index) const override;

  // Value of a parameter by name; throws std::invalid_argument for an unknown name.
  double value(const std::string& name) const;
  const ModelOptions& options() const { return options_; }
  void setOptions(const ModelOptions& o);
  ModelTopology topology() const;
  // One line for the GUI and --help, naming the seed's equation.
  virtual std::string description() const = 0;
  // Names of the states and outputs in order, e.g. "r*phi_m - phi_a", "phi_m'".
  std::vector<std::string> stateNames() const;
  std::vector<std::string> outputNames() const;
  // The row over the core states that gives the whole deflection between motor and arm,
  // r phi_m - phi_a (arm side, rad): the gear spring's deflection plus, for the three- and
  // four-mass models, the arm spring's (phi_g - phi_a); zero for the rigid model. What an
  // arm-side encoder sees against the motor encoder through the gear.
  Eigen::RowVectorXd armDeflectionRow() const;

  // Implementation hooks: matrices A (n x n) and B (n x 1) of the core states, row-major, for
  // double and for dual numbers (value + derivative along one parameter).
  struct Dual {
    double v = 0.0, d = 0.0;
  };
  virtual void core(const std::vector<double>& p, std::vector<double>& A,
                    std::vector<double>& B) const = 0;
  virtual void core(const std::vector<Dual>& p, std::vector<Dual>& A,
                    std::vector<Dual>& B) const = 0;

 protected:
  PhysicalModel(std::vector<ParameterInfo> params, ModelTopology topology,
                std::vector<std::string> coreStateNames, ModelOptions options);
  template <class T>
  void assemble(const std::vector<T>& p, std::vector<T>& A, std::vector<T>& B,
                std::vector<T>& C, std::vector<T>& D, int& n, int& ny) const;

 private:
  std::vector<ParameterInfo> params_;
  ModelTopology topology_;
  std::vector<std::string> coreStateNames_;
  ModelOptions options_;
};

// Structure names accepted by makeModel, in the order a combo box lists them.
const std::vector<std::string>& modelStructureNames();
// A model with IRB-1400-like defaults: "rigid" (3.10), "two-mass" (3.13, Table 5.2),
// "three-mass" (3.21, Table 5.7 p6), "four-mass" (3.22, p6 plus a parallel mass),
// "two-mass-theta" (5.5, Table 5.2 converted). Throws std::invalid_argument for other names.
std::unique_ptr<PhysicalModel> makeModel(const std::string& structure,
                                         const ModelOptions& options = {});

// Converts the (5.5) parameters theta_1..theta_5 to J_m, J_a, f_m, k, d and back (r given).
struct TwoMassPhysical {
  double J_m = 0, J_a = 0, f_m = 0, k = 0, d = 0;
};
TwoMassPhysical twoMassFromTheta(const double theta[5], double r);
void thetaFromTwoMass(const TwoMassPhysical& p, double r, double theta[5]);

// The structure with one more mass (rigid -> two-mass -> three-mass -> four-mass), used by
// the extra_mass effect: the outermost mass is split, a fraction massFraction of it is hung on
// a new spring whose resonance is frequencyRadS (k = J omega^2) with damping ratio zeta.
// Returns nullptr for the four-mass model (there is no larger structure).
std::unique_ptr<PhysicalModel> addMass(const PhysicalModel& model, double massFraction,
                                       double frequencyRadS, double zeta = 0.02);

}  // namespace flexarm
