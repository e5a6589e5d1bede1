#pragma once
// Continuous-time algebraic Riccati equation A'X + XA - X B R^-1 B' X + Q = 0, the equation
// behind the LQR gain of (8.17) and, in dual form, the Kalman filter gain of (8.16).
#include <Eigen/Dense>
#include <string>

#include "core/common/progress.h"

namespace flexarm {

struct CareOptions {
  // Newton (Kleinman) refinement steps taken after the Schur solution while they lower the
  // residual; 0 keeps the plain Schur solution.
  int maxRefinementSteps = 2;
  // The solve is reported Failed when the relative residual stays above this.
  double residualTolerance = 1e-8;
  bool isValid(std::string* why = nullptr) const;
};

struct CareResult {
  Termination termination = Termination::Failed;
  std::string message;
  Eigen::MatrixXd X;  // the stabilizing solution, symmetric
  // ||A'X + XA - XGX + Q||_F / (||Q||_F + 2||A'X||_F + ||XGX||_F), G = B R^-1 B'.
  double residual = 0.0;
  int iterations = 0;  // refinement steps taken
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
};

// Stabilizing solution of A'X + XA - X B R^-1 B' X + Q = 0 from the stable invariant subspace
// of the Hamiltonian [A -G; -Q -A'] (G = B R^-1 B'), found by the complex Schur form with the
// stable eigenvalues moved to the top by unitary swaps, X = U21 U11^-1, then refined by Newton
// steps. A data-dependent failure (eigenvalues on the imaginary axis, i.e. (A,B) not
// stabilizable or (Q,A) with an unobservable mode on the axis; singular U11) is reported in
// the result. Throws std::invalid_argument for mismatched sizes, non-symmetric Q or R, R not
// positive definite, or non-finite entries.
CareResult solveCare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const CareOptions& options = {});

// Relative residual of X in A'X + XA - X B R^-1 B' X + Q = 0 (as CareResult::residual).
double careResidual(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                    const Eigen::MatrixXd& R, const Eigen::MatrixXd& X);

// Solution of the Sylvester equation A X + X B = C by the complex Schur forms of A and B
// (Bartels-Stewart). Throws std::invalid_argument for mismatched sizes; the caller ensures
// that A and -B share no eigenvalue.
Eigen::MatrixXd solveSylvester(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                               const Eigen::MatrixXd& C);

}  // namespace flexarm
