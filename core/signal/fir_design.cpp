#include "core/signal/fir_design.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

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

}  // namespace

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

KaiserLowpass::KaiserLowpass(double passEdge, double stopEdge, double attenuationDb) {
  if (!(passEdge > 0.0 && stopEdge > passEdge && stopEdge <= 0.5))
    throw std::invalid_argument("designLowpassFir: need 0 < passEdge < stopEdge <= 0.5");
  // Kaiser's estimates of the length and the window parameter for the attenuation.
  const double width = 2.0 * kPi * (stopEdge - passEdge);
  taps_ = static_cast<int>(std::ceil((attenuationDb - 8.0) / (2.285 * width))) + 1;
  if (taps_ % 2 == 0) ++taps_;
  beta_ = attenuationDb > 50.0   ? 0.1102 * (attenuationDb - 8.7)
          : attenuationDb >= 21.0 ? 0.5842 * std::pow(attenuationDb - 21.0, 0.4) +
                                        0.07886 * (attenuationDb - 21.0)
                                  : 0.0;
  fc_ = 0.5 * (passEdge + stopEdge);
  m_ = taps_ / 2;
  i0beta_ = besselI0(beta_);
}

double KaiserLowpass::operator()(double k) const {
  if (!(std::abs(k) <= m_)) return 0.0;
  const double ideal = k == 0 ? 2.0 * fc_ : std::sin(2.0 * kPi * fc_ * k) / (kPi * k);
  const double r = k / m_;
  return ideal * besselI0(beta_ * std::sqrt(std::max(0.0, 1.0 - r * r))) / i0beta_;
}

std::vector<double> designLowpassFir(double passEdge, double stopEdge, double attenuationDb) {
  const KaiserLowpass kernel(passEdge, stopEdge, attenuationDb);
  const int m = kernel.halfLength();
  std::vector<double> h(static_cast<std::size_t>(kernel.taps()));
  double sum = 0.0;
  for (int n = 0; n < kernel.taps(); ++n) {
    h[static_cast<std::size_t>(n)] = kernel(static_cast<double>(n - m));
    sum += h[static_cast<std::size_t>(n)];
  }
  for (double& v : h) v /= sum;
  return h;
}

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

}  // namespace flexarm
