#include "core/ident/nonparametric.h"

#include "core/common/parallel.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <stdexcept>

#include "core/common/fft.h"
#include "core/common/simd.h"

namespace flexarm {

const char* const kClosedLoopBiasWarning =
    "The data were logged in closed loop (a reference channel is present): ETFE and SPA are "
    "biased towards minus the inverse controller wherever noise dominates the reference (4.30).";

const char* toString(LagWindow w) { return w == LagWindow::Hann ? "hann" : "hamming"; }
std::optional<LagWindow> lagWindowFromString(std::string_view s) {
  if (s == "hann") return LagWindow::Hann;
  if (s == "hamming") return LagWindow::Hamming;
  return std::nullopt;
}

namespace {

bool positiveOmega(const std::vector<double>& omega, std::string* why) {
  for (double w : omega)
    if (!(w > 0.0) || !std::isfinite(w)) {
      if (why) *why = "frequencies must be positive and finite";
      return false;
    }
  return true;
}

using Clock = std::chrono::steady_clock;

// out[k] = sum_{j < taps} w[j] p[k + j] for k < n, each sum in the order of j: the smoothing
// (4.25) of a whole spectrum at once (p holds taps - 1 more values than out), eight bins at a
// time in the lanes of vectors V. out may be p itself: a value is overwritten only after the
// last sum that reads it.
template <class V>
inline __attribute__((always_inline)) void correlate(const double* p, const double* w, int taps,
                                                     double* out, int n) {
  constexpr int L = simd::kLanes<V>, Q = 8 / L;
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    V acc[Q];
    for (int q = 0; q < Q; ++q) acc[q] = V{};
    for (int j = 0; j < taps; ++j)
      for (int q = 0; q < Q; ++q) {
        V x;
        simd::load(x, p + k + j + q * L);
        acc[q] += w[j] * x;
      }
    for (int q = 0; q < Q; ++q) simd::store(out + k + q * L, acc[q]);
  }
  for (; k < n; ++k) {
    double s = 0.0;
    for (int j = 0; j < taps; ++j) s += w[j] * p[k + j];
    out[k] = s;
  }
}

FLEXARM_AVX2 void correlateAvx2(const double* p, const double* w, int taps, double* out, int n) {
  correlate<simd::Lanes4>(p, w, taps, out, n);
}

void correlate(const double* p, const double* w, int taps, double* out, int n) {
  if (simd::hasAvx2()) return correlateAvx2(p, w, taps, out, n);
  correlate<simd::Lanes2>(p, w, taps, out, n);
}

bool checkSignals(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double ts,
                  NonparametricEstimate& r, Eigen::Index minSamples) {
  if (u.size() != y.size())
    throw std::invalid_argument("input and output must have the same number of samples");
  if (!(ts > 0.0)) throw std::invalid_argument("the sample time must be positive");
  if (u.size() < minSamples) {
    r.message = "too few samples (" + std::to_string(u.size()) + ", need at least " +
                std::to_string(minSamples) + ")";
    return false;
  }
  if (!u.allFinite() || !y.allFinite()) {
    r.message = "the data contain NaN or infinite values";
    return false;
  }
  if (u.squaredNorm() == 0.0) {
    r.message = "the input is identically zero: nothing to estimate";
    return false;
  }
  return true;
}

NonparametricEstimate flagClosedLoop(NonparametricEstimate r, const IdData& data) {
  if (data.isClosedLoop()) {
    r.closedLoopBias = true;
    r.warning = kClosedLoopBiasWarning;
  }
  return r;
}

}  // namespace

bool EtfeOptions::isValid(std::string* why) const {
  if (smoothingWidth < 0) {
    if (why) *why = "the smoothing width must not be negative";
    return false;
  }
  return positiveOmega(omega, why);
}

bool SpaOptions::isValid(std::string* why) const {
  if (windowWidth < 0) {
    if (why) *why = "the lag-window width must not be negative";
    return false;
  }
  if (!(level > 0.0 && level < 1.0)) {
    if (why) *why = "the confidence level must lie strictly between 0 and 1";
    return false;
  }
  return positiveOmega(omega, why);
}

NonparametricEstimate etfe(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double ts,
                           const EtfeOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("etfe: " + why);
  const auto t0 = Clock::now();
  NonparametricEstimate r;
  if (!checkSignals(u, y, ts, r, 8)) return r;
  const int n = static_cast<int>(u.size());
  // DFTs of u and y (4.24); their scaling cancels in the ratios.
  // On a long record the two transforms, and below the three smoothings, run at once.
  const unsigned threads = threadsFor(static_cast<std::size_t>(n), 16384);
  std::vector<std::complex<double>> U(static_cast<std::size_t>(n / 2 + 1)), Y(U.size());
  inParallel(std::min(threads, 2u), [&](unsigned k) {
    if (k == 0 || threads == 1) realDft(u.data(), n, U.data());
    if (k == 1 || threads == 1) realDft(y.data(), n, Y.data());
  });
  const int nb = n / 2;
  const double dw = 2.0 * M_PI / (n * ts);
  const int width = std::max(1, options.smoothingWidth);
  r.window = width;
  // The cross spectrum Y conj(U) and |U|^2 per bin (written out: std::complex's product
  // checks for infinities on every call), with `pad` zeros at both ends.
  const int pad = width - 1;
  std::vector<double> cross(static_cast<std::size_t>(nb + 1 + 2 * pad), 0.0),
      crossIm(cross.size(), 0.0), power(cross.size(), 0.0);
  for (int k = 0; k <= nb; ++k) {
    const double ur = U[k].real(), ui = U[k].imag(), yr = Y[k].real(), yi = Y[k].imag();
    cross[k + pad] = yr * ur + yi * ui;
    crossIm[k + pad] = yi * ur - yr * ui;
    power[k + pad] = ur * ur + ui * ui;
  }
  const auto ratio = [](double re, double im, double den) {
    return den > 0.0 ? std::complex<double>(re, im) / den : std::complex<double>(NAN, NAN);
  };
  auto& response = r.response;
  if (options.omega.empty()) {
    // Every DFT frequency k dw, k = 1..N/2: (4.25) with a Hann window of `width` bins is one
    // correlation of each spectrum with the 2 width - 1 weights inside the window.
    std::vector<double> weight;
    for (int j = -pad; j <= pad; ++j)
      weight.push_back(0.5 * (1.0 + std::cos(M_PI * (static_cast<double>(j) / width))));
    // The smoothed spectra of bins 1..nb replace the raw ones in place, from index 1 on.
    double *num = cross.data() + 1, *numIm = crossIm.data() + 1, *den = power.data() + 1;
    const int taps = static_cast<int>(weight.size());
    double* const spectra[] = {num, numIm, den};
    const unsigned parts = std::min(threads, 3u);
    inParallel(parts, [&](unsigned k) {
      for (unsigned j = k; j < 3; j += parts) correlate(spectra[j], weight.data(), taps, spectra[j], nb);
    });
    response.omega.resize(static_cast<std::size_t>(nb));
    response.value.resize(response.omega.size());
    for (int k = 1; k <= nb; ++k) {
      response.omega[k - 1] = k * dw;
      response.value[k - 1] = ratio(num[k - 1], numIm[k - 1], den[k - 1]);
    }
  } else {
    for (double w : options.omega) {
      const double kc = w / dw;  // fractional bin
      double re = 0.0, im = 0.0, den = 0.0;
      if (width <= 1) {
        const int k = std::min(nb, std::max(0, static_cast<int>(std::lround(kc)))) + pad;
        re = cross[k];
        im = crossIm[k];
        den = power[k];
      } else {
        // Hann window over frequency (4.25), half-width `width` bins, weighted by |U|^2.
        const int lo = std::max(0, static_cast<int>(std::floor(kc - width)));
        const int hi = std::min(nb, static_cast<int>(std::ceil(kc + width)));
        for (int k = lo; k <= hi; ++k) {
          const double x = (k - kc) / width;
          if (std::abs(x) >= 1.0) continue;
          const double a = 0.5 * (1.0 + std::cos(M_PI * x));
          re += a * cross[k + pad];
          im += a * crossIm[k + pad];
          den += a * power[k + pad];
        }
      }
      response.omega.push_back(w);
      response.value.push_back(ratio(re, im, den));
    }
  }
  finishFrequencyResponse(response, {});
  r.termination = Termination::Converged;
  r.message = options.smoothingWidth > 1
                  ? "ETFE smoothed over " + std::to_string(options.smoothingWidth) + " bins"
                  : "raw ETFE";
  for (const auto& v : response.value)
    if (!std::isfinite(v.real())) {
      r.message += "; the input has no energy at some frequencies, where G is undefined (NaN)";
      break;
    }
  r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

// The time SPA's default lag window spans (spaDefaultWindow).
constexpr double kSpaWindowSeconds = 1.0;
// Frequencies where SPA's smoothed input spectrum is below this share of its largest value
// on the grid are left out of the estimate (counted in omittedFrequencies).
constexpr double kSpaWeakInput = 1e-2;

SpaWindow spaDefaultWindow(Eigen::Index samples, double sampleTime) {
  if (samples < 2 || !(sampleTime > 0.0))
    throw std::invalid_argument("spaDefaultWindow: needs two samples and a positive sample time");
  const auto tenth = static_cast<int>(std::max<Eigen::Index>(1, samples / 10));
  const auto second = static_cast<int>(std::min(1e9, std::ceil(kSpaWindowSeconds / sampleTime)));
  SpaWindow w;
  char buf[400];
  if (second <= 30) {
    w.width = std::min(tenth, 30);
    std::snprintf(buf, sizeof buf, "the default min(N/10, 30) of N = %lld samples, as SITB's",
                  static_cast<long long>(samples));
  } else if (tenth <= second) {
    w.width = tenth;
    std::snprintf(buf, sizeof buf,
                  "chosen from the data: N/10 of N = %lld samples (%.3g s), as long as the record "
                  "allows for a bounded variance, short of %.3g s at %.4g Hz",
                  static_cast<long long>(samples), tenth * sampleTime, kSpaWindowSeconds,
                  1.0 / sampleTime);
  } else {
    w.width = second;
    std::snprintf(buf, sizeof buf,
                  "chosen from the data: %.3g s at %.4g Hz, a resolution of about %.3g rad/s; "
                  "30 lags would span %.3g ms and ripple every %.3g rad/s",
                  kSpaWindowSeconds, 1.0 / sampleTime, 2.0 * M_PI / kSpaWindowSeconds,
                  30e3 * sampleTime, 2.0 * M_PI / (30.0 * sampleTime));
  }
  w.reason = buf;
  return w;
}

NonparametricEstimate spa(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double ts,
                          const SpaOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("spa: " + why);
  const auto t0 = Clock::now();
  NonparametricEstimate r;
  if (!checkSignals(u, y, ts, r, 8)) return r;
  const Eigen::Index n = u.size();
  const SpaWindow chosen = spaDefaultWindow(n, ts);
  int M = options.windowWidth > 0 ? options.windowWidth : chosen.width;
  M = static_cast<int>(std::max<Eigen::Index>(1, std::min<Eigen::Index>(M, n - 1)));
  r.window = M;
  // Covariances R_yu(tau) = 1/N sum y(t + tau) u(t), tau = -M..M, and R_u, R_y for tau >= 0.
  auto cov = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b, int tau) {
    double s = 0.0;
    if (tau >= 0)
      s = a.tail(n - tau).dot(b.head(n - tau));
    else
      s = a.head(n + tau).dot(b.tail(n + tau));
    return s / static_cast<double>(n);
  };
  std::vector<double> ryu(2 * M + 1), ru(M + 1), ry(M + 1), win(M + 1);
  for (int tau = -M; tau <= M; ++tau) ryu[tau + M] = cov(y, u, tau);
  double cw = 0.0;
  for (int tau = 0; tau <= M; ++tau) {
    ru[tau] = cov(u, u, tau);
    ry[tau] = cov(y, y, tau);
    const double c = std::cos(M_PI * tau / M);
    win[tau] = options.window == LagWindow::Hann ? 0.5 * (1.0 + c) : 0.54 + 0.46 * c;
    cw += (tau == 0 ? 1.0 : 2.0) * win[tau] * win[tau];
  }
  std::vector<double> omega = options.omega;
  if (omega.empty())
    for (int k = 1; k <= 128; ++k) omega.push_back(M_PI / ts * k / 128.0);
  std::vector<Eigen::Matrix2d> covs;
  // The lag window's spectral window has negative side lobes, so where the input has no power
  // the smoothed Phi_u can come out zero or negative: G is undefined there and the frequency
  // is left out of the estimate (counted and named in the message). So is a frequency where
  // Phi_u is below kSpaWeakInput of its largest value on the grid: there the estimate is the
  // leakage of the window's side lobes and the noise, not G (a PRBS's spectral nulls, the
  // band above a chirp's last frequency), and it draws notches and peaks that are not there.
  struct Spectra {
    double phiU, phiY;
    std::complex<double> phiYU;
  };
  std::vector<Spectra> spectra;
  spectra.reserve(omega.size());
  double phiUMax = 0.0;
  for (double w : omega) {
    const double wt = w * ts;
    double phiU = ru[0] * win[0], phiY = ry[0] * win[0];
    std::complex<double> phiYU = ryu[M] * win[0];
    for (int tau = 1; tau <= M; ++tau) {
      const double c = std::cos(wt * tau);
      phiU += 2.0 * win[tau] * ru[tau] * c;
      phiY += 2.0 * win[tau] * ry[tau] * c;
      phiYU += win[tau] * (ryu[M + tau] * std::polar(1.0, -wt * tau) +
                           ryu[M - tau] * std::polar(1.0, wt * tau));
    }
    spectra.push_back({phiU, phiY, phiYU});
    phiUMax = std::max(phiUMax, phiU);
  }
  int undefined = 0, weak = 0;
  double undefinedLow = INFINITY, undefinedHigh = 0.0;
  for (std::size_t i = 0; i < omega.size(); ++i) {
    const double w = omega[i];
    const auto& [phiU, phiY, phiYU] = spectra[i];
    if (!(phiU > 0.0) || phiU < kSpaWeakInput * phiUMax) {
      ++(phiU > 0.0 ? weak : undefined);
      undefinedLow = std::min(undefinedLow, w);
      undefinedHigh = std::max(undefinedHigh, w);
      continue;
    }
    r.response.omega.push_back(w);
    const std::complex<double> G = phiYU / phiU;
    r.response.value.push_back(G);
    const double phiV = std::max(0.0, phiY - std::norm(phiYU) / phiU);
    const double varG = cw / static_cast<double>(n) * phiV / phiU;
    covs.push_back(Eigen::Matrix2d::Identity() * (varG / 2.0));  // circular complex normal
  }
  r.response.level = options.level;
  finishFrequencyResponse(r.response, covs);
  r.termination = Termination::Converged;
  r.message = std::string("SPA with a ") + toString(options.window) + " lag window of width " +
              std::to_string(M) +
              (options.windowWidth > 0 ? std::string(" (as asked)") : " (" + chosen.reason + ")");
  r.omittedFrequencies = undefined + weak;
  if (undefined + weak > 0) {
    char range[96];
    std::snprintf(range, sizeof range, "%.4g-%.4g rad/s", undefinedLow, undefinedHigh);
    r.message += "; left out " + std::to_string(undefined + weak) + " of " +
                 std::to_string(omega.size()) + " frequencies (between " + range +
                 ") where the smoothed input spectrum is not positive or below 1e-2 of its "
                 "peak: the input has (almost) no power there";
  }
  if (r.response.omega.empty()) {
    r.termination = Termination::Failed;
    r.message = "SPA: the smoothed input spectrum is not positive at any frequency (is the "
                "input constant?)";
  }
  r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

void inputOutput(const IdData& data, Eigen::VectorXd& u, Eigen::VectorXd& y, SampleRange range) {
  const Channel* in = data.input();
  const Channel* out = data.output();
  if (!in || !out) throw std::invalid_argument("the data need an input and an output channel");
  if (range.empty()) range = {0, data.samples()};
  if (range.end > data.samples()) throw std::invalid_argument("range outside the data");
  const auto n = static_cast<Eigen::Index>(range.size());
  u = Eigen::Map<const Eigen::VectorXd>(in->values.data() + range.begin, n);
  y = Eigen::Map<const Eigen::VectorXd>(out->values.data() + range.begin, n);
}

NonparametricEstimate etfe(const IdData& data, const EtfeOptions& options) {
  Eigen::VectorXd u, y;
  inputOutput(data, u, y);
  return flagClosedLoop(etfe(u, y, data.sampleTime, options), data);
}

NonparametricEstimate spa(const IdData& data, const SpaOptions& options) {
  Eigen::VectorXd u, y;
  inputOutput(data, u, y);
  return flagClosedLoop(spa(u, y, data.sampleTime, options), data);
}

}  // namespace flexarm
