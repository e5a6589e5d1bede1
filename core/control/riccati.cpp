#include "core/control/riccati.h"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace flexarm {
namespace {

using Complex = std::complex<double>;
using CMatrix = Eigen::MatrixXcd;

bool allFinite(const Eigen::MatrixXd& M) { return M.allFinite(); }

// Swaps the adjacent diagonal entries k and k+1 of the upper triangular T (T = U^H M U) by a
// unitary rotation whose first column is the eigenvector of the 2x2 block for T(k+1,k+1).
void swapAdjacent(CMatrix& T, CMatrix& U, int k) {
  const Complex a = T(k, k), b = T(k + 1, k + 1), c = T(k, k + 1);
  if (a == b) return;
  Eigen::Vector2cd q(c, b - a);
  q.normalize();
  Eigen::Matrix2cd G;
  G << q(0), -std::conj(q(1)), q(1), std::conj(q(0));
  T.middleRows(k, 2) = G.adjoint() * T.middleRows(k, 2);
  T.middleCols(k, 2) = T.middleCols(k, 2) * G;
  U.middleCols(k, 2) = U.middleCols(k, 2) * G;
  T(k + 1, k) = 0.0;
  T(k, k) = b;
  T(k + 1, k + 1) = a;
}

// Reorders the complex Schur form so that the eigenvalues with negative real part come first;
// returns how many there are.
int moveStableFirst(CMatrix& T, CMatrix& U) {
  const int n = static_cast<int>(T.rows());
  int placed = 0;
  for (int j = 0; j < n; ++j) {
    if (T(j, j).real() >= 0.0) continue;
    for (int k = j - 1; k >= placed; --k) swapAdjacent(T, U, k);
    ++placed;
  }
  return placed;
}

Eigen::MatrixXd residualMatrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& G,
                               const Eigen::MatrixXd& Q, const Eigen::MatrixXd& X) {
  return A.transpose() * X + X * A - X * G * X + Q;
}

double relativeResidual(const Eigen::MatrixXd& A, const Eigen::MatrixXd& G,
                        const Eigen::MatrixXd& Q, const Eigen::MatrixXd& X) {
  const double scale = Q.norm() + 2.0 * (A.transpose() * X).norm() + (X * G * X).norm();
  const double r = residualMatrix(A, G, Q, X).norm();
  return scale > 0.0 ? r / scale : r;
}

Eigen::MatrixXd gainWeight(const Eigen::MatrixXd& B, const Eigen::MatrixXd& R) {
  return B * Eigen::LLT<Eigen::MatrixXd>(R).solve(B.transpose());
}

void checkCareArguments(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                        const Eigen::MatrixXd& Q, const Eigen::MatrixXd& R) {
  const auto n = A.rows();
  if (A.cols() != n || B.rows() != n || Q.rows() != n || Q.cols() != n || R.rows() != B.cols() ||
      R.cols() != B.cols() || n == 0 || B.cols() == 0)
    throw std::invalid_argument("Riccati equation: matrix sizes do not agree");
  if (!allFinite(A) || !allFinite(B) || !allFinite(Q) || !allFinite(R))
    throw std::invalid_argument("Riccati equation: a matrix has a non-finite entry");
  const double tol = 1e-12;
  if ((Q - Q.transpose()).norm() > tol * (1.0 + Q.norm()))
    throw std::invalid_argument("Riccati equation: Q is not symmetric");
  if ((R - R.transpose()).norm() > tol * (1.0 + R.norm()))
    throw std::invalid_argument("Riccati equation: R is not symmetric");
  Eigen::LLT<Eigen::MatrixXd> llt(R);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument("Riccati equation: R is not positive definite");
}

}  // namespace

bool CareOptions::isValid(std::string* why) const {
  if (maxRefinementSteps < 0) {
    if (why) *why = "maxRefinementSteps must not be negative";
    return false;
  }
  if (!(residualTolerance > 0.0)) {
    if (why) *why = "residualTolerance must be positive";
    return false;
  }
  return true;
}

Eigen::MatrixXd solveSylvester(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                               const Eigen::MatrixXd& C) {
  if (A.rows() != A.cols() || B.rows() != B.cols() || C.rows() != A.rows() || C.cols() != B.rows())
    throw std::invalid_argument("Sylvester equation: matrix sizes do not agree");
  Eigen::ComplexSchur<CMatrix> sa(A.cast<Complex>()), sb(B.cast<Complex>());
  const CMatrix& Ta = sa.matrixT();
  const CMatrix& Tb = sb.matrixT();
  const CMatrix F = sa.matrixU().adjoint() * C.cast<Complex>() * sb.matrixU();
  const auto n = A.rows(), m = B.rows();
  CMatrix Y(n, m);
  for (Eigen::Index j = 0; j < m; ++j) {
    Eigen::VectorXcd rhs = F.col(j);
    for (Eigen::Index i = 0; i < j; ++i) rhs -= Tb(i, j) * Y.col(i);
    CMatrix M = Ta;
    M.diagonal().array() += Tb(j, j);
    Y.col(j) = M.triangularView<Eigen::Upper>().solve(rhs);
  }
  return (sa.matrixU() * Y * sb.matrixU().adjoint()).real();
}

double careResidual(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                    const Eigen::MatrixXd& R, const Eigen::MatrixXd& X) {
  checkCareArguments(A, B, Q, R);
  return relativeResidual(A, gainWeight(B, R), Q, X);
}

CareResult solveCare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const CareOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("CareOptions: " + why);
  checkCareArguments(A, B, Q, R);
  const auto start = std::chrono::steady_clock::now();
  CareResult result;
  auto finish = [&](Termination t, std::string message) {
    result.termination = t;
    result.message = std::move(message);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };

  const int n = static_cast<int>(A.rows());
  const Eigen::MatrixXd G = gainWeight(B, R);
  Eigen::MatrixXd H(2 * n, 2 * n);
  H << A, -G, -Q, -A.transpose();
  Eigen::ComplexSchur<CMatrix> schur(H.cast<Complex>());
  if (schur.info() != Eigen::Success)
    return finish(Termination::Failed, "the Schur form of the Hamiltonian did not converge");
  CMatrix T = schur.matrixT();
  CMatrix U = schur.matrixU();
  const int stable = moveStableFirst(T, U);
  // Eigenvalues this close to the imaginary axis make the stable subspace ill-determined.
  const double axisTol = 1e-10 * (1.0 + H.norm());
  double closest = 1e300;
  for (int i = 0; i < 2 * n; ++i) closest = std::min(closest, std::abs(T(i, i).real()));
  if (stable != n || closest < axisTol) {
    std::ostringstream s;
    s << "the Hamiltonian has eigenvalues on the imaginary axis (" << stable << " stable of "
      << 2 * n << "): the system is not stabilizable, or a weighted mode is not detectable";
    return finish(Termination::Failed, s.str());
  }
  const CMatrix U11 = U.topLeftCorner(n, n);
  const CMatrix U21 = U.bottomLeftCorner(n, n);
  Eigen::PartialPivLU<CMatrix> lu(U11.transpose());
  const double rcond = lu.rcond();
  if (!(rcond > 1e-14))
    return finish(Termination::Failed,
                  "the stable subspace of the Hamiltonian has a singular first block: no "
                  "stabilizing solution exists (the system is not stabilizable)");
  // X = U21 U11^-1, i.e. U11^T X^T = U21^T.
  CMatrix Xc = lu.solve(U21.transpose()).transpose();
  Eigen::MatrixXd X = Xc.real();
  X = 0.5 * (X + X.transpose()).eval();
  result.residual = relativeResidual(A, G, Q, X);
  // Newton refinement: (A - G X)' E + E (A - G X) = -Res(X), X <- X + E.
  for (int step = 0; step < options.maxRefinementSteps && result.residual > 1e-15; ++step) {
    const Eigen::MatrixXd Acl = A - G * X;
    const Eigen::MatrixXd E = solveSylvester(Acl.transpose(), Acl, -residualMatrix(A, G, Q, X));
    Eigen::MatrixXd Xn = X + E;
    Xn = 0.5 * (Xn + Xn.transpose()).eval();
    const double r = relativeResidual(A, G, Q, Xn);
    if (!(r < result.residual)) break;
    X = Xn;
    result.residual = r;
    ++result.iterations;
  }
  result.X = X;
  const Eigen::VectorXcd closedLoop =
      Eigen::EigenSolver<Eigen::MatrixXd>(A - G * X, false).eigenvalues();
  if ((closedLoop.real().array() >= 0.0).any())
    return finish(Termination::Failed,
                  "the Riccati solution does not stabilize A - B R^-1 B' X: the system is not "
                  "stabilizable");
  if (!(result.residual <= options.residualTolerance)) {
    std::ostringstream s;
    s << "the Riccati solution has a relative residual of " << result.residual
      << ", above the tolerance " << options.residualTolerance;
    return finish(Termination::Failed, s.str());
  }
  std::ostringstream s;
  s << "stabilizing solution, relative residual " << result.residual;
  return finish(Termination::Converged, s.str());
}

}  // namespace flexarm
