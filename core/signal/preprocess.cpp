#include "core/signal/preprocess.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "core/common/fft.h"

namespace flexarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

double besselI0(double x) {
  double sum = 1.0, term = 1.0;
  const double q = x * x / 4.0;
  for (int k = 1; k < 200; ++k) {
    term *= q / (static_cast<double>(k) * k);
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

// Value of x extended beyond its ends by odd reflection: x(-i) = 2 x(0) - x(i).
inline double extended(const std::vector<double>& x, long i) {
  const long n = static_cast<long>(x.size());
  if (i < 0) {
    long j = std::min(-i, n - 1);
    return 2.0 * x[0] - x[static_cast<std::size_t>(j)];
  }
  if (i >= n) {
    long j = std::max(2 * (n - 1) - i, 0L);
    return 2.0 * x[static_cast<std::size_t>(n - 1)] - x[static_cast<std::size_t>(j)];
  }
  return x[static_cast<std::size_t>(i)];
}

// Second-order section b0 + b1 z^-1 + b2 z^-2 over 1 + a1 z^-1 + a2 z^-2.
struct Biquad {
  double b0, b1, b2, a1, a2;
};

// Order-8 Chebyshev type I low-pass with the given ripple, cutoff in cycles per sample, by the
// bilinear transform of the analog prototype (pole pairs -> biquads).
std::vector<Biquad> chebyshevLowpass(int order, double rippleDb, double cutoff) {
  const double eps = std::sqrt(std::pow(10.0, rippleDb / 10.0) - 1.0);
  const double mu = std::asinh(1.0 / eps) / order;
  const double wc = 2.0 * std::tan(kPi * cutoff);  // prewarped, T = 1
  std::vector<Biquad> sections;
  for (int k = 0; k < order / 2; ++k) {
    const double theta = kPi * (2.0 * k + 1.0) / (2.0 * order);
    const std::complex<double> p(-std::sinh(mu) * std::sin(theta), std::cosh(mu) * std::cos(theta));
    const std::complex<double> pa = p * wc;  // analog pole, its conjugate is the pair
    // H(s) = |pa|^2 / (s^2 - 2 Re(pa) s + |pa|^2), s = 2 (z - 1) / (z + 1).
    const double w2 = std::norm(pa), c = -2.0 * pa.real();
    const double a0 = 4.0 + 2.0 * c + w2;
    Biquad b;
    b.b0 = w2 / a0;
    b.b1 = 2.0 * w2 / a0;
    b.b2 = w2 / a0;
    b.a1 = (2.0 * w2 - 8.0) / a0;
    b.a2 = (4.0 - 2.0 * c + w2) / a0;
    sections.push_back(b);
  }
  // Even-order Chebyshev I has DC gain 1/sqrt(1+eps^2); scale the first section so the DC gain
  // is exactly 1 (the top of the ripple band, as MATLAB's cheby1 does not, but as the data's
  // means should be kept).
  double dc = 1.0;
  for (const auto& s : sections) dc *= (s.b0 + s.b1 + s.b2) / (1.0 + s.a1 + s.a2);
  sections[0].b0 /= dc;
  sections[0].b1 /= dc;
  sections[0].b2 /= dc;
  return sections;
}

void runBiquads(const std::vector<Biquad>& sections, std::vector<double>& x) {
  for (const auto& s : sections) {
    double z1 = 0.0, z2 = 0.0;  // transposed direct form II
    // Start in the steady state for the first value, so a constant passes untouched.
    const double x0 = x.empty() ? 0.0 : x[0];
    const double y0 = x0 * (s.b0 + s.b1 + s.b2) / (1.0 + s.a1 + s.a2);
    z1 = y0 - s.b0 * x0;
    z2 = s.b2 * x0 - s.a2 * y0;
    for (double& v : x) {
      const double in = v;
      const double out = s.b0 * in + z1;
      z1 = s.b1 * in - s.a1 * out + z2;
      z2 = s.b2 * in - s.a2 * out;
      v = out;
    }
  }
}

}  // namespace

std::vector<double> differentiate(const std::vector<double>& x, double sampleTime) {
  if (!(sampleTime > 0.0)) throw std::invalid_argument("differentiate: sample time must be > 0");
  const std::size_t n = x.size();
  std::vector<double> d(n, 0.0);
  if (n < 2) return d;
  if (n == 2) {
    d[0] = d[1] = (x[1] - x[0]) / sampleTime;
    return d;
  }
  const double h2 = 2.0 * sampleTime;
  for (std::size_t i = 1; i + 1 < n; ++i) d[i] = (x[i + 1] - x[i - 1]) / h2;
  d[0] = (-3.0 * x[0] + 4.0 * x[1] - x[2]) / h2;
  d[n - 1] = (3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / h2;
  return d;
}

IdData addDerivative(const IdData& data, const std::string& from, const std::string& to,
                     bool makeOutput) {
  const Channel* src = data.channel(from);
  if (!src) throw std::invalid_argument("addDerivative: the data have no channel '" + from + "'");
  IdData out = data;
  Channel c;
  c.name = to;
  c.unit = unitFromColumnName(to);
  if (c.unit.empty()) c.unit = src->unit.empty() ? "1/s" : src->unit + "/s";
  c.values = differentiate(src->values, data.sampleTime);
  out.setChannel(std::move(c));
  if (makeOutput) out.setRole(to, ChannelRole::Output);
  return out;
}

const char* toString(AntiAliasFilter f) {
  switch (f) {
    case AntiAliasFilter::Fir: return "fir";
    case AntiAliasFilter::Chebyshev: return "chebyshev";
    case AntiAliasFilter::None: return "none";
  }
  return "fir";
}

std::optional<AntiAliasFilter> antiAliasFilterFromString(std::string_view s) {
  for (AntiAliasFilter f : {AntiAliasFilter::Fir, AntiAliasFilter::Chebyshev, AntiAliasFilter::None})
    if (s == toString(f)) return f;
  return std::nullopt;
}

bool DecimateOptions::isValid(std::string* why) const {
  if (factor < 1) {
    if (why) *why = "the decimation factor must be 1 or more";
    return false;
  }
  if (factor > 10000) {
    if (why) *why = "the decimation factor must be at most 10000";
    return false;
  }
  if (!(stopbandDb >= 20.0 && stopbandDb <= 200.0)) {
    if (why) *why = "the stopband attenuation must lie between 20 and 200 dB";
    return false;
  }
  return true;
}

std::vector<double> designLowpassFir(double passEdge, double stopEdge, double attenuationDb) {
  if (!(passEdge > 0.0 && stopEdge > passEdge && stopEdge <= 0.5))
    throw std::invalid_argument("designLowpassFir: need 0 < passEdge < stopEdge <= 0.5");
  const double width = 2.0 * kPi * (stopEdge - passEdge);
  int taps = static_cast<int>(std::ceil((attenuationDb - 8.0) / (2.285 * width))) + 1;
  if (taps % 2 == 0) ++taps;
  const double beta = attenuationDb > 50.0   ? 0.1102 * (attenuationDb - 8.7)
                      : attenuationDb >= 21.0 ? 0.5842 * std::pow(attenuationDb - 21.0, 0.4) +
                                                    0.07886 * (attenuationDb - 21.0)
                                              : 0.0;
  const double fc = 0.5 * (passEdge + stopEdge);
  const int m = taps / 2;
  std::vector<double> h(static_cast<std::size_t>(taps));
  const double i0beta = besselI0(beta);
  double sum = 0.0;
  for (int n = 0; n < taps; ++n) {
    const double k = n - m;
    const double ideal = k == 0 ? 2.0 * fc : std::sin(2.0 * kPi * fc * k) / (kPi * k);
    const double r = static_cast<double>(k) / m;
    const double w = besselI0(beta * std::sqrt(std::max(0.0, 1.0 - r * r))) / i0beta;
    h[static_cast<std::size_t>(n)] = ideal * w;
    sum += ideal * w;
  }
  for (double& v : h) v /= sum;
  return h;
}

std::vector<double> decimate(const std::vector<double>& x, const DecimateOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("decimate: " + why);
  const int r = options.factor;
  if (r == 1 || x.empty()) return x;
  const std::size_t nOut = (x.size() + static_cast<std::size_t>(r) - 1) / static_cast<std::size_t>(r);
  std::vector<double> y(nOut);
  switch (options.filter) {
    case AntiAliasFilter::None:
      for (std::size_t k = 0; k < nOut; ++k) y[k] = x[k * static_cast<std::size_t>(r)];
      return y;
    case AntiAliasFilter::Fir: {
      const double newNyquist = 0.5 / r;
      const auto h = designLowpassFir(0.8 * newNyquist, newNyquist, options.stopbandDb);
      const long m = static_cast<long>(h.size() / 2);
      const long n = static_cast<long>(x.size());
      for (std::size_t k = 0; k < nOut; ++k) {
        const long c = static_cast<long>(k) * r;
        double acc = 0.0;
        if (c - m >= 0 && c + m < n) {
          const double* p = x.data() + (c - m);
          for (std::size_t j = 0; j < h.size(); ++j) acc += h[j] * p[j];
        } else {
          for (long j = -m; j <= m; ++j) acc += h[static_cast<std::size_t>(j + m)] * extended(x, c + j);
        }
        y[k] = acc;
      }
      return y;
    }
    case AntiAliasFilter::Chebyshev: {
      const auto sections = chebyshevLowpass(8, 0.05, 0.8 * 0.5 / r);
      // Pad both ends by odd reflection, filter forward and backward, cut the padding.
      const long n = static_cast<long>(x.size());
      const long pad = std::min<long>(n - 1, 24L * r);
      std::vector<double> w;
      w.reserve(static_cast<std::size_t>(n + 2 * pad));
      for (long i = -pad; i < n + pad; ++i) w.push_back(extended(x, i));
      runBiquads(sections, w);
      std::reverse(w.begin(), w.end());
      runBiquads(sections, w);
      std::reverse(w.begin(), w.end());
      for (std::size_t k = 0; k < nOut; ++k) y[k] = w[static_cast<std::size_t>(pad) + k * static_cast<std::size_t>(r)];
      return y;
    }
  }
  return y;
}

IdData decimate(const IdData& data, const DecimateOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("decimate: " + why);
  if (options.factor == 1) return data;
  IdData out;
  out.sampleTime = data.sampleTime * options.factor;
  out.startTime = data.startTime;
  out.metadata = data.metadata;
  for (const auto& c : data.channels) out.channels.push_back({c.name, c.unit, c.role, decimate(c.values, options)});
  const std::size_t r = static_cast<std::size_t>(options.factor);
  auto scale = [&](const std::optional<SampleRange>& in) -> std::optional<SampleRange> {
    if (!in) return std::nullopt;
    SampleRange s{(in->begin + r - 1) / r, (in->end + r - 1) / r};
    s.end = std::min(s.end, out.samples());
    if (s.empty()) return std::nullopt;
    return s;
  };
  out.estimationRange = scale(data.estimationRange);
  out.validationRange = scale(data.validationRange);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", out.sampleRateHz());
  out.setMeta("sample_rate_hz", buf);
  return out;
}

const char* toString(Detrend d) {
  switch (d) {
    case Detrend::None: return "none";
    case Detrend::Mean: return "mean";
    case Detrend::Linear: return "linear";
  }
  return "none";
}

std::optional<Detrend> detrendFromString(std::string_view s) {
  for (Detrend d : {Detrend::None, Detrend::Mean, Detrend::Linear})
    if (s == toString(d)) return d;
  return std::nullopt;
}

std::vector<double> detrend(const std::vector<double>& x, Detrend kind) {
  std::vector<double> y = x;
  const std::size_t n = x.size();
  if (n == 0 || kind == Detrend::None) return y;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  if (kind == Detrend::Mean || n < 2) {
    for (double& v : y) v -= mean;
    return y;
  }
  // Least-squares line through (i, x_i) with i centred for accuracy.
  const double ic = 0.5 * static_cast<double>(n - 1);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double di = static_cast<double>(i) - ic;
    sxy += di * (x[i] - mean);
    sxx += di * di;
  }
  const double slope = sxy / sxx;
  for (std::size_t i = 0; i < n; ++i) y[i] -= mean + slope * (static_cast<double>(i) - ic);
  return y;
}

IdData detrend(const IdData& data, Detrend kind, bool allChannels) {
  IdData out = data;
  for (auto& c : out.channels)
    if (allChannels || c.role == ChannelRole::Input || c.role == ChannelRole::Output)
      c.values = detrend(c.values, kind);
  if (kind != Detrend::None) out.setMeta("detrend", toString(kind));
  return out;
}

AmplitudeSpectrum amplitudeSpectrum(const std::vector<double>& x, double sampleTime,
                                    int segmentLength) {
  AmplitudeSpectrum s;
  const int n = static_cast<int>(x.size());
  if (n < 8 || !(sampleTime > 0.0)) return s;
  int len = segmentLength;
  if (len <= 0) {
    len = 8;
    while (len * 2 <= std::min(n, 8192)) len *= 2;
  }
  len = std::min(len, n);
  std::vector<double> window(static_cast<std::size_t>(len));
  double wsum = 0.0;
  for (int i = 0; i < len; ++i) {
    window[static_cast<std::size_t>(i)] = 0.5 - 0.5 * std::cos(2.0 * kPi * i / len);
    wsum += window[static_cast<std::size_t>(i)];
  }
  const int bins = len / 2 + 1;
  std::vector<double> power(static_cast<std::size_t>(bins), 0.0);
  std::vector<double> in(static_cast<std::size_t>(len));
  std::vector<std::complex<double>> out(static_cast<std::size_t>(bins));
  const int step = std::max(1, len / 2);
  int segments = 0;
  for (int start = 0; start + len <= n; start += step) {
    double mean = 0.0;
    for (int i = 0; i < len; ++i) mean += x[static_cast<std::size_t>(start + i)];
    mean /= len;
    for (int i = 0; i < len; ++i)
      in[static_cast<std::size_t>(i)] =
          (x[static_cast<std::size_t>(start + i)] - mean) * window[static_cast<std::size_t>(i)];
    realDft(in.data(), len, out.data());
    for (int k = 0; k < bins; ++k) {
      const auto& X = out[static_cast<std::size_t>(k)];
      power[static_cast<std::size_t>(k)] += X.real() * X.real() + X.imag() * X.imag();
    }
    ++segments;
  }
  s.frequencyHz.resize(static_cast<std::size_t>(bins));
  s.amplitude.resize(static_cast<std::size_t>(bins));
  for (int k = 0; k < bins; ++k) {
    s.frequencyHz[static_cast<std::size_t>(k)] = k / (len * sampleTime);
    const double mag = std::sqrt(power[static_cast<std::size_t>(k)] / segments);
    s.amplitude[static_cast<std::size_t>(k)] = (k == 0 ? 1.0 : 2.0) * mag / wsum;
  }
  return s;
}

bool PreprocessOptions::isValid(std::string* why) const {
  if (!decimation.isValid(why)) return false;
  if (range && range->empty()) {
    if (why) *why = "the selected range is empty";
    return false;
  }
  return true;
}

IdData preprocess(const IdData& data, const PreprocessOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("preprocess: " + why);
  IdData d = options.differentiateAngle ? addDerivative(data) : data;
  if (options.range) d = d.select(*options.range);
  d = decimate(d, options.decimation);
  if (options.detrend != Detrend::None) d = detrend(d, options.detrend);
  return d;
}

}  // namespace flexarm
