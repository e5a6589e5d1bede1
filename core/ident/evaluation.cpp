#include "core/ident/evaluation.h"

#include "core/common/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexarm {

Eigen::VectorXd simulate(const PolynomialModel& m, const Eigen::VectorXd& u) {
  return filter(m.b, polyMultiply(m.a, m.f), u);
}

Eigen::VectorXd predict(const PolynomialModel& m, const Eigen::VectorXd& u,
                        const Eigen::VectorXd& y, int k) {
  if (u.size() != y.size())
    throw std::invalid_argument("predict: input and output must have the same length");
  if (k <= 0) return simulate(m, u);
  // H = C/(D A); Hbar_k = first k impulse-response coefficients of H; the k-step predictor is
  // Hbar_k H^{-1} G u + (1 - Hbar_k H^{-1}) y with H^{-1} G = D B / (C F).
  Eigen::VectorXd imp = Eigen::VectorXd::Zero(k);
  imp[0] = 1.0;
  const Eigen::VectorXd h = filter(m.c, polyMultiply(m.d, m.a), imp);
  Poly hbar(h.data(), h.data() + k);
  const Poly num = polyMultiply(hbar, m.d);
  const Eigen::VectorXd gu = filter(m.b, m.f, u);
  return filter(num, m.c, gu) + y - filter(polyMultiply(num, m.a), m.c, y);
}

FitPercents fitPercentsFromSums(double squaredErrors, double squaredDeviations) {
  if (!(squaredDeviations > 0.0)) return {-INFINITY, -INFINITY};
  const double ratio = squaredErrors / squaredDeviations;
  return {(1.0 - ratio) * 100.0, (1.0 - std::sqrt(ratio)) * 100.0};
}

FitPercents fitPercents(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, Eigen::Index begin,
                        Eigen::Index end) {
  if (y.size() != yhat.size())
    throw std::invalid_argument("fitPercent: signals of different length");
  if (end == 0) end = y.size();
  if (begin < 0 || end > y.size() || end - begin < 2)
    throw std::invalid_argument("fitPercent: range outside the data or shorter than 2 samples");
  const auto ys = y.segment(begin, end - begin);
  const auto es = ys - yhat.segment(begin, end - begin);
  return fitPercentsFromSums(es.squaredNorm(), (ys.array() - ys.mean()).square().sum());
}

double fitPercent(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, Eigen::Index begin,
                  Eigen::Index end) {
  return fitPercents(y, yhat, begin, end).seed52;
}

double twoSidedNormalQuantile(double level) {
  if (!(level > 0.0 && level < 1.0))
    throw std::invalid_argument("confidence level must lie strictly between 0 and 1");
  // Bisection on erf(z / sqrt 2) = level.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erf(mid / std::sqrt(2.0)) < level ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::vector<double> logGrid(double wMin, double wMax, int n) {
  if (!(wMin > 0.0) || !(wMax > wMin) || n < 2)
    throw std::invalid_argument("logGrid: need 0 < wMin < wMax and n >= 2");
  std::vector<double> w(n);
  for (int i = 0; i < n; ++i)
    w[i] = wMin * std::pow(wMax / wMin, static_cast<double>(i) / (n - 1));
  return w;
}

void finishFrequencyResponse(FrequencyResponse& r, const std::vector<Eigen::Matrix2d>& cov) {
  const std::size_t n = r.value.size();
  r.magnitude.resize(n);
  r.phase.resize(n);
  // Magnitude and principal phase of every value (a dense grid of an ETFE has tens of
  // thousands: split over the cores); |G| as sqrt(re^2 + im^2) where that cannot overflow or
  // underflow, else by hypot's careful scaling.
  parallelRanges(n, threadsFor(n, 8192), [&](std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; ++i) {
      const double re = r.value[i].real(), im = r.value[i].imag();
      const double sq = re * re + im * im;
      r.magnitude[i] = std::isnormal(sq) && sq < 1e300 ? std::sqrt(sq) : std::abs(r.value[i]);
      r.phase[i] = std::atan2(im, re);
    }
  });
  // Unwrapped: consecutive phases differ by at most pi.
  double offset = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double ph = r.phase[i] + offset;
    if (i > 0) {
      while (ph - r.phase[i - 1] > M_PI) { ph -= 2 * M_PI; offset -= 2 * M_PI; }
      while (ph - r.phase[i - 1] < -M_PI) { ph += 2 * M_PI; offset += 2 * M_PI; }
    }
    r.phase[i] = ph;
  }
  r.magnitudeStd.clear();
  r.phaseStd.clear();
  r.magnitudeLower.clear();
  r.magnitudeUpper.clear();
  r.phaseLower.clear();
  r.phaseUpper.clear();
  if (cov.empty()) return;
  const double z = twoSidedNormalQuantile(r.level);
  for (std::size_t i = 0; i < n; ++i) {
    const double re = r.value[i].real(), im = r.value[i].imag();
    const double mag = std::max(r.magnitude[i], 1e-300);
    // d|G| = (re dRe + im dIm)/|G|, dphase = (re dIm - im dRe)/|G|^2.
    const Eigen::Vector2d jm(re / mag, im / mag);
    const Eigen::Vector2d jp(-im / (mag * mag), re / (mag * mag));
    const double sm = std::sqrt(std::max(0.0, jm.dot(cov[i] * jm)));
    const double sp = std::sqrt(std::max(0.0, jp.dot(cov[i] * jp)));
    r.magnitudeStd.push_back(sm);
    r.phaseStd.push_back(sp);
    r.magnitudeLower.push_back(std::max(0.0, r.magnitude[i] - z * sm));
    r.magnitudeUpper.push_back(r.magnitude[i] + z * sm);
    r.phaseLower.push_back(r.phase[i] - z * sp);
    r.phaseUpper.push_back(r.phase[i] + z * sp);
  }
}

FrequencyResponse frequencyResponse(const PolynomialModel& m, const std::vector<double>& omega,
                                    double level) {
  FrequencyResponse r;
  r.omega = omega;
  r.level = level;
  twoSidedNormalQuantile(level);
  const auto& o = m.orders;
  const int p = o.parameters();
  const bool bands = m.covariance.rows() == p && p > 0;
  std::vector<Eigen::Matrix2d> cov;
  for (double w : omega) {
    const double wt = w * m.sampleTime;
    const std::complex<double> A = polyEval(m.a, wt), B = polyEval(m.b, wt),
                               F = polyEval(m.f, wt);
    const std::complex<double> G = B / (A * F);
    r.value.push_back(G);
    if (!bands) continue;
    // dG/dtheta: a_k -> -G z^-k / A; b_j -> z^-(nk+j) / (A F); f_k -> -G z^-k / F.
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, p);
    int col = 0;
    auto put = [&](std::complex<double> d) {
      J(0, col) = d.real();
      J(1, col) = d.imag();
      ++col;
    };
    auto zk = [&](int k) { return std::polar(1.0, -wt * k); };
    for (int k = 1; k <= o.na; ++k) put(-G * zk(k) / A);
    for (int j = 0; j < o.nb; ++j) put(zk(o.nk + j) / (A * F));
    col += o.nc + o.nd;
    for (int k = 1; k <= o.nf; ++k) put(-G * zk(k) / F);
    cov.push_back(J * m.covariance * J.transpose());
  }
  finishFrequencyResponse(r, cov);
  return r;
}

std::vector<std::complex<double>> poles(const PolynomialModel& m) {
  return polyRoots(polyMultiply(m.a, m.f));
}

std::vector<std::complex<double>> zeros(const PolynomialModel& m) { return polyRoots(m.b); }

NotchesPeaks notchesAndPeaks(const FrequencyResponse& r, double minDepthDb,
                             const std::function<double(double)>& exact) {
  return magnitudeExtrema(r.omega, r.magnitude, minDepthDb, exact);
}

NotchesPeaks notchesAndPeaksFromRoots(const std::vector<std::complex<double>>& zerosZ,
                                      const std::vector<std::complex<double>>& polesZ,
                                      double sampleTime, double maxDamping) {
  NotchesPeaks out;
  auto collect = [&](const std::vector<std::complex<double>>& roots, std::vector<double>& to) {
    for (const auto& z : roots) {
      if (z.imag() <= 0.0 || std::abs(z) <= 0.0) continue;  // one of each conjugate pair
      const std::complex<double> s = std::log(z) / sampleTime;
      const double wn = std::abs(s);
      const double zeta = -s.real() / wn;
      if (zeta < maxDamping) to.push_back(wn);
    }
    std::sort(to.begin(), to.end());
  };
  collect(zerosZ, out.notches);
  collect(polesZ, out.peaks);
  return out;
}

}  // namespace flexarm
