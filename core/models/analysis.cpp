#include "core/models/analysis.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

namespace flexarm {

namespace {

void checkPair(const StateSpace& sys, int output, int input, const char* who) {
  std::string why;
  if (!sys.isValid(&why)) throw std::invalid_argument(std::string(who) + ": " + why);
  if (output < 0 || output >= sys.outputs() || input < 0 || input >= sys.inputs())
    throw std::invalid_argument(std::string(who) + ": output " + std::to_string(output) +
                                " / input " + std::to_string(input) + " out of range");
}

std::vector<std::complex<double>> eigenvalues(const Eigen::MatrixXd& M) {
  std::vector<std::complex<double>> out;
  if (M.rows() == 0) return out;
  Eigen::EigenSolver<Eigen::MatrixXd> es(M, false);
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) out.push_back(es.eigenvalues()(i));
  return out;
}

// Zeros and high-frequency gain of one pair (see zeros()).
struct ZeroData {
  std::vector<std::complex<double>> zeros;
  double gain = 0.0;
};

ZeroData zeroData(const StateSpace& sys, int output, int input) {
  const Eigen::VectorXd b = sys.B.col(input);
  const Eigen::RowVectorXd c = sys.C.row(output);
  const double d = sys.D(output, input);
  const int n = sys.states();
  ZeroData z;
  const double scaleA = std::max(sys.A.norm(), 1e-300);
  const double scaleBC = b.norm() * c.norm();
  if (d != 0.0) {
    z.gain = d;
    z.zeros = eigenvalues(sys.A - b * c / d);
    return z;
  }
  // Relative degree k: the first nonzero Markov parameter c A^(k-1) b.
  Eigen::MatrixXd O(n, n);
  Eigen::RowVectorXd cAj = c;
  int k = 0;
  double markov = 0.0;
  for (int j = 0; j < n; ++j) {
    O.row(j) = cAj;
    const double m = cAj.dot(b);
    if (std::abs(m) > 1e-11 * scaleBC * std::pow(scaleA, j)) {
      k = j + 1;
      markov = m;
      break;
    }
    cAj = cAj * sys.A;
  }
  if (k == 0) return z;  // zero transfer function
  z.gain = markov;
  const Eigen::RowVectorXd cAk = cAj * sys.A;
  const Eigen::MatrixXd Acl = sys.A - b * (cAk / markov);
  if (k == n) return z;
  // Orthonormal basis of the kernel of O(0:k-1): the last n-k columns of Q in O^T = QR.
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(O.topRows(k).transpose());
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd N = Q.rightCols(n - k);
  z.zeros = eigenvalues(N.transpose() * Acl * N);
  return z;
}

}  // namespace

std::complex<double> TransferFunction::operator()(std::complex<double> s) const {
  auto eval = [s](const std::vector<double>& p) {
    std::complex<double> v = 0.0;
    for (double c : p) v = v * s + c;
    return v;
  };
  return eval(num) / eval(den);
}

std::vector<double> polynomialFromRoots(const std::vector<std::complex<double>>& roots) {
  std::vector<std::complex<double>> p = {1.0};
  for (const auto& r : roots) {
    p.push_back(0.0);
    for (std::size_t i = p.size() - 1; i > 0; --i) p[i] -= r * p[i - 1];
  }
  std::vector<double> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = p[i].real();
  return out;
}

TransferFunction transferFunction(const StateSpace& sys, int output, int input) {
  checkPair(sys, output, input, "transferFunction");
  TransferFunction tf;
  tf.den = polynomialFromRoots(poles(sys));
  const ZeroData z = zeroData(sys, output, input);
  if (z.gain == 0.0) {
    tf.num = {0.0};
    return tf;
  }
  tf.num = polynomialFromRoots(z.zeros);
  for (double& c : tf.num) c *= z.gain;
  return tf;
}

std::vector<std::complex<double>> frequencyResponse(const StateSpace& sys,
                                                    const std::vector<double>& omega,
                                                    int output, int input) {
  checkPair(sys, output, input, "frequencyResponse");
  const int n = sys.states();
  const Eigen::MatrixXcd A = sys.A.cast<std::complex<double>>();
  const Eigen::VectorXcd b = sys.B.col(input).cast<std::complex<double>>();
  const Eigen::RowVectorXcd c = sys.C.row(output).cast<std::complex<double>>();
  std::vector<std::complex<double>> out;
  out.reserve(omega.size());
  for (double w : omega) {
    const std::complex<double> s = sys.isDiscrete()
                                       ? std::exp(std::complex<double>(0.0, w * sys.sampleTime))
                                       : std::complex<double>(0.0, w);
    Eigen::MatrixXcd M = -A;
    M.diagonal().array() += s;
    const Eigen::VectorXcd x = M.partialPivLu().solve(b);
    std::complex<double> y = sys.D(output, input);
    if (n > 0) y += (c * x)(0);
    out.push_back(y);
  }
  return out;
}

std::vector<std::complex<double>> poles(const StateSpace& sys) {
  std::string why;
  if (!sys.isValid(&why)) throw std::invalid_argument("poles: " + why);
  return eigenvalues(sys.A);
}

std::vector<std::complex<double>> zeros(const StateSpace& sys, int output, int input) {
  checkPair(sys, output, input, "zeros");
  return zeroData(sys, output, input).zeros;
}

std::vector<Mode> lightlyDamped(const std::vector<std::complex<double>>& roots,
                                double maxDamping) {
  std::vector<Mode> out;
  for (const auto& r : roots) {
    if (r.imag() <= 0.0) continue;
    const double wn = std::abs(r);
    const double zeta = -r.real() / wn;
    if (std::abs(zeta) < maxDamping) out.push_back({r.imag(), wn, zeta});
  }
  std::sort(out.begin(), out.end(),
            [](const Mode& a, const Mode& b) { return a.frequency < b.frequency; });
  return out;
}

std::vector<Mode> notchFrequencies(const StateSpace& sys, int output, int input,
                                   double maxDamping) {
  return lightlyDamped(zeros(sys, output, input), maxDamping);
}

std::vector<Mode> peakFrequencies(const StateSpace& sys, double maxDamping) {
  return lightlyDamped(poles(sys), maxDamping);
}

NotchesPeaks magnitudeExtrema(const std::vector<double>& omega, const std::vector<double>& magnitude,
                              double minDepthDb, const std::function<double(double)>& exact) {
  if (omega.size() != magnitude.size())
    throw std::invalid_argument("magnitudeExtrema: omega and magnitude differ in length");
  NotchesPeaks out;
  const std::size_t n = magnitude.size();
  if (n < 3) return out;
  auto toDb = [](double m) { return 20.0 * std::log10(std::max(m, 1e-300)); };
  std::vector<double> db(n);
  for (std::size_t i = 0; i < n; ++i) db[i] = toDb(magnitude[i]);
  // Indices of all strict local extrema, with the ends as anchors.
  std::vector<std::size_t> ext{0};
  for (std::size_t i = 1; i + 1 < n; ++i)
    if ((db[i] < db[i - 1] && db[i] <= db[i + 1]) || (db[i] > db[i - 1] && db[i] >= db[i + 1]))
      ext.push_back(i);
  ext.push_back(n - 1);
  auto refine = [&](std::size_t i, bool isMin) {
    const double x0 = std::log(omega[i - 1]), x1 = std::log(omega[i]), x2 = std::log(omega[i + 1]);
    if (exact) {
      // Golden-section search of the extremum of |G| in dB over log-frequency in [x0, x2].
      const double sign = isMin ? 1.0 : -1.0;
      auto f = [&](double x) { return sign * toDb(exact(std::exp(x))); };
      const double g = 0.5 * (std::sqrt(5.0) - 1.0);
      double a = x0, b = x2, c = b - g * (b - a), d = a + g * (b - a);
      double fc = f(c), fd = f(d);
      while (b - a > 1e-10) {
        if (fc < fd) {
          b = d; d = c; fd = fc; c = b - g * (b - a); fc = f(c);
        } else {
          a = c; c = d; fc = fd; d = a + g * (b - a); fd = f(d);
        }
      }
      return std::exp(0.5 * (a + b));
    }
    // Parabola through three points in log-frequency.
    const double y0 = db[i - 1], y1 = db[i], y2 = db[i + 1];
    const double den = (x0 - x1) * (x0 - x2) * (x1 - x2);
    const double a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den;
    const double b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den;
    if (a == 0.0) return omega[i];
    const double xv = std::clamp(-b / (2 * a), std::min(x0, x2), std::max(x0, x2));
    return std::exp(xv);
  };
  for (std::size_t k = 1; k + 1 < ext.size(); ++k) {
    const std::size_t i = ext[k];
    double left = db[ext[k - 1]], right = db[ext[k + 1]];
    // Compare with the highest/lowest value on each side up to the next extremum of the
    // same kind, so that ripples do not hide a real notch.
    const bool isMin = db[i] < db[i - 1];
    for (std::size_t j = ext[k - 1]; j < i; ++j)
      left = isMin ? std::max(left, db[j]) : std::min(left, db[j]);
    for (std::size_t j = i + 1; j <= ext[k + 1]; ++j)
      right = isMin ? std::max(right, db[j]) : std::min(right, db[j]);
    if (isMin && left - db[i] >= minDepthDb && right - db[i] >= minDepthDb)
      out.notches.push_back(refine(i, true));
    if (!isMin && db[i] - left >= minDepthDb && db[i] - right >= minDepthDb)
      out.peaks.push_back(refine(i, false));
  }
  return out;
}

NotchesPeaks notchesAndPeaks(const StateSpace& sys, int output, int input, double minDepthDb) {
  if (sys.isDiscrete()) throw std::invalid_argument("notchesAndPeaks: the model must be continuous");
  double lo = INFINITY, hi = 0.0;
  auto span = [&](const std::vector<std::complex<double>>& roots) {
    for (const auto& r : roots) {
      const double m = std::abs(r);
      if (m > 1e-9 && std::isfinite(m)) {
        lo = std::min(lo, m);
        hi = std::max(hi, m);
      }
    }
  };
  span(poles(sys));
  span(zeros(sys, output, input));
  if (!(hi > 0.0)) return {};
  const int points = 4000;
  std::vector<double> w(points);
  const double w0 = 0.1 * lo, w1 = 10.0 * hi;
  for (int i = 0; i < points; ++i) w[i] = w0 * std::pow(w1 / w0, static_cast<double>(i) / (points - 1));
  const auto g = frequencyResponse(sys, w, output, input);
  std::vector<double> mag(points);
  for (int i = 0; i < points; ++i) mag[i] = std::abs(g[i]);
  return magnitudeExtrema(w, mag, minDepthDb, [&](double x) {
    return std::abs(frequencyResponse(sys, std::vector<double>{x}, output, input).front());
  });
}

const char* toString(Discretization d) {
  return d == Discretization::FirstOrderHold ? "foh" : "zoh";
}

std::optional<Discretization> discretizationFromString(std::string_view s) {
  for (Discretization d : {Discretization::ZeroOrderHold, Discretization::FirstOrderHold})
    if (s == toString(d)) return d;
  return std::nullopt;
}

StateSpace discretize(const StateSpace& sys, double T, Discretization method) {
  std::string why;
  if (!sys.isValid(&why)) throw std::invalid_argument("discretize: " + why);
  if (sys.isDiscrete()) throw std::invalid_argument("discretize: the model is discrete already");
  if (!(T > 0.0) || !std::isfinite(T))
    throw std::invalid_argument("discretize: the sample time must be positive");
  const int n = sys.states(), m = sys.inputs();
  StateSpace d;
  d.sampleTime = T;
  d.C = sys.C;
  if (method == Discretization::ZeroOrderHold) {
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
    M.topLeftCorner(n, n) = sys.A * T;
    M.topRightCorner(n, m) = sys.B * T;
    const Eigen::MatrixXd E = M.exp();
    d.A = E.topLeftCorner(n, n);
    d.B = E.topRightCorner(n, m);
    d.D = sys.D;
    return d;
  }
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 2 * m, n + 2 * m);
  M.block(0, 0, n, n) = sys.A * T;
  M.block(0, n, n, m) = sys.B * T;
  M.block(n, n + m, m, m) = Eigen::MatrixXd::Identity(m, m);  // (I/T) T
  const Eigen::MatrixXd E = M.exp();
  const Eigen::MatrixXd Phi = E.block(0, 0, n, n);
  const Eigen::MatrixXd G1 = E.block(0, n, n, m);
  const Eigen::MatrixXd G2 = E.block(0, n + m, n, m);
  d.A = Phi;
  d.B = G1 + (Phi - Eigen::MatrixXd::Identity(n, n)) * G2;
  d.D = sys.D + sys.C * G2;
  return d;
}

}  // namespace flexarm
