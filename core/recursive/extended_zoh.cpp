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

void ExtendedZoh::collect(const Eigen::MatrixXd& M, Sparse& out) {
  out.start.clear();
  out.col.clear();
  out.value.clear();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    out.start.push_back(static_cast<int>(out.col.size()));
    for (Eigen::Index j = 0; j < M.cols(); ++j)
      if (M(i, j) != 0.0) {
        out.col.push_back(static_cast<int>(j));
        out.value.push_back(M(i, j));
      }
  }
  out.start.push_back(static_cast<int>(out.col.size()));
}

void ExtendedZoh::apply(const Sparse& A, const double* v, const Sparse* D, const double* vx,
                        double* out, Eigen::Index n) {
  for (Eigen::Index i = 0; i < n; ++i) {
    double acc = 0.0;
    for (int k = A.start[static_cast<std::size_t>(i)]; k < A.start[static_cast<std::size_t>(i) + 1]; ++k)
      acc += A.value[static_cast<std::size_t>(k)] * v[A.col[static_cast<std::size_t>(k)]];
    if (D)
      for (int k = D->start[static_cast<std::size_t>(i)]; k < D->start[static_cast<std::size_t>(i) + 1]; ++k)
        acc += D->value[static_cast<std::size_t>(k)] * vx[D->col[static_cast<std::size_t>(k)]];
    out[i] = acc;
  }
}

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
  const Eigen::Index N = n * static_cast<Eigen::Index>(p + 1);
  term_.resize(N);
  next_.resize(N);
  sum_.resize(N);
  weight_.resize(N);
  for (Eigen::Index i = 0; i < n; ++i) weight_[i] = 1.0 / stateScale_[i];
  for (std::size_t j = 0; j < p; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      weight_[n * static_cast<Eigen::Index>(j + 1) + i] =
          1.0 / (stateScale_[i] * blockScale_[static_cast<Eigen::Index>(j)]);

  collect(A, a_);
  da_.resize(p);
  for (std::size_t j = 0; j < p; ++j) collect(dA[j], da_[j]);

  // The number of sub-steps follows the weighted norm of h A: the coupling blocks dA_j are
  // nilpotent in the extended matrix and only add a polynomial factor to the series' terms.
  double nu = 0.0;
  {
    for (Eigen::Index i = 0; i < n; ++i) {
      double row = 0.0;
      for (int k = a_.start[static_cast<std::size_t>(i)]; k < a_.start[static_cast<std::size_t>(i) + 1]; ++k)
        row += std::abs(a_.value[static_cast<std::size_t>(k)]) *
               stateScale_[a_.col[static_cast<std::size_t>(k)]];
      nu = std::max(nu, row / stateScale_[i]);
    }
    nu *= T;
  }
  if (!std::isfinite(nu)) {
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  const int substeps = std::max(1, static_cast<int>(std::ceil(nu / kMaxStepNorm)));
  const double h = T / substeps;

  // The extended state w = (x, X_1, ..., X_p).
  double* sum = sum_.data();
  double* term = term_.data();
  double* next = next_.data();
  const double* w = weight_.data();
  std::copy(x.data(), x.data() + n, sum);
  for (std::size_t j = 0; j < p; ++j)
    std::copy(X.col(static_cast<Eigen::Index>(j)).data(), X.col(static_cast<Eigen::Index>(j)).data() + n,
              sum + n * static_cast<Eigen::Index>(j + 1));

  lastTerms_ = 0;
  for (int s = 0; s < substeps; ++s) {
    std::copy(sum, sum + N, term);
    double previous = 0.0;
    for (Eigen::Index i = 0; i < N; ++i) previous = std::max(previous, std::abs(term[i]) * w[i]);
    for (int k = 1; k <= kMaxTerms; ++k) {
      // next = (h / k) M term, with the held input's contribution h (B u, dB_j u) in the
      // first term only.
      apply(a_, term, nullptr, nullptr, next, n);
      for (std::size_t j = 0; j < p; ++j) {
        const Eigen::Index off = n * static_cast<Eigen::Index>(j + 1);
        apply(a_, term + off, &da_[j], term, next + off, n);
      }
      if (k == 1 && u != 0.0) {
        for (Eigen::Index i = 0; i < n; ++i) next[i] += B[i] * u;
        for (std::size_t j = 0; j < p; ++j) {
          double* out = next + n * static_cast<Eigen::Index>(j + 1);
          for (Eigen::Index i = 0; i < n; ++i) out[i] += dB[j][i] * u;
        }
      }
      const double c = h / k;
      double current = 0.0, total = 0.0;
      for (Eigen::Index i = 0; i < N; ++i) {
        next[i] *= c;
        sum[i] += next[i];
        current = std::max(current, std::abs(next[i]) * w[i]);
        total = std::max(total, std::abs(sum[i]) * w[i]);
      }
      std::swap(term, next);
      ++lastTerms_;
      if (current + previous <= kTolerance * total) break;
      previous = current;
    }
  }
  x = sum_.head(n);
  for (std::size_t j = 0; j < p; ++j)
    X.col(static_cast<Eigen::Index>(j)) = sum_.segment(n * static_cast<Eigen::Index>(j + 1), n);
}

}  // namespace flexarm
