#include "core/control/loop_analysis.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Turn of (b - p) relative to (a - p), in (-pi, pi].
double turn(std::complex<double> a, std::complex<double> b, std::complex<double> p) {
  return std::arg((b - p) / (a - p));
}

bool needsRefinement(std::complex<double> a, std::complex<double> b, std::complex<double> p,
                     const NyquistOptions& o) {
  if (!std::isfinite(std::abs(a)) || !std::isfinite(std::abs(b))) return false;
  if (std::abs(turn(a, b, p)) > o.maxAngleStep) return true;
  const double nearest = std::min(std::abs(a - p), std::abs(b - p));
  return std::abs(b - a) > o.maxChordRatio * nearest;
}

// True when the curve's direction turns by more than o.maxBendStep at v (from before to after), both
// chords visible at the scale of the distance to p.
bool bendsSharply(std::complex<double> before, std::complex<double> v, std::complex<double> after,
                  std::complex<double> p, const NyquistOptions& o) {
  const std::complex<double> d1 = v - before, d2 = after - v;
  const double a = std::abs(d1), b = std::abs(d2);
  if (!std::isfinite(a) || !std::isfinite(b) || a == 0.0 || b == 0.0) return false;
  if (std::max(a, b) <= o.bendMinChord * std::abs(v - p)) return false;
  return std::abs(std::arg(d2 / d1)) > o.maxBendStep;
}

// Refines the parameter grid x (with values v = g(x)) by inserting midpoints where the curve
// turns or jumps too much around p, and (geometric: the frequency axis) where it bends;
// returns false when the point limit stopped it.
template <class Eval>
bool refine(std::vector<double>& x, std::vector<std::complex<double>>& v, const Eval& g,
            std::complex<double> p, const NyquistOptions& o, bool geometric) {
  for (;;) {
    // Intervals to halve: those that turn or jump around p, and both sides of a sharp bend.
    std::vector<char> split(x.size(), 0);
    for (std::size_t i = 0; i + 1 < x.size(); ++i) {
      if (needsRefinement(v[i], v[i + 1], p, o)) split[i] = 1;
      if (geometric && i > 0 && bendsSharply(v[i - 1], v[i], v[i + 1], p, o)) split[i - 1] = split[i] = 1;
    }
    std::vector<double> nx;
    std::vector<std::complex<double>> nv;
    nx.reserve(2 * x.size());
    nv.reserve(2 * x.size());
    bool inserted = false;
    for (std::size_t i = 0; i < x.size(); ++i) {
      nx.push_back(x[i]);
      nv.push_back(v[i]);
      if (i + 1 == x.size() || !split[i]) continue;
      if (static_cast<int>(x.size() + (nx.size() - i)) >= o.maxPoints) return false;
      const double mid = geometric ? std::sqrt(x[i] * x[i + 1]) : 0.5 * (x[i] + x[i + 1]);
      if (!(mid > x[i] && mid < x[i + 1])) continue;
      nx.push_back(mid);
      nv.push_back(g(mid));
      inserted = true;
    }
    x.swap(nx);
    v.swap(nv);
    if (!inserted) return true;
  }
}

double totalTurn(const std::vector<std::complex<double>>& v, std::complex<double> p) {
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < v.size(); ++i) sum += turn(v[i], v[i + 1], p);
  return sum;
}

}  // namespace

bool NyquistOptions::isValid(std::string* why) const {
  auto fail = [why](const char* s) {
    if (why) *why = s;
    return false;
  };
  if (initialPoints < 10) return fail("initialPoints must be at least 10");
  if (maxPoints < initialPoints) return fail("maxPoints must be at least initialPoints");
  if (!(maxAngleStep > 0.0 && maxAngleStep < 1.0)) return fail("maxAngleStep must be in (0, 1)");
  if (!(maxChordRatio > 0.0)) return fail("maxChordRatio must be positive");
  if (!(maxBendStep > 0.0 && maxBendStep < 1.0)) return fail("maxBendStep must be in (0, 1)");
  if (!(bendMinChord > 0.0) || !std::isfinite(bendMinChord)) return fail("bendMinChord must be positive");
  if (!(minFrequency >= 0.0) || !(maxFrequency >= 0.0))
    return fail("frequency limits must not be negative");
  if (minFrequency > 0.0 && maxFrequency > 0.0 && !(maxFrequency > minFrequency))
    return fail("maxFrequency must exceed minFrequency");
  return true;
}

NyquistCurve nyquist(const ComplexFunction& f, std::complex<double> point,
                     const std::vector<double>& characteristicFrequencies,
                     const NyquistOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("NyquistOptions: " + why);
  double largest = 0.0;
  for (double w : characteristicFrequencies)
    if (std::isfinite(w)) largest = std::max(largest, std::abs(w));
  double smallest = largest;
  for (double w : characteristicFrequencies)
    if (std::isfinite(w) && std::abs(w) > 1e-9 * largest)
      smallest = std::min(smallest, std::abs(w));
  if (!(largest > 0.0) && (options.minFrequency == 0.0 || options.maxFrequency == 0.0))
    throw std::invalid_argument("nyquist: no positive characteristic frequency to set the range");
  const double lo = options.minFrequency > 0.0 ? options.minFrequency : 1e-3 * smallest;
  const double hi = options.maxFrequency > 0.0 ? options.maxFrequency : 1e3 * largest;
  // The indentation must keep every non-zero pole outside.
  const double eps = largest > 0.0 ? std::min(lo, 1e-3 * smallest) : lo;

  NyquistCurve c;
  c.indentationRadius = eps;
  auto onAxis = [&f](double w) { return f({0.0, w}); };
  const int n = options.initialPoints;
  const double ratio = std::log(hi / eps) / (n - 1);
  for (int i = 0; i < n; ++i) c.frequencies.push_back(eps * std::exp(ratio * i));
  c.frequencies.back() = hi;
  for (double w : characteristicFrequencies)
    if (std::abs(w) > eps && std::abs(w) < hi) c.frequencies.push_back(std::abs(w));
  std::sort(c.frequencies.begin(), c.frequencies.end());
  c.frequencies.erase(std::unique(c.frequencies.begin(), c.frequencies.end()), c.frequencies.end());
  c.values.reserve(c.frequencies.size());
  for (double w : c.frequencies) c.values.push_back(onAxis(w));
  c.gridLimitReached = !refine(c.frequencies, c.values, onAxis, point, options, true);

  // Winding: both frequency half-axes turn alike (f(conj s) = conj f(s)); the tail to
  // infinity and the indentation s = eps e^{i theta}, theta from -pi/2 to pi/2, complete it.
  const double positive =
      totalTurn(c.values, point) + turn(c.values.back(), onAxis(1e6 * hi), point);
  std::vector<double> theta;
  std::vector<std::complex<double>> arc;
  auto onArc = [&f, eps](double t) { return f(std::polar(eps, t)); };
  for (int i = 0; i <= 64; ++i) {
    theta.push_back(-kPi / 2 + kPi * i / 64.0);
    arc.push_back(onArc(theta.back()));
  }
  NyquistOptions arcOptions = options;
  arcOptions.maxPoints = 4096;
  refine(theta, arc, onArc, point, arcOptions, false);
  const double turns = (2.0 * positive + totalTurn(arc, point)) / (2.0 * kPi);
  c.encirclements = static_cast<int>(std::lround(turns));
  c.windingError = std::abs(turns - c.encirclements);
  return c;
}

double bodeSensitivityIntegral(const ComplexFunction& loopGain, const std::vector<double>& grid) {
  if (grid.size() < 2) throw std::invalid_argument("bodeSensitivityIntegral: grid too short");
  auto logS = [&loopGain](double w) { return -std::log(std::abs(1.0 + loopGain({0.0, w}))); };
  // 4-point Gauss-Legendre in t = log w on each panel: integrand log|S(e^t)| e^t.
  static const double node[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                 0.8611363115940526};
  static const double weight[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                   0.3478548451374538};
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < grid.size(); ++i) {
    const double a = std::log(grid[i]), b = std::log(grid[i + 1]);
    const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
    for (int k = 0; k < 4; ++k) {
      const double w = std::exp(mid + half * node[k]);
      sum += half * weight[k] * logS(w) * w;
    }
  }
  // [0, w0]: log|S| ~ log|S(w0)| + m log(w / w0), whose integral is w0 (log|S(w0)| - m).
  const double w0 = grid[0], w1 = grid[1];
  const double h0 = logS(w0), h1 = logS(w1);
  const double m = (h1 - h0) / std::log(w1 / w0);
  sum += w0 * (h0 - m);
  // [wN, inf): log|S| ~ c w^-p with p > 1 for a loop gain falling at least as 1/s^2.
  const double wn = grid.back(), wp = grid[grid.size() - 2];
  const double hn = logS(wn), hp = logS(wp);
  if (hn != 0.0 && hp != 0.0 && (hn > 0) == (hp > 0)) {
    const double p = -std::log(std::abs(hn / hp)) / std::log(wn / wp);
    if (p > 1.0) sum += hn * wn / (p - 1.0);
  }
  return sum;
}

double saturationDescribingFunction(double amplitude) {
  if (!(amplitude > 1.0)) return 1.0;
  const double r = 1.0 / amplitude;
  return 2.0 / kPi * (std::asin(r) + r * std::sqrt(1.0 - r * r));
}

std::vector<DescribingFunctionCrossing> describingFunctionCrossings(const ComplexFunction& f,
                                                                    const NyquistCurve& curve) {
  std::vector<DescribingFunctionCrossing> out;
  const auto& w = curve.frequencies;
  const auto& v = curve.values;
  for (std::size_t i = 0; i + 1 < w.size(); ++i) {
    const double ia = v[i].imag(), ib = v[i + 1].imag();
    if (!(ia * ib < 0.0)) continue;
    if (v[i].real() > -1.0 && v[i + 1].real() > -1.0) continue;
    double lo = w[i], hi = w[i + 1], flo = ia;
    for (int it = 0; it < 60; ++it) {
      const double mid = std::sqrt(lo * hi);
      const double fm = f({0.0, mid}).imag();
      if ((fm < 0.0) == (flo < 0.0)) {
        lo = mid;
        flo = fm;
      } else {
        hi = mid;
      }
    }
    DescribingFunctionCrossing x;
    x.frequency = std::sqrt(lo * hi);
    x.realPart = f({0.0, x.frequency}).real();
    if (!(x.realPart <= -1.0) || !std::isfinite(x.realPart)) continue;
    // -1/Y_f(C) = realPart: Y_f(C) = 1/|realPart|, Y_f decreasing in C.
    const double target = -1.0 / x.realPart;
    double clo = 1.0, chi = 2.0;
    while (saturationDescribingFunction(chi) > target && chi < 1e15) chi *= 2.0;
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (clo + chi);
      (saturationDescribingFunction(mid) > target ? clo : chi) = mid;
    }
    x.amplitude = 0.5 * (clo + chi);
    out.push_back(x);
  }
  return out;
}

}  // namespace flexarm
