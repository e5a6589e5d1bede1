#include "core/ident/transient.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <stdexcept>

#include "core/ident/pem.h"
#include "core/ident/polynomial.h"
#include "core/ident/evaluation.h"

namespace flexarm {

const char* toString(TransientKind k) { return k == TransientKind::Step ? "step" : "impulse"; }

namespace {

constexpr int kMinSamples = 50, kMaxSamples = 4000;

// Samples until the slowest stable discrete pole z has decayed to 1 %, within the limits.
int settlingSamples(const std::vector<std::complex<double>>& poles) {
  double slowest = 0.0;  // largest |z| below 1
  for (const auto& z : poles) {
    const double r = std::abs(z);
    if (r < 1.0 - 1e-9) slowest = std::max(slowest, r);
  }
  if (slowest <= 0.0) return kMinSamples;
  const double k = std::log(0.01) / std::log(slowest);
  return static_cast<int>(std::clamp(k, static_cast<double>(kMinSamples), static_cast<double>(kMaxSamples)));
}

Eigen::VectorXd input(TransientKind kind, int n, double T) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  if (kind == TransientKind::Step) u.setOnes();
  else u[0] = 1.0 / T;
  return u;
}

// y(t) for a response function of the parameters, with the band from P by central differences.
void withBand(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& response, const Eigen::VectorXd& theta,
              const Eigen::MatrixXd& P, double level, TransientResponse& out) {
  const Eigen::VectorXd y = response(theta);
  out.value.assign(y.data(), y.data() + y.size());
  const Eigen::Index p = theta.size();
  if (P.rows() != p || P.cols() != p || p == 0 || !P.allFinite()) return;
  Eigen::MatrixXd J(y.size(), p);
  for (Eigen::Index i = 0; i < p; ++i) {
    // A step of a fraction of the parameter's own spread: small against what the data allow.
    const double h = std::max(1e-3 * std::sqrt(std::max(P(i, i), 0.0)), 1e-9 * std::max(std::abs(theta[i]), 1e-12));
    Eigen::VectorXd a = theta, b = theta;
    a[i] += h;
    b[i] -= h;
    J.col(i) = (response(a) - response(b)) / (2.0 * h);
  }
  if (!J.allFinite()) return;
  const double z = twoSidedNormalQuantile(level);
  const Eigen::VectorXd var = ((J * P).cwiseProduct(J)).rowwise().sum();
  out.lower.resize(out.value.size());
  out.upper.resize(out.value.size());
  for (std::size_t t = 0; t < out.value.size(); ++t) {
    const double s = std::sqrt(std::max(var[static_cast<Eigen::Index>(t)], 0.0));
    out.lower[t] = out.value[t] - z * s;
    out.upper[t] = out.value[t] + z * s;
  }
}

}  // namespace

TransientResponse transientResponse(const PhysicalModel* physical, const Eigen::MatrixXd& covariance,
                                    const std::vector<int>& freeIndices, const PolynomialModel* polynomial,
                                    TransientKind kind, double sampleTime, double level, int samples) {
  if ((physical == nullptr) == (polynomial == nullptr))
    throw std::invalid_argument("transientResponse: give exactly one of a physical and a polynomial model");
  TransientResponse out;
  out.kind = kind;
  out.level = level;
  if (polynomial) {
    const PolynomialModel& m = *polynomial;
    const double T = m.sampleTime;
    if (!(T > 0.0)) throw std::invalid_argument("transientResponse: the model's sample time must be positive");
    out.sampleTime = T;
    const Poly den = polyMultiply(m.a, m.f);
    const int n = samples > 0 ? samples : settlingSamples(polyRoots(den));
    const Eigen::VectorXd u = input(kind, n, T);
    auto response = [&](const Eigen::VectorXd& th) {
      PolynomialModel w = m;
      w.setParameterVector(th);
      return filter(w.b, polyMultiply(w.a, w.f), u);
    };
    withBand(response, m.parameterVector(), m.covariance, level, out);
  } else {
    if (!(sampleTime > 0.0)) throw std::invalid_argument("transientResponse: the sample time must be positive");
    out.sampleTime = sampleTime;
    const StateSpace d = discretizeZoh(physical->stateSpace(), sampleTime);
    std::vector<std::complex<double>> poles;
    Eigen::EigenSolver<Eigen::MatrixXd> es(d.A, false);
    for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) poles.push_back(es.eigenvalues()[i]);
    const int n = samples > 0 ? samples : settlingSamples(poles);
    const Eigen::VectorXd u = input(kind, n, sampleTime);
    Eigen::VectorXd theta(static_cast<Eigen::Index>(freeIndices.size()));
    const auto& params = physical->parameters();
    for (std::size_t i = 0; i < freeIndices.size(); ++i)
      theta[static_cast<Eigen::Index>(i)] = params.at(static_cast<std::size_t>(freeIndices[i])).value;
    std::unique_ptr<ParametricModel> work = physical->clone();
    auto response = [&](const Eigen::VectorXd& th) {
      for (std::size_t i = 0; i < freeIndices.size(); ++i)
        work->setParameter(params[static_cast<std::size_t>(freeIndices[i])].name, th[static_cast<Eigen::Index>(i)]);
      return simulate(*work, u, sampleTime);
    };
    withBand(response, theta, covariance, level, out);
  }
  for (std::size_t t = 0; t < out.value.size(); ++t) out.time.push_back(static_cast<double>(t) * out.sampleTime);
  return out;
}

}  // namespace flexarm
