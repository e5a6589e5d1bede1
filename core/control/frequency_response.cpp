#include "core/control/frequency_response.h"

#include <stdexcept>

namespace flexarm {

TransferEvaluator::TransferEvaluator(const StateSpace& system) {
  std::string why;
  if (!system.isValid(&why)) throw std::invalid_argument("TransferEvaluator: " + why);
  if (system.isDiscrete())
    throw std::invalid_argument("TransferEvaluator: the system must be continuous-time");
  D_ = system.D;
  if (system.states() == 0) {
    H_.resize(0, 0);
    Bt_.resize(0, system.inputs());
    Ct_.resize(system.outputs(), 0);
    return;
  }
  Eigen::HessenbergDecomposition<Eigen::MatrixXd> hess(system.A);
  const Eigen::MatrixXd Q = hess.matrixQ();
  H_ = hess.matrixH();
  Bt_ = Q.transpose() * system.B;
  Ct_ = system.C * Q;
}

Eigen::MatrixXcd TransferEvaluator::solve(std::complex<double> s, int columns) const {
  using C = std::complex<double>;
  const Eigen::Index n = H_.rows();
  Eigen::MatrixXcd M = -H_.cast<C>();
  M.diagonal().array() += s;
  Eigen::MatrixXcd X = Bt_.leftCols(columns).cast<C>();
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    if (std::abs(M(i + 1, i)) > std::abs(M(i, i))) {
      M.row(i).tail(n - i).swap(M.row(i + 1).tail(n - i));
      X.row(i).swap(X.row(i + 1));
    }
    if (M(i + 1, i) == C(0.0)) continue;
    const C f = M(i + 1, i) / M(i, i);
    M.row(i + 1).tail(n - i - 1) -= f * M.row(i).tail(n - i - 1);
    M(i + 1, i) = 0.0;
    X.row(i + 1) -= f * X.row(i);
  }
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    if (i + 1 < n) X.row(i) -= M.row(i).tail(n - i - 1) * X.bottomRows(n - i - 1);
    X.row(i) /= M(i, i);
  }
  return X;
}

Eigen::MatrixXcd TransferEvaluator::operator()(std::complex<double> s) const {
  Eigen::MatrixXcd G = D_.cast<std::complex<double>>();
  if (H_.rows() > 0) G += Ct_.cast<std::complex<double>>() * solve(s, inputs());
  return G;
}

std::complex<double> TransferEvaluator::scalar(std::complex<double> s) const {
  std::complex<double> g = D_(0, 0);
  if (H_.rows() > 0) g += (Ct_.row(0).cast<std::complex<double>>() * solve(s, 1))(0, 0);
  return g;
}

}  // namespace flexarm
