#include "core/ident/polynomial.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexarm {

Eigen::VectorXd filter(const Poly& num, const Poly& den, const Eigen::VectorXd& x) {
  if (den.empty() || den[0] == 0.0)
    throw std::invalid_argument("filter: the denominator's leading coefficient is zero");
  const Eigen::Index n = x.size();
  Eigen::VectorXd y(n);
  const int nb = static_cast<int>(num.size());
  const int na = static_cast<int>(den.size());
  // Leading zeros of the numerator are a pure delay (B of (4.10) holds nk of them): they are
  // skipped, so a long delay costs nothing per sample.
  int k0 = 0;
  while (k0 < nb && num[static_cast<std::size_t>(k0)] == 0.0) ++k0;
  const double inv0 = 1.0 / den[0];
  for (Eigen::Index t = 0; t < n; ++t) {
    double s = 0.0;
    const int kb = static_cast<int>(std::min<Eigen::Index>(nb - 1, t));
    for (int k = k0; k <= kb; ++k) s += num[k] * x[t - k];
    const int ka = static_cast<int>(std::min<Eigen::Index>(na - 1, t));
    for (int k = 1; k <= ka; ++k) s -= den[k] * y[t - k];
    y[t] = s * inv0;
  }
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
