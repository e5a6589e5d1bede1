#include "core/ident/pole_zero_regions.h"

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "core/ident/polynomial.h"
#include "core/models/analysis.h"

namespace flexarm {

bool RootRegion::contains(std::complex<double> z) const {
  const Eigen::Vector2d d(z.real() - value.real(), z.imag() - value.imag());
  // In the covariance's principal axes; an axis of no variance (a real root's imaginary
  // part, or the second axis when one parameter moves the root) admits no offset along it.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(covariance);
  const Eigen::Vector2d along = es.eigenvectors().transpose() * d;
  const double top = std::max(es.eigenvalues().maxCoeff(), 0.0);
  const double scale = std::max(std::abs(value), 1e-12);
  double sum = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double l = es.eigenvalues()[i];
    if (l > 1e-12 * top && l > 0.0) sum += along[i] * along[i] / l;
    else if (std::abs(along[i]) > 1e-9 * scale) return false;
  }
  return sum <= radiusSquared;
}

std::vector<std::complex<double>> RootRegion::boundary(int points) const {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(covariance);
  const Eigen::Vector2d axes = es.eigenvalues().cwiseMax(0.0).cwiseSqrt() * std::sqrt(radiusSquared);
  std::vector<std::complex<double>> out;
  for (int k = 0; k <= points; ++k) {
    const double a = 2.0 * M_PI * k / points;
    const Eigen::Vector2d p = es.eigenvectors() * Eigen::Vector2d(axes[0] * std::cos(a), axes[1] * std::sin(a));
    out.emplace_back(value.real() + p[0], value.imag() + p[1]);
  }
  return out;
}

namespace {

// The roots at theta, each of the nominal ones matched to the nearest (every root used once).
std::vector<std::complex<double>> matched(const std::vector<std::complex<double>>& nominal,
                                          std::vector<std::complex<double>> roots) {
  std::vector<std::complex<double>> out;
  for (const auto& z : nominal) {
    std::size_t best = 0;
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < roots.size(); ++i)
      if (std::abs(roots[i] - z) < d) {
        d = std::abs(roots[i] - z);
        best = i;
      }
    if (roots.empty()) return {};
    out.push_back(roots[best]);
    roots.erase(roots.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return out;
}

void regionsOf(const std::function<std::vector<std::complex<double>>(const Eigen::VectorXd&)>& roots,
               const Eigen::VectorXd& theta, const Eigen::MatrixXd& P, bool zero, double r2,
               std::vector<RootRegion>& out) {
  const std::vector<std::complex<double>> nominal = roots(theta);
  const Eigen::Index p = theta.size();
  std::vector<Eigen::MatrixXd> J(nominal.size(), Eigen::MatrixXd::Zero(2, p));
  for (Eigen::Index i = 0; i < p; ++i) {
    const double h = std::max(1e-4 * std::sqrt(std::max(P(i, i), 0.0)), 1e-10 * std::max(std::abs(theta[i]), 1e-12));
    Eigen::VectorXd a = theta, b = theta;
    a[i] += h;
    b[i] -= h;
    const auto ra = matched(nominal, roots(a)), rb = matched(nominal, roots(b));
    if (ra.size() != nominal.size() || rb.size() != nominal.size()) return;
    for (std::size_t k = 0; k < nominal.size(); ++k) {
      const std::complex<double> d = (ra[k] - rb[k]) / (2.0 * h);
      J[k](0, i) = d.real();
      J[k](1, i) = d.imag();
    }
  }
  for (std::size_t k = 0; k < nominal.size(); ++k) {
    RootRegion r;
    r.value = nominal[k];
    r.zero = zero;
    r.radiusSquared = r2;
    r.covariance = J[k] * P * J[k].transpose();
    if (r.covariance.allFinite()) out.push_back(r);
  }
}

}  // namespace

std::vector<RootRegion> poleZeroRegions(const PhysicalModel* physical, const Eigen::MatrixXd& covariance,
                                        const std::vector<int>& freeIndices, const PolynomialModel* polynomial,
                                        double level) {
  if ((physical == nullptr) == (polynomial == nullptr))
    throw std::invalid_argument("poleZeroRegions: give exactly one of a physical and a polynomial model");
  if (!(level > 0.0 && level < 1.0)) throw std::invalid_argument("poleZeroRegions: the level must be in (0, 1)");
  const double r2 = -2.0 * std::log(1.0 - level);
  std::vector<RootRegion> out;
  if (polynomial) {
    const PolynomialModel& m = *polynomial;
    if (m.covariance.rows() != m.orders.parameters() || m.covariance.size() == 0) return out;
    auto with = [&](const Eigen::VectorXd& th) {
      PolynomialModel w = m;
      w.setParameterVector(th);
      return w;
    };
    regionsOf([&](const Eigen::VectorXd& th) { const auto w = with(th); return polyRoots(polyMultiply(w.a, w.f)); },
              m.parameterVector(), m.covariance, false, r2, out);
    regionsOf([&](const Eigen::VectorXd& th) { return polyRoots(with(th).b); }, m.parameterVector(), m.covariance,
              true, r2, out);
    return out;
  }
  const auto n = static_cast<Eigen::Index>(freeIndices.size());
  if (n == 0 || covariance.rows() != n || covariance.cols() != n) return out;
  const auto& params = physical->parameters();
  Eigen::VectorXd theta(n);
  for (Eigen::Index i = 0; i < n; ++i) theta[i] = params.at(static_cast<std::size_t>(freeIndices[static_cast<std::size_t>(i)])).value;
  std::unique_ptr<ParametricModel> work = physical->clone();
  auto system = [&](const Eigen::VectorXd& th) {
    for (Eigen::Index i = 0; i < n; ++i)
      work->setParameter(params[static_cast<std::size_t>(freeIndices[static_cast<std::size_t>(i)])].name, th[i]);
    return work->stateSpace();
  };
  regionsOf([&](const Eigen::VectorXd& th) { return poles(system(th)); }, theta, covariance, false, r2, out);
  regionsOf([&](const Eigen::VectorXd& th) { return zeros(system(th)); }, theta, covariance, true, r2, out);
  return out;
}

}  // namespace flexarm
