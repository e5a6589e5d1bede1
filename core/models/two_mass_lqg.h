#pragma once
// The two-mass arm in the form used for LQG design in chapter 8 of the seed: gear ratio 1
// (arm inertia scaled), states (8.1) x = (phi_m, phi_m', phi_a, phi_a'), input torque u, load
// disturbances w on the motor and v on the arm, (8.2)-(8.6); the two-measurement form with arm
// acceleration (8.40)-(8.42); and the extension by a state x5 representing a constant load
// disturbance on the arm, used for integral action (Section 8.3).
#include <Eigen/Dense>
#include <complex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

// Physical parameters of Figure 8.1; defaults are Table 8.1.
struct TwoMassLqgParameters {
  double Jm = 0.0043;  // motor inertia, kg m^2
  double Ja = 0.0762;  // arm inertia (scaled to the motor side), kg m^2
  double fm = 0.02;    // motor viscous friction, N m s/rad
  double fa = 0.005;   // arm viscous friction, N m s/rad
  double k = 43.0;     // spring stiffness, N m/rad
  double d = 0.05;     // spring damping, N m s/rad

  // Names as in Table 8.1, in a fixed order: J_m, J_a, f_m, f_a, k, d.
  static const std::vector<std::string>& names();
  // Unit of a parameter named in names(); throws std::invalid_argument otherwise.
  static std::string unit(const std::string& name);
  // Value by name; throws std::invalid_argument for an unknown name.
  double get(const std::string& name) const;
  // Sets a value by name; throws std::invalid_argument for an unknown name.
  void set(const std::string& name, double value);

  // True when inertias and stiffness are positive and frictions and damping non-negative
  // and all finite; otherwise says which is not.
  bool isValid(std::string* why = nullptr) const;
};

// Which signals the regulator measures.
enum class LqgMeasurement {
  MotorAngle,                    // y = phi_m, (8.6)
  MotorAngleAndArmAcceleration,  // y = (phi_m, phi_a''), (8.40)-(8.42)
};
const char* toString(LqgMeasurement m);
std::optional<LqgMeasurement> lqgMeasurementFromString(std::string_view s);

// x' = A x + B u + Bw w + Bv v, y = C x + Dv v. Dv is zero for the motor angle; the arm
// acceleration sees the arm disturbance directly (1/J_a), which (8.42) leaves out because it
// writes the measurement of the undisturbed model.
struct TwoMassLqgPlant {
  Eigen::MatrixXd A, B, Bw, Bv, C, Dv;
  int states() const { return static_cast<int>(A.rows()); }
  int measurements() const { return static_cast<int>(C.rows()); }
};

// State space (8.2)-(8.5) with the measurement (8.6) or (8.41)-(8.42). Throws
// std::invalid_argument when the parameters are not valid.
TwoMassLqgPlant twoMassLqgPlant(const TwoMassLqgParameters& p, LqgMeasurement m);

// The model extended with x5, a constant load disturbance acting on the arm (Section 8.3):
// A_bar = [A Bv; 0 0], B_bar = [B; 0], Bw_bar = [Bw; 0], Bv_bar = [Bv; 0], C_bar = [C Dv],
// Dv_bar = Dv. x5 is observable from phi_m but not controllable from u.
TwoMassLqgPlant withArmLoadDisturbanceState(const TwoMassLqgPlant& plant);

// Transfer function G_a(s) from phi_m to phi_a (Figure 8.4): (d s + k)/(J_a s^2 + (d+f_a) s + k).
std::complex<double> armFromMotorResponse(const TwoMassLqgParameters& p, std::complex<double> s);

}  // namespace flexarm
