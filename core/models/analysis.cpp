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
