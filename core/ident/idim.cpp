#include "core/ident/idim.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <stdexcept>

#include "core/ident/evaluation.h"
#include "core/signal/fir_design.h"
#include "core/signal/preprocess.h"

namespace flexarm {

const char* toString(IdimFriction f) { return f == IdimFriction::Asymmetric ? "asymmetric" : "symmetric"; }

bool IdimOptions::isValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(cutoffHz >= 0.0) || !std::isfinite(cutoffHz)) return fail("the cut-off must be a finite frequency >= 0");
  if (filterOrder < 2 || filterOrder > 12 || filterOrder % 2) return fail("the filter order must be even, 2 to 12");
  if (decimation < 0 || decimation > 1000) return fail("the decimation must be 0 (automatic) to 1000");
  if (!(edgeSeconds >= 0.0) || !std::isfinite(edgeSeconds)) return fail("the edge must be a finite time >= 0");
  if (!(level > 0.0 && level < 1.0)) return fail("the level must lie strictly between 0 and 1");
  return true;
}

std::optional<double> IdimResult::value(const std::string& name) const {
  for (const auto& p : parameters)
    if (p.name == name) return p.value;
  return std::nullopt;
}

std::vector<double> butterworthFiltFilt(const std::vector<double>& x, int order, double cutoff) {
  if (!(cutoff > 0.0 && cutoff < 0.5) || order < 2 || order % 2)
    throw std::invalid_argument("butterworthFiltFilt: need an even order and 0 < cutoff < 0.5");
  // Analog prototype poles exp(i pi (2k + n + 1) / (2n)), k = 0..n/2-1 (one of each conjugate
  // pair), scaled to the prewarped cut-off and mapped by the bilinear transform (T = 1).
  const double wc = 2.0 * std::tan(M_PI * cutoff);
  std::vector<Biquad> sections;
  for (int k = 0; k < order / 2; ++k) {
    const double theta = M_PI * (2.0 * k + order + 1.0) / (2.0 * order);
    const std::complex<double> pa = wc * std::complex<double>(std::cos(theta), std::sin(theta));
    const double w2 = std::norm(pa), c = -2.0 * pa.real();
    const double a0 = 4.0 + 2.0 * c + w2;
    sections.push_back({w2 / a0, 2.0 * w2 / a0, w2 / a0, (2.0 * w2 - 8.0) / a0, (4.0 - 2.0 * c + w2) / a0});
  }
  // Odd reflection at both ends, long enough for the filter's transient to die out.
  const std::size_t n = x.size();
  if (n < 2) return x;
  const std::size_t pad = std::min(n - 1, static_cast<std::size_t>(std::ceil(3.0 * order / cutoff)));
  std::vector<double> y(n + 2 * pad);
  for (std::size_t i = 0; i < pad; ++i) {
    y[pad - 1 - i] = 2.0 * x[0] - x[i + 1];
    y[pad + n + i] = 2.0 * x[n - 1] - x[n - 2 - i];
  }
  std::copy(x.begin(), x.end(), y.begin() + static_cast<std::ptrdiff_t>(pad));
  runBiquads(sections, y);
  std::reverse(y.begin(), y.end());
  runBiquads(sections, y);
  std::reverse(y.begin(), y.end());
  return std::vector<double>(y.begin() + static_cast<std::ptrdiff_t>(pad),
                             y.begin() + static_cast<std::ptrdiff_t>(pad + n));
}

namespace {

std::string format(const char* pattern, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, pattern, v);
  return buf;
}

// The regressors of the inverse dynamic model from a position: filtered, differentiated, the
// columns in the order of the parameters.
std::vector<std::vector<double>> regressors(const Eigen::VectorXd& q, double Ts, const IdimOptions& o,
                                            double cutoff) {
  const std::vector<double> raw(q.data(), q.data() + q.size());
  const std::vector<double> qf = butterworthFiltFilt(raw, o.filterOrder, cutoff * Ts);
  const std::vector<double> v = differentiate(qf, Ts), a = differentiate(v, Ts);
  const std::size_t n = v.size();
  std::vector<std::vector<double>> cols;
  cols.push_back(a);
  if (o.friction == IdimFriction::Symmetric) {
    std::vector<double> sign(n), one(n, 1.0);
    for (std::size_t k = 0; k < n; ++k) sign[k] = (v[k] > 0.0) - (v[k] < 0.0);
    cols.push_back(v);
    cols.push_back(sign);
    cols.push_back(one);
  } else {
    std::vector<double> vp(n), vn(n), sp(n), sn(n);
    for (std::size_t k = 0; k < n; ++k) {
      vp[k] = v[k] > 0.0 ? v[k] : 0.0;
      vn[k] = v[k] < 0.0 ? v[k] : 0.0;
      sp[k] = v[k] > 0.0 ? 1.0 : 0.0;
      sn[k] = v[k] < 0.0 ? -1.0 : 0.0;
    }
    for (auto* c : {&vp, &vn, &sp, &sn}) cols.push_back(std::move(*c));
  }
  if (o.heldTorque)
    for (auto& c : cols)
      for (std::size_t k = 0; k + 1 < n; ++k) c[k] = 0.5 * (c[k] + c[k + 1]);
  return cols;
}

// Parallel filtering and decimation of columns, then the kept rows [edge, n - edge).
Eigen::MatrixXd parallel(const std::vector<std::vector<double>>& cols, int factor, std::size_t edge) {
  std::vector<std::vector<double>> out;
  for (const auto& c : cols) {
    if (factor > 1) {
      DecimateOptions d;
      d.factor = factor;
      out.push_back(decimate(c, d));
    } else {
      out.push_back(c);
    }
  }
  const std::size_t n = out.front().size();
  const std::size_t rows = n > 2 * edge ? n - 2 * edge : 0;
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(out.size()));
  for (std::size_t j = 0; j < out.size(); ++j)
    for (std::size_t i = 0; i < rows; ++i) m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = out[j][i + edge];
  return m;
}

}  // namespace

IdimResult idim(const Eigen::VectorXd& q, const Eigen::VectorXd& tau, double Ts, const IdimOptions& o,
                const Eigen::VectorXd& reference) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("idim: " + why);
  if (q.size() != tau.size()) throw std::invalid_argument("idim: the position and the torque differ in length");
  if (!(Ts > 0.0) || !std::isfinite(Ts)) throw std::invalid_argument("idim: the sample time must be positive");
  if (o.instrumentalVariables && reference.size() != q.size())
    throw std::invalid_argument("idim: instrumental variables need a reference as long as the position");
  IdimResult r;
  auto fail = [&r](std::string text) {
    r.termination = Termination::Failed;
    r.message = std::move(text);
    return r;
  };
  if (!q.allFinite() || !tau.allFinite() || (o.instrumentalVariables && !reference.allFinite()))
    return fail("the position or the torque holds a value that is not finite");
  const double nyquist = 0.5 / Ts;
  r.cutoffHz = o.cutoffHz > 0.0 ? o.cutoffHz : nyquist / 10.0;
  if (r.cutoffHz >= 0.9 * nyquist)
    return fail("the cut-off " + format("%g", r.cutoffHz) + " Hz lies too close to the Nyquist frequency " +
                format("%g", nyquist) + " Hz");
  // The parallel low-pass (the decimator's, flat to 0.8 of its new Nyquist frequency) keeps
  // the band below half the position's cut-off, where the differentiated position is exact.
  r.decimation = o.decimation > 0 ? o.decimation
                                  : std::max(1, static_cast<int>(std::ceil(1.6 * nyquist / r.cutoffHz - 1e-9)));
  const double edgeSeconds = o.edgeSeconds > 0.0 ? o.edgeSeconds : 4.0 / r.cutoffHz;
  const auto edge = static_cast<std::size_t>(std::ceil(edgeSeconds / (Ts * r.decimation)));
  const std::size_t p = o.friction == IdimFriction::Symmetric ? 4 : 5;
  const std::size_t kept = static_cast<std::size_t>(q.size()) / static_cast<std::size_t>(r.decimation);
  if (kept < 2 * edge + 4 * p)
    return fail("the log holds too few samples (" + std::to_string(q.size()) + ") for the filters' transients at a " +
                format("%g", r.cutoffHz) + " Hz cut-off");

  const Eigen::MatrixXd Phi = parallel(regressors(q, Ts, o, r.cutoffHz), r.decimation, edge);
  const std::vector<double> t(tau.data(), tau.data() + tau.size());
  const Eigen::VectorXd y = parallel({t}, r.decimation, edge).col(0);
  r.samples = static_cast<int>(Phi.rows());
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Phi);
  const Eigen::VectorXd sv = svd.singularValues();
  r.conditionNumber = sv[sv.size() - 1] > 0.0 ? sv[0] / sv[sv.size() - 1] : INFINITY;
  if (!(r.conditionNumber < 1e10))
    return fail("the motion does not excite every parameter (the observation matrix has rank " +
                std::to_string(svd.setThreshold(1e-10).rank()) + " of " + std::to_string(p) +
                "): the axis must accelerate and move both ways");

  Eigen::VectorXd theta;
  Eigen::MatrixXd cov;
  const double dof = std::max(1.0, static_cast<double>(Phi.rows()) - static_cast<double>(p));
  if (o.instrumentalVariables) {
    const Eigen::MatrixXd Z = parallel(regressors(reference, Ts, o, r.cutoffHz), r.decimation, edge);
    const Eigen::MatrixXd ZtPhi = Z.transpose() * Phi;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(ZtPhi);
    if (!lu.isInvertible()) return fail("the reference does not excite every parameter (Z^T Phi is singular)");
    theta = lu.solve(Z.transpose() * y);
    const double s2 = (y - Phi * theta).squaredNorm() / dof;
    const Eigen::MatrixXd inv = lu.inverse();
    cov = s2 * inv * (Z.transpose() * Z) * inv.transpose();
  } else {
    theta = Phi.colPivHouseholderQr().solve(y);
    const double s2 = (y - Phi * theta).squaredNorm() / dof;
    cov = s2 * (Phi.transpose() * Phi).inverse();
  }
  r.covariance = cov;
  r.torque = y;
  r.predicted = Phi * theta;
  r.time.resize(Phi.rows());
  for (Eigen::Index i = 0; i < Phi.rows(); ++i)
    r.time[i] = static_cast<double>((static_cast<std::size_t>(i) + edge) * static_cast<std::size_t>(r.decimation)) * Ts;
  r.relativeError = 100.0 * (y - r.predicted).norm() / y.norm();
  r.torqueFitPercent = fitPercent(y, r.predicted);

  const bool lin = o.prismatic;
  const std::string force = lin ? "N" : "N m", speed = lin ? "N s/m" : "N m s/rad";
  std::vector<std::pair<std::string, std::string>> names = {{lin ? "M" : "J", lin ? "kg" : "kg m^2"}};
  if (o.friction == IdimFriction::Symmetric) {
    names.insert(names.end(), {{"F_v", speed}, {"F_c", force}, {"offset", force}});
  } else {
    names.insert(names.end(), {{"F_v+", speed}, {"F_v-", speed}, {"F_c+", force}, {"F_c-", force}});
  }
  const double z = twoSidedNormalQuantile(o.level);
  for (std::size_t i = 0; i < p; ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const double s = std::sqrt(std::max(0.0, cov(k, k)));
    r.parameters.push_back({names[i].first, names[i].second, theta[k], s, theta[k] - z * s, theta[k] + z * s});
  }
  if (!(theta[0] > 0.0))
    return fail("the inertia came out " + format("%g", theta[0]) +
                ", not positive: the data do not hold enough acceleration below the cut-off " +
                format("%g", r.cutoffHz) + " Hz");
  r.termination = Termination::Converged;
  r.message = std::string(o.instrumentalVariables ? "IDIM-IV" : "IDIM-LS") + " on " + std::to_string(r.samples) +
              " samples (position low-passed at " + format("%g", r.cutoffHz) + " Hz, decimated by " +
              std::to_string(r.decimation) + "): relative error " + format("%.2f", r.relativeError) + " %";
  return r;
}

}  // namespace flexarm
