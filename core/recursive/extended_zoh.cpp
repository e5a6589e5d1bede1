#include "core/recursive/extended_zoh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/common/balancing.h"

namespace flexarm {

namespace {
// Unit roundoff of double: the series stops when two successive terms are below it relative
// to the sum (the early termination of Al-Mohy and Higham's expmv).
constexpr double kTolerance = 1.1102230246251565e-16;
// Largest weighted norm of h A a sub-step may have; the series then needs ~35 terms at most.
constexpr double kMaxStepNorm = 4.0;
constexpr int kMaxTerms = 60;

}  // namespace

void ExtendedZoh::setScales(const Eigen::VectorXd& stateScale, const Eigen::VectorXd& blockScale) {
  if ((stateScale.array() <= 0.0).any() || (blockScale.array() <= 0.0).any())
    throw std::invalid_argument("ExtendedZoh: scales must be positive");
  stateScale_ = stateScale;
  blockScale_ = blockScale;
}

void ExtendedZoh::setScalesFor(const Eigen::MatrixXd& A, const std::vector<Eigen::MatrixXd>& dA,
                               const std::vector<Eigen::VectorXd>& dB) {
  const Eigen::Index n = A.rows();
  const Eigen::VectorXd d = balancingScales(A);
  // Row sums of |D^-1 M D| for A and each dA_j (plus dB_j measured against the largest entry
  // of the balanced B-like column, so that a parameter entering only B counts too).
  auto rowNorm = [&](const Eigen::MatrixXd& M) {
    double m = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      double s = 0.0;
      for (Eigen::Index k = 0; k < n; ++k) s += std::abs(M(i, k)) * d[k] / d[i];
      m = std::max(m, s);
    }
    return m;
  };
  const double a = std::max(rowNorm(A), 1e-300);
  Eigen::VectorXd block = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(dA.size()));
  for (std::size_t j = 0; j < dA.size(); ++j) {
    double g = rowNorm(dA[j]);
    if (j < dB.size())
      for (Eigen::Index i = 0; i < n; ++i) g = std::max(g, std::abs(dB[j][i]) / d[i]);
    if (g > 0.0 && std::isfinite(g)) block[static_cast<Eigen::Index>(j)] = g / a;
  }
  setScales(d, block);
}

namespace {

// The series for one model size. N is the number of states (Eigen::Dynamic for any), MaxCols
// bounds the columns x, X_1..X_p (Eigen::Dynamic: no bound): with both fixed, every matrix
// lives on the stack and the products unroll.
template <int N, int MaxCols>
int series(const Eigen::MatrixXd& A0, const Eigen::VectorXd& B0,
           const std::vector<Eigen::MatrixXd>& dA0, const std::vector<Eigen::VectorXd>& dB0,
           double h, int substeps, double u, const Eigen::MatrixXd& weight, Eigen::VectorXd& x,
           Eigen::MatrixXd& X, double tolerance, int maxTerms) {
  constexpr int MaxStack = (N == Eigen::Dynamic || MaxCols == Eigen::Dynamic) ? Eigen::Dynamic
                                                                              : N * (MaxCols - 1);
  using Square = Eigen::Matrix<double, N, N>;
  using Wide = Eigen::Matrix<double, N, Eigen::Dynamic, N == 1 ? Eigen::RowMajor : Eigen::ColMajor, N, MaxCols>;
  using Stack = Eigen::Matrix<double, Eigen::Dynamic, N, Eigen::ColMajor, MaxStack, N>;
  using Column = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, MaxStack, 1>;
  const Eigen::Index n = A0.rows();
  const auto p = static_cast<Eigen::Index>(dA0.size());
  const Square A = A0;
  Stack D(n * p, n);          // dA_1 .. dA_p stacked
  Wide input(n, p + 1);       // (B, dB_1, .., dB_p) u
  input.col(0) = B0 * u;
  for (Eigen::Index j = 0; j < p; ++j) {
    D.middleRows(j * n, n) = dA0[static_cast<std::size_t>(j)];
    input.col(j + 1) = dB0[static_cast<std::size_t>(j)] * u;
  }
  const Wide w = weight;
  Wide sum(n, p + 1), term(n, p + 1), next(n, p + 1);
  Column coupling(n * p);
  sum.col(0) = x;
  if (p) sum.rightCols(p) = X;
  int terms = 0;
  for (int s = 0; s < substeps; ++s) {
    term = sum;
    double previous = term.cwiseAbs().cwiseProduct(w).maxCoeff();
    for (int k = 1; k <= maxTerms; ++k) {
      // next = (h / k) M term: A on every column, dA_j x on X_j's, and the held input's
      // contribution in the first term only.
      next.noalias() = A.lazyProduct(term);
      if (p) {
        coupling.noalias() = D.lazyProduct(term.col(0));
        next.rightCols(p) += Eigen::Map<const Eigen::MatrixXd>(coupling.data(), n, p);
      }
      if (k == 1) next += input;
      next *= h / k;
      sum += next;
      ++terms;
      const double current = next.cwiseAbs().cwiseProduct(w).maxCoeff();
      const double total = sum.cwiseAbs().cwiseProduct(w).maxCoeff();
      term.swap(next);
      if (current + previous <= tolerance * total) break;
      previous = current;
    }
  }
  x = sum.col(0);
  if (p) X = sum.rightCols(p);
  return terms;
}

template <int N>
int seriesOfSize(const Eigen::MatrixXd& A, const Eigen::VectorXd& B,
                 const std::vector<Eigen::MatrixXd>& dA, const std::vector<Eigen::VectorXd>& dB,
                 double h, int substeps, double u, const Eigen::MatrixXd& weight,
                 Eigen::VectorXd& x, Eigen::MatrixXd& X, double tolerance, int maxTerms) {
  if (dA.size() < 16)
    return series<N, 16>(A, B, dA, dB, h, substeps, u, weight, x, X, tolerance, maxTerms);
  return series<N, Eigen::Dynamic>(A, B, dA, dB, h, substeps, u, weight, x, X, tolerance, maxTerms);
}

}  // namespace

void ExtendedZoh::advance(const Eigen::MatrixXd& A, const Eigen::VectorXd& B,
                          const std::vector<Eigen::MatrixXd>& dA,
                          const std::vector<Eigen::VectorXd>& dB, double T, double u,
                          Eigen::VectorXd& x, Eigen::MatrixXd& X) {
  const Eigen::Index n = A.rows();
  const std::size_t p = dA.size();
  if (A.cols() != n || B.size() != n || x.size() != n || dB.size() != p ||
      X.rows() != (p ? n : X.rows()) || static_cast<std::size_t>(X.cols()) != p)
    throw std::invalid_argument("ExtendedZoh: inconsistent sizes");
  if (stateScale_.size() != n || static_cast<std::size_t>(blockScale_.size()) < p)
    setScalesFor(A, dA, dB);
  weight_.resize(n, static_cast<Eigen::Index>(p + 1));
  weight_.col(0) = stateScale_.cwiseInverse();
  for (std::size_t j = 0; j < p; ++j)
    weight_.col(static_cast<Eigen::Index>(j + 1)) =
        stateScale_.cwiseInverse() / blockScale_[static_cast<Eigen::Index>(j)];

  // The number of sub-steps follows the weighted norm of h A: the coupling blocks dA_j are
  // nilpotent in the extended matrix and only add a polynomial factor to the series' terms.
  double nu = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    double row = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) row += std::abs(A(i, k)) * stateScale_[k];
    nu = std::max(nu, row / stateScale_[i]);
  }
  nu *= T;
  tooLong_ = 0.0;
  if (!std::isfinite(nu)) {
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  if (nu / kMaxStepNorm > kMaxSubsteps) {
    tooLong_ = std::ceil(nu / kMaxStepNorm);
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  const int substeps = std::max(1, static_cast<int>(std::ceil(nu / kMaxStepNorm)));
  const double h = T / substeps;
  switch (n) {
#define FLEXARM_SERIES_CASE(K) \
  case K:                      \
    lastTerms_ = seriesOfSize<K>(A, B, dA, dB, h, substeps, u, weight_, x, X, kTolerance, kMaxTerms); \
    break;
    FLEXARM_SERIES_CASE(1)
    FLEXARM_SERIES_CASE(2)
    FLEXARM_SERIES_CASE(3)
    FLEXARM_SERIES_CASE(4)
    FLEXARM_SERIES_CASE(5)
    FLEXARM_SERIES_CASE(6)
    FLEXARM_SERIES_CASE(7)
    FLEXARM_SERIES_CASE(8)
#undef FLEXARM_SERIES_CASE
    default:
      lastTerms_ = series<Eigen::Dynamic, Eigen::Dynamic>(A, B, dA, dB, h, substeps, u, weight_,
                                                           x, X, kTolerance, kMaxTerms);
  }
}

}  // namespace flexarm
