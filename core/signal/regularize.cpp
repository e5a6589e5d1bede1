#include "core/signal/regularize.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/signal/fir_design.h"

namespace flexarm {
namespace {

void checkSamples(const std::vector<double>& t, const std::vector<const std::vector<double>*>& x) {
  if (t.size() < 2) throw std::invalid_argument("interpolation needs at least two samples");
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1])) throw std::invalid_argument("interpolation needs strictly increasing times");
  for (const auto* c : x)
    if (!c || c->size() != t.size()) throw std::invalid_argument("interpolation: a channel has the wrong length");
}

double sign(double v) { return v > 0.0 ? 1.0 : v < 0.0 ? -1.0 : 0.0; }

// End slope of PCHIP by the one-sided three-point formula, kept shape-preserving (as SciPy).
double pchipEndSlope(double h0, double h1, double m0, double m1) {
  double d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
  if (sign(d) != sign(m0))
    d = 0.0;
  else if (sign(m0) != sign(m1) && std::abs(d) > 3.0 * std::abs(m0))
    d = 3.0 * m0;
  return d;
}

// Fritsch-Carlson slopes: weighted harmonic mean of the neighbouring secants, zero at extrema.
std::vector<double> pchipSlopes(const std::vector<double>& t, const std::vector<double>& x) {
  const std::size_t n = t.size();
  std::vector<double> h(n - 1), m(n - 1), d(n, 0.0);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    h[k] = t[k + 1] - t[k];
    m[k] = (x[k + 1] - x[k]) / h[k];
  }
  if (n == 2) return {m[0], m[0]};
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (sign(m[k - 1]) != sign(m[k]) || m[k - 1] == 0.0 || m[k] == 0.0) continue;
    const double w1 = 2.0 * h[k] + h[k - 1], w2 = h[k] + 2.0 * h[k - 1];
    d[k] = (w1 + w2) / (w1 / m[k - 1] + w2 / m[k]);
  }
  d[0] = pchipEndSlope(h[0], h[1], m[0], m[1]);
  d[n - 1] = pchipEndSlope(h[n - 2], h[n - 3], m[n - 2], m[n - 3]);
  return d;
}

// Index k of the piece [t[k], t[k+1]] holding tau, walking forward from k (sorted queries).
std::size_t pieceOf(const std::vector<double>& t, double tau, std::size_t k) {
  if (k + 2 < t.size() && tau > t[k + 1]) {
    k = static_cast<std::size_t>(std::upper_bound(t.begin() + static_cast<std::ptrdiff_t>(k), t.end(), tau) - t.begin());
    k = k == 0 ? 0 : k - 1;
  } else if (tau < t[k]) {
    k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), tau) - t.begin());
    k = k == 0 ? 0 : k - 1;
  }
  return std::min(k, t.size() - 2);
}

double pchipAt(const std::vector<double>& t, const std::vector<double>& x, const std::vector<double>& d,
               std::size_t k, double tau) {
  const double h = t[k + 1] - t[k], s = tau - t[k];
  const double m = (x[k + 1] - x[k]) / h;
  const double c2 = (3.0 * m - 2.0 * d[k] - d[k + 1]) / h;
  const double c3 = (d[k] + d[k + 1] - 2.0 * m) / (h * h);
  return x[k] + s * (d[k] + s * (c2 + s * c3));
}

// Odd reflection beyond the ends of the grid.
inline double at(const std::vector<double>& g, long i) {
  const long n = static_cast<long>(g.size());
  if (i < 0) return 2.0 * g[0] - g[static_cast<std::size_t>(std::min(-i, n - 1))];
  if (i >= n) return 2.0 * g[static_cast<std::size_t>(n - 1)] - g[static_cast<std::size_t>(std::max(2 * (n - 1) - i, 0L))];
  return g[static_cast<std::size_t>(i)];
}

// The band-limited interpolant of grid values: the Kaiser low-pass with its passband to 0.8 of
// the grid's Nyquist frequency (80 dB), its first and second derivatives at whole samples, and
// the high-pass that measures energy above the band.
struct BandKernels {
  long half = 0;
  std::vector<double> d1, d2, highpass;  // index k + half, k = -half..half
};

const BandKernels& bandKernels() {
  static const BandKernels k = [] {
    const KaiserLowpass h(0.4, 0.5, 80.0);
    BandKernels b;
    b.half = h.halfLength();
    double sum = 0.0;
    for (long j = -b.half; j <= b.half; ++j) sum += h(static_cast<double>(j));
    const double e1 = 1e-5, e2 = 1e-4;
    for (long j = -b.half; j <= b.half; ++j) {
      const double x = static_cast<double>(j);
      // The window ends in a step at +-half: differentiate inside it only.
      const bool inside = std::abs(j) < b.half;
      b.d1.push_back(inside ? (h(x + e1) - h(x - e1)) / (2.0 * e1) / sum : 0.0);
      b.d2.push_back(inside ? (h(x + e2) - 2.0 * h(x) + h(x - e2)) / (e2 * e2) / sum : 0.0);
      b.highpass.push_back((j == 0 ? 1.0 : 0.0) - h(x) / sum);
    }
    return b;
  }();
  return k;
}

double filterAt(const std::vector<double>& taps, long half, const std::vector<double>& g, long n) {
  double acc = 0.0;
  for (long k = -half; k <= half; ++k) acc += taps[static_cast<std::size_t>(k + half)] * at(g, n - k);
  return acc;
}

constexpr std::size_t kMaxBandLimitedGap = 512;

// A sample closer to its grid point than this (fraction of the interval) counts as on it.
constexpr double kOnGrid = 1e-6;

// Fills the unknown grid points of every channel with the values of least energy above the
// band (normal equations of the high-passed signal; one factorisation per cluster of gaps).
void fillGapsBandLimited(const std::vector<char>& known, std::vector<std::vector<double>>& g, GridFill& fill) {
  const BandKernels& k = bandKernels();
  const long n = static_cast<long>(known.size()), H = k.half;
  long i = 0;
  while (i < n) {
    if (known[static_cast<std::size_t>(i)]) {
      ++i;
      continue;
    }
    // A cluster: gaps closer than the filter length solve together.
    std::vector<long> unknown;
    long last = i;
    for (long j = i; j < n && j <= last + 2 * H; ++j)
      if (!known[static_cast<std::size_t>(j)]) {
        unknown.push_back(j);
        last = j;
      }
    i = last + 1;
    if (unknown.size() > kMaxBandLimitedGap) {
      fill.pchipFallback += unknown.size();
      continue;  // keeps the PCHIP values
    }
    const long r0 = std::max(unknown.front() - H, H), r1 = std::min(last + H, n - 1 - H);
    if (r1 < r0) {
      fill.pchipFallback += unknown.size();
      continue;
    }
    const long G = static_cast<long>(unknown.size()), R = r1 - r0 + 1;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(R, G);
    for (long r = 0; r < R; ++r)
      for (long c = 0; c < G; ++c) {
        const long lag = r0 + r - unknown[static_cast<std::size_t>(c)];
        if (lag >= -H && lag <= H) A(r, c) = k.highpass[static_cast<std::size_t>(lag + H)];
      }
    Eigen::MatrixXd normal = A.transpose() * A;
    normal.diagonal().array() += 1e-12 * normal.trace() / static_cast<double>(G);
    const Eigen::LDLT<Eigen::MatrixXd> solver(normal);
    for (auto& values : g) {
      for (long u : unknown) values[static_cast<std::size_t>(u)] = 0.0;
      Eigen::VectorXd b(R);
      for (long r = 0; r < R; ++r) b(r) = filterAt(k.highpass, H, values, r0 + r);
      const Eigen::VectorXd u = solver.solve(-A.transpose() * b);
      for (long c = 0; c < G; ++c) values[static_cast<std::size_t>(unknown[static_cast<std::size_t>(c)])] = u(c);
    }
  }
}

}  // namespace

const char* toString(InterpolationMethod m) {
  switch (m) {
    case InterpolationMethod::Linear: return "linear";
    case InterpolationMethod::Pchip: return "pchip";
    case InterpolationMethod::BandLimited: return "bandlimited";
  }
  return "bandlimited";
}

std::optional<InterpolationMethod> interpolationMethodFromString(std::string_view s) {
  for (InterpolationMethod m : {InterpolationMethod::Linear, InterpolationMethod::Pchip, InterpolationMethod::BandLimited})
    if (s == toString(m)) return m;
  return std::nullopt;
}

std::vector<double> interpolateLinear(const std::vector<double>& t, const std::vector<double>& x,
                                      const std::vector<double>& query) {
  checkSamples(t, {&x});
  std::vector<double> y(query.size());
  std::size_t k = 0;
  for (std::size_t q = 0; q < query.size(); ++q) {
    k = pieceOf(t, query[q], k);
    const double w = (query[q] - t[k]) / (t[k + 1] - t[k]);
    y[q] = x[k] + w * (x[k + 1] - x[k]);
  }
  return y;
}

std::vector<double> interpolatePchip(const std::vector<double>& t, const std::vector<double>& x,
                                     const std::vector<double>& query) {
  checkSamples(t, {&x});
  const std::vector<double> d = pchipSlopes(t, x);
  std::vector<double> y(query.size());
  std::size_t k = 0;
  for (std::size_t q = 0; q < query.size(); ++q) {
    k = pieceOf(t, query[q], k);
    y[q] = pchipAt(t, x, d, k, query[q]);
  }
  return y;
}

std::vector<std::vector<double>> regularize(const std::vector<double>& t,
                                            const std::vector<const std::vector<double>*>& x,
                                            double start, double interval, std::size_t points,
                                            InterpolationMethod method, GridFill* fillOut) {
  checkSamples(t, x);
  if (!(interval > 0.0) || points == 0) throw std::invalid_argument("regularize: empty grid");
  GridFill fill;
  // The sample nearest each grid point (within half an interval) and its offset in intervals.
  const std::size_t none = static_cast<std::size_t>(-1);
  std::vector<std::size_t> nearest(points, none);
  std::vector<double> offset(points, 0.0);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double p = (t[i] - start) / interval;
    const double k = std::round(p);
    if (k < 0.0 || k >= static_cast<double>(points)) continue;
    const std::size_t g = static_cast<std::size_t>(k);
    if (nearest[g] != none) {
      ++fill.unused;
      if (std::abs(p - k) >= std::abs(offset[g])) continue;
    }
    nearest[g] = i;
    offset[g] = p - k;
  }
  std::vector<char> known(points, 0);
  for (std::size_t g = 0; g < points; ++g) {
    if (nearest[g] == none) {
      ++fill.filled;
    } else {
      known[g] = 1;
      if (std::abs(offset[g]) > kOnGrid) ++fill.retimed; else ++fill.exact;
    }
  }
  if (method != InterpolationMethod::BandLimited) fill.unused = 0;

  std::vector<double> grid(points);
  for (std::size_t g = 0; g < points; ++g) grid[g] = start + static_cast<double>(g) * interval;
  std::vector<std::vector<double>> out;
  for (const auto* c : x) {
    std::vector<double> y = method == InterpolationMethod::Linear ? interpolateLinear(t, *c, grid)
                                                                  : interpolatePchip(t, *c, grid);
    for (std::size_t g = 0; g < points; ++g)  // samples on their grid point keep their value
      if (known[g] && std::abs(offset[g]) <= kOnGrid) y[g] = (*c)[nearest[g]];
    out.push_back(std::move(y));
  }
  if (method == InterpolationMethod::BandLimited) {
    // Start from the samples where they are (jitter not yet removed) and fill the gaps.
    for (std::size_t c = 0; c < x.size(); ++c)
      for (std::size_t g = 0; g < points; ++g)
        if (known[g]) out[c][g] = (*x[c])[nearest[g]];
    GridFill first;
    fillGapsBandLimited(known, out, first);
    fill.pchipFallback = first.pchipFallback;
    std::vector<std::size_t> jittered;
    for (std::size_t g = 0; g < points; ++g)
      if (known[g] && std::abs(offset[g]) > kOnGrid) jittered.push_back(g);
    // Moving a jittered sample uses the gap values near it and the other way round: alternate.
    if (!jittered.empty()) {
      const BandKernels& k = bandKernels();
      for (int iteration = 0; iteration < 4; ++iteration) {
        for (std::size_t c = 0; c < x.size(); ++c) {
          std::vector<double>& y = out[c];
          for (std::size_t g : jittered) {
            const double e = offset[g];
            const long n = static_cast<long>(g);
            y[g] = (*x[c])[nearest[g]] - e * filterAt(k.d1, k.half, y, n) -
                   0.5 * e * e * filterAt(k.d2, k.half, y, n);
          }
        }
        if (fill.filled) fillGapsBandLimited(known, out, first);
      }
    }
  }
  if (fillOut) *fillOut = fill;
  return out;
}

}  // namespace flexarm
