#include "core/ident/polynomial.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexarm {

namespace {

// y_j[t] -= sum_{k=1}^{na-1} den[k] y_j[t-k] in place for the S series y_0..y_{S-1}, the
// lag-one term last so that each sample waits for its predecessor through one multiply-subtract
// only, and the series interleaved so that their recursions overlap; Order > 0 unrolls the
// lags. Each series gets exactly the operations it would get alone.
template <int Order, int S>
void recurse(const double* den, int na, double* const* y, Eigen::Index n) {
  const int m = Order > 0 ? Order + 1 : na;
  for (Eigen::Index t = 1; t < std::min<Eigen::Index>(m - 1, n); ++t)
    for (int j = 0; j < S; ++j)
      for (int k = static_cast<int>(t); k >= 1; --k) y[j][t] -= den[k] * y[j][t - k];
  for (Eigen::Index t = m - 1; t < n; ++t) {
    double s[S];
    for (int j = 0; j < S; ++j) s[j] = y[j][t];
    for (int k = m - 1; k >= 2; --k)
      for (int j = 0; j < S; ++j) s[j] -= den[k] * y[j][t - k];
    for (int j = 0; j < S; ++j) y[j][t] = s[j] - den[1] * y[j][t - 1];
  }
}

// num(q)/den(q) applied to the S signals x[j] into y[j] (sized by the caller).
template <int S>
void filterMany(const Poly& num, const Poly& den, const Eigen::VectorXd* const* x,
                Eigen::VectorXd* const* y) {
  if (den.empty() || den[0] == 0.0)
    throw std::invalid_argument("filter: the denominator's leading coefficient is zero");
  const Eigen::Index n = x[0]->size();
  // Monic form: the leading coefficient divides both polynomials.
  const double inv0 = 1.0 / den[0];
  int na = static_cast<int>(den.size());
  while (na > 1 && den[na - 1] == 0.0) --na;
  // Moving average part (vectorized over t), then the autoregressive recursion.
  double* out[S];
  for (int j = 0; j < S; ++j) {
    Eigen::VectorXd& yj = *y[j];
    yj.setZero(n);
    for (std::size_t k = 0; k < num.size() && static_cast<Eigen::Index>(k) < n; ++k) {
      const double c = num[k] * inv0;
      if (c == 0.0) continue;
      const Eigen::Index len = n - static_cast<Eigen::Index>(k);
      yj.tail(len) += c * x[j]->head(len);
    }
    out[j] = yj.data();
  }
  if (na == 1) return;
  std::vector<double> dn(den.begin(), den.begin() + na);
  for (double& v : dn) v *= inv0;
  switch (na - 1) {
    case 1: recurse<1, S>(dn.data(), na, out, n); break;
    case 2: recurse<2, S>(dn.data(), na, out, n); break;
    case 3: recurse<3, S>(dn.data(), na, out, n); break;
    case 4: recurse<4, S>(dn.data(), na, out, n); break;
    default: recurse<0, S>(dn.data(), na, out, n); break;
  }
}

}  // namespace

Eigen::VectorXd filter(const Poly& num, const Poly& den, const Eigen::VectorXd& x) {
  Eigen::VectorXd y;
  const Eigen::VectorXd* in[1] = {&x};
  Eigen::VectorXd* out[1] = {&y};
  filterMany<1>(num, den, in, out);
  return y;
}

Eigen::VectorXd delayed(const Eigen::VectorXd& x, int k) {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(x.size());
  if (k < x.size()) y.tail(x.size() - k) = x.head(x.size() - k);
  return y;
}

Poly polyMultiply(const Poly& a, const Poly& b) {
  if (a.empty() || b.empty()) return {};
  Poly c(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}

std::vector<std::complex<double>> polyRoots(const Poly& p) {
  std::size_t first = 0;
  while (first < p.size() && p[first] == 0.0) ++first;
  std::size_t last = p.size();
  while (last > first && p[last - 1] == 0.0) --last;
  if (last <= first + 1) return {};
  const int n = static_cast<int>(last - first - 1);
  Eigen::MatrixXd comp = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) comp(0, j) = -p[first + 1 + j] / p[first];
  for (int i = 1; i < n; ++i) comp(i, i - 1) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> es(comp, false);
  std::vector<std::complex<double>> r(n);
  for (int i = 0; i < n; ++i) r[i] = es.eigenvalues()[i];
  return r;
}

Poly polyFromRoots(const std::vector<std::complex<double>>& roots) {
  std::vector<std::complex<double>> c{1.0};
  for (const auto& z : roots) {
    std::vector<std::complex<double>> next(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i] += c[i];
      next[i + 1] -= z * c[i];
    }
    c.swap(next);
  }
  Poly p(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) p[i] = c[i].real();
  return p;
}

bool reflectIntoUnitCircle(Poly& p, double maxRadius) {
  if (p.size() < 2) return false;
  auto roots = polyRoots(p);
  bool changed = false;
  for (auto& z : roots) {
    const double m = std::abs(z);
    if (m > 1.0) {
      z = 1.0 / std::conj(z);
      changed = true;
    }
    if (std::abs(z) > maxRadius) {
      z *= maxRadius / std::abs(z);
      changed = true;
    }
  }
  if (!changed) return false;
  const double lead = p[0];
  const std::size_t n = p.size();
  Poly q = polyFromRoots(roots);
  q.resize(n, 0.0);
  for (auto& v : q) v *= lead;
  p = q;
  return true;
}

double maxRootMagnitude(const Poly& p) {
  double m = 0.0;
  for (const auto& z : polyRoots(p)) m = std::max(m, std::abs(z));
  return m;
}

std::complex<double> polyEval(const Poly& p, double w) {
  std::complex<double> s = 0.0;
  const std::complex<double> zinv = std::polar(1.0, -w);
  std::complex<double> zk = 1.0;
  for (double c : p) {
    s += c * zk;
    zk *= zinv;
  }
  return s;
}

}  // namespace flexarm
