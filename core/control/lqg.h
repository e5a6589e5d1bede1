#pragma once
// LQG design of chapter 8: the LQR gain minimizing (8.17), the Kalman filter gain of (8.16),
// the observer-based regulator (8.15)-(8.16) and its transfer functions F_r (8.19),
// F_y (8.20), G_C (8.21), S (8.22), for the two-mass arm with integral action by the arm-load
// state x5 (Section 8.3) and optionally the arm-acceleration measurement (8.40)-(8.42).
#include <Eigen/Dense>
#include <complex>
#include <string>

#include "core/common/progress.h"
#include "core/common/state_space.h"
#include "core/control/riccati.h"
#include "core/models/two_mass_lqg.h"

namespace flexarm {

// A feedback or filter gain from a Riccati equation: the LQR gain L of (8.17) or the Kalman
// gain K of (8.16).
struct GainResult {
  Termination termination = Termination::Failed;
  std::string message;
  Eigen::MatrixXd gain;    // L (inputs x states) or K (states x measurements)
  Eigen::MatrixXd X;       // Riccati solution (the error covariance P for the filter)
  double residual = 0.0;   // relative Riccati residual
  Eigen::VectorXcd poles;  // eigenvalues of A - B L, or of A - K C
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
};

// LQR gain of (8.17): L = Q2^-1 B' X with A'X + XA - X B Q2^-1 B' X + Q1 = 0. Throws
// std::invalid_argument for inconsistent sizes, weights that are not symmetric, or Q2 not
// positive definite.
GainResult lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q1,
               const Eigen::MatrixXd& Q2, const CareOptions& options = {});

// Stationary Kalman gain of (8.16) for x' = Ax + Bu + (noise of covariance R1),
// y = Cx + (noise of covariance R2): K = P C' R2^-1 with AP + PA' - P C' R2^-1 C P + R1 = 0
// (the dual of lqr). Throws std::invalid_argument as lqr does.
GainResult kalman(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& R1,
                  const Eigen::MatrixXd& R2, const CareOptions& options = {});

// Design variables of Section 8.3. Weights are diagonals over the states of the design model
// (five with integral action, four without) and the measurements.
struct LqgOptions {
  TwoMassLqgParameters parameters;  // Table 8.1 by default
  LqgMeasurement measurement = LqgMeasurement::MotorAngle;
  bool integralAction = true;  // extend with x5, a constant load on the arm
  Eigen::VectorXd q1 = (Eigen::VectorXd(5) << 100, 1, 0, 0, 0).finished();
  double q2 = 1.0;
  Eigen::VectorXd r1 = (Eigen::VectorXd(5) << 0, 0, 0, 0, 1).finished();
  Eigen::VectorXd r2 = Eigen::VectorXd::Constant(1, 1e-6);
  CareOptions care;

  // The seed's designs: case (i) R2 = 1e-6 (stable regulator), case (ii) R2 = 1e-8
  // (unstable regulator), and Section 8.7 with acceleration feedback, R2 = diag(1e-8, 1e-1).
  static LqgOptions seedCaseI();
  static LqgOptions seedCaseII();
  static LqgOptions seedAccelerationFeedback();

  int designStates() const { return integralAction ? 5 : 4; }
  int measurements() const { return measurement == LqgMeasurement::MotorAngle ? 1 : 2; }
  bool isValid(std::string* why = nullptr) const;
};

// The regulator (8.15)-(8.16) with l_0 = 1 and everything needed to analyse it.
struct LqgDesign {
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;

  TwoMassLqgPlant plant;  // the arm (8.2)-(8.6) or (8.39)-(8.42)
  TwoMassLqgPlant model;  // the design model: plant, or plant extended with x5 (A_bar, ...)
  Eigen::RowVectorXd L;   // (8.15) state feedback on the model states (L_bar with x5)
  Eigen::MatrixXd K;      // (8.16) Kalman gain, model states x measurements
  double lqrResidual = 0.0, kalmanResidual = 0.0;

  Eigen::VectorXcd plantPoles;       // eig(A) of the arm (8.4)
  Eigen::VectorXcd statePoles;       // eig(A - B L) of the controllable part
  Eigen::VectorXcd observerPoles;    // eig(A_bar - K C_bar)
  Eigen::VectorXcd regulatorPoles;   // poles of F_y: eig(A_bar - B_bar L - K C_bar)
  Eigen::VectorXcd closedLoopPoles;  // arm and estimator together
  int rhpRegulatorPoles = 0;         // regulator poles with positive real part
  int rhpClosedLoopPoles = 0;

  bool ok() const { return termination == Termination::Converged; }
  // "the regulator is stable" or "the regulator is unstable: 2 poles in the RHP".
  std::string regulatorStability() const;
};

// Designs the LQG regulator. The LQR gain with x5: x5 is observable but not controllable,
// so the extended Riccati equation has no stabilizing solution. Its (1,1) block is the
// Riccati equation of the four-state arm, giving L; its (1,2) block is linear,
// (A - B L)' X12 = -X Bv, and gives the feed-forward gain on the estimated load,
// L5 = Q2^-1 B' X12 (the stationary optimal disturbance feed-forward; it leaves no steady
// motor-angle error for a constant arm load). The fifth entry of Q1 only weights the
// uncontrollable x5 and changes neither gain. Data-dependent failures (a Riccati equation
// without stabilizing solution) are reported in the result; throws std::invalid_argument
// when options are not valid.
LqgDesign designLqg(const LqgOptions& options);

// Numbers of eigenvalues with real part above tol * max(1, spectral radius), i.e. in the open
// right half plane; eigenvalues within the tolerance of the axis are not counted.
int countRightHalfPlane(const Eigen::VectorXcd& poles, double relativeTolerance = 1e-9);
// Sum of the real parts of the eigenvalues that countRightHalfPlane counts.
double rightHalfPlaneRealSum(const Eigen::VectorXcd& poles, double relativeTolerance = 1e-9);

// Transfer functions of a design (all continuous-time state space).
StateSpace plantTransfer(const LqgDesign& d);    // G: u -> y, C (sI - A)^-1 B
StateSpace regulatorFy(const LqgDesign& d);      // (8.20) L (sI - A + BL + KC)^-1 K
StateSpace regulatorFr(const LqgDesign& d);      // (8.19) 1 - L (sI - A + BL + KC)^-1 B
StateSpace closedLoopGc(const LqgDesign& d);     // (8.21) C (sI - A + BL)^-1 B
StateSpace stateFeedbackG0(const LqgDesign& d);  // (8.35) L (sI - A)^-1 B
// The closed loop with inputs (w, v) and outputs (phi_a, phi_m, u), states (x, x_hat).
StateSpace disturbanceClosedLoop(const LqgDesign& d);
// Output sensitivity of (8.22), I - G_C(s) L (sI - A + KC)^-1 K (measurements x
// measurements); equal to 1/(1 + F_y G) (8.36) for one measurement.
Eigen::MatrixXcd sensitivity822(const LqgDesign& d, std::complex<double> s);

}  // namespace flexarm
