#include "core/control/frequency_response.h"

#include <stdexcept>
#include <vector>

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

namespace {

using Complex = std::complex<double>;

// |re| + |im|: enough to choose a pivot, without a square root.
inline double size1(Complex z) { return std::abs(z.real()) + std::abs(z.imag()); }

// a / b without the overflow-guarding library call (the values here are far from overflow).
inline Complex divide(Complex a, Complex b) { return a * std::conj(b) / std::norm(b); }

}  // namespace

void TransferEvaluator::solve(Complex s, int columns, Complex* M, Complex* X) const {
  const int n = static_cast<int>(H_.rows());
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) M[i * n + j] = -H_(i, j);
    M[i * n + i] += s;
    for (int c = 0; c < columns; ++c) X[i * columns + c] = Bt_(i, c);
  }
  for (int i = 0; i + 1 < n; ++i) {
    Complex* r0 = M + i * n;
    Complex* r1 = M + (i + 1) * n;
    if (size1(r1[i]) > size1(r0[i])) {
      for (int j = i; j < n; ++j) std::swap(r0[j], r1[j]);
      for (int c = 0; c < columns; ++c) std::swap(X[i * columns + c], X[(i + 1) * columns + c]);
    }
    if (r1[i] == Complex(0.0)) continue;
    const Complex f = divide(r1[i], r0[i]);
    for (int j = i + 1; j < n; ++j) r1[j] -= f * r0[j];
    r1[i] = 0.0;
    for (int c = 0; c < columns; ++c) X[(i + 1) * columns + c] -= f * X[i * columns + c];
  }
  for (int i = n - 1; i >= 0; --i) {
    const Complex* row = M + i * n;
    for (int c = 0; c < columns; ++c) {
      Complex acc = X[i * columns + c];
      for (int j = i + 1; j < n; ++j) acc -= row[j] * X[j * columns + c];
      X[i * columns + c] = divide(acc, row[i]);
    }
  }
}

Eigen::MatrixXcd TransferEvaluator::operator()(Complex s) const {
  Eigen::MatrixXcd G = D_.cast<Complex>();
  const int n = static_cast<int>(H_.rows()), m = inputs();
  if (n == 0) return G;
  std::vector<Complex> M(static_cast<std::size_t>(n) * n), X(static_cast<std::size_t>(n) * m);
  solve(s, m, M.data(), X.data());
  for (int o = 0; o < outputs(); ++o)
    for (int c = 0; c < m; ++c)
      for (int i = 0; i < n; ++i) G(o, c) += Ct_(o, i) * X[i * m + c];
  return G;
}

Complex TransferEvaluator::scalar(Complex s) const {
  Complex g = D_(0, 0);
  const int n = static_cast<int>(H_.rows());
  if (n == 0) return g;
  constexpr int kStack = 12;  // arm models are far smaller; larger ones use the heap
  Complex Ms[kStack * kStack], Xs[kStack];
  std::vector<Complex> Mh, Xh;
  Complex* M = Ms;
  Complex* X = Xs;
  if (n > kStack) {
    Mh.resize(static_cast<std::size_t>(n) * n);
    Xh.resize(static_cast<std::size_t>(n));
    M = Mh.data();
    X = Xh.data();
  }
  solve(s, 1, M, X);
  for (int i = 0; i < n; ++i) g += Ct_(0, i) * X[i];
  return g;
}

}  // namespace flexarm
