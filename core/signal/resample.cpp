#include "core/signal/resample.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <thread>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FLEXARM_AVX2_KERNELS 1
#endif

namespace flexarm {
namespace {

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

// Dot products of the taps g with windows of x. The portable kernels sum in tap order (the
// order of the direct convolution they replace); the AVX2 kernels differ only by rounding.
double dot1Portable(const double* g, long len, const double* x) {
  double acc = 0.0;
  for (long j = 0; j < len; ++j) acc += g[j] * x[j];
  return acc;
}

// out[t] = sum_j g[j] x[t stride + j], t = 0..3.
void dot4Portable(const double* g, long len, const double* x, long stride, double* out) {
  const double *x0 = x, *x1 = x + stride, *x2 = x + 2 * stride, *x3 = x + 3 * stride;
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
  for (long j = 0; j < len; ++j) {
    const double h = g[j];
    a0 += h * x0[j];
    a1 += h * x1[j];
    a2 += h * x2[j];
    a3 += h * x3[j];
  }
  out[0] = a0;
  out[1] = a1;
  out[2] = a2;
  out[3] = a3;
}

#ifdef FLEXARM_AVX2_KERNELS
__attribute__((target("avx2,fma"))) inline double horizontalSum(__m256d v) {
  __m128d s = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
  return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
}

// One lane of dot4Avx2 (the same sums in the same order), so that an output does not depend
// on whether it was computed alone or in a group of four.
__attribute__((target("avx2,fma"))) double dot1Avx2(const double* g, long len, const double* x) {
  __m256d a = _mm256_setzero_pd(), b = _mm256_setzero_pd();
  long j = 0;
  for (; j + 8 <= len; j += 8) {
    a = _mm256_fmadd_pd(_mm256_loadu_pd(g + j), _mm256_loadu_pd(x + j), a);
    b = _mm256_fmadd_pd(_mm256_loadu_pd(g + j + 4), _mm256_loadu_pd(x + j + 4), b);
  }
  for (; j + 4 <= len; j += 4) a = _mm256_fmadd_pd(_mm256_loadu_pd(g + j), _mm256_loadu_pd(x + j), a);
  double acc = horizontalSum(_mm256_add_pd(a, b));
  for (; j < len; ++j) acc += g[j] * x[j];
  return acc;
}

__attribute__((target("avx2,fma"))) void dot4Avx2(const double* g, long len, const double* x,
                                                   long stride, double* out) {
  const double *x0 = x, *x1 = x + stride, *x2 = x + 2 * stride, *x3 = x + 3 * stride;
  __m256d a0 = _mm256_setzero_pd(), a1 = _mm256_setzero_pd(), a2 = _mm256_setzero_pd(),
          a3 = _mm256_setzero_pd(), b0 = _mm256_setzero_pd(), b1 = _mm256_setzero_pd(),
          b2 = _mm256_setzero_pd(), b3 = _mm256_setzero_pd();
  long j = 0;
  for (; j + 8 <= len; j += 8) {
    const __m256d h = _mm256_loadu_pd(g + j), k = _mm256_loadu_pd(g + j + 4);
    a0 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x0 + j), a0);
    a1 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x1 + j), a1);
    a2 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x2 + j), a2);
    a3 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x3 + j), a3);
    b0 = _mm256_fmadd_pd(k, _mm256_loadu_pd(x0 + j + 4), b0);
    b1 = _mm256_fmadd_pd(k, _mm256_loadu_pd(x1 + j + 4), b1);
    b2 = _mm256_fmadd_pd(k, _mm256_loadu_pd(x2 + j + 4), b2);
    b3 = _mm256_fmadd_pd(k, _mm256_loadu_pd(x3 + j + 4), b3);
  }
  for (; j + 4 <= len; j += 4) {
    const __m256d h = _mm256_loadu_pd(g + j);
    a0 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x0 + j), a0);
    a1 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x1 + j), a1);
    a2 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x2 + j), a2);
    a3 = _mm256_fmadd_pd(h, _mm256_loadu_pd(x3 + j), a3);
  }
  out[0] = horizontalSum(_mm256_add_pd(a0, b0));
  out[1] = horizontalSum(_mm256_add_pd(a1, b1));
  out[2] = horizontalSum(_mm256_add_pd(a2, b2));
  out[3] = horizontalSum(_mm256_add_pd(a3, b3));
  for (; j < len; ++j) {
    out[0] += g[j] * x0[j];
    out[1] += g[j] * x1[j];
    out[2] += g[j] * x2[j];
    out[3] += g[j] * x3[j];
  }
}
#endif

struct Kernels {
  double (*dot1)(const double*, long, const double*) = dot1Portable;
  void (*dot4)(const double*, long, const double*, long, double*) = dot4Portable;
};

const Kernels& kernels() {
  static const Kernels k = [] {
    Kernels s;
#ifdef FLEXARM_AVX2_KERNELS
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
      s.dot1 = dot1Avx2;
      s.dot4 = dot4Avx2;
    }
#endif
    return s;
  }();
  return k;
}

// One phase of the polyphase filter: the taps and the input index of tap 0 relative to the
// output's base index (whole part of the offset + k down / up, integer division).
struct Phase {
  long start = 0;
  std::vector<double> taps;
};

struct FirPlan {
  int up = 1, down = 1;
  long whole = 0;             // floor(offset)
  std::vector<Phase> phases;  // by (k down) mod up
};

// The prototype at the rate up x input, sampled at the positions of each phase and
// normalised to unit DC gain per phase (for up = 1 and offset 0: designLowpassFir exactly).
FirPlan makeFirPlan(const ResampleOptions& o) {
  const int L = o.up, M = o.down;
  const double nyquist = 0.5 / std::max(L, M);
  const KaiserLowpass kernel(0.8 * nyquist, nyquist, o.stopbandDb);
  const double m = kernel.halfLength();
  FirPlan plan;
  plan.up = L;
  plan.down = M;
  plan.whole = static_cast<long>(std::floor(o.offset));
  const double frac = o.offset - static_cast<double>(plan.whole);
  plan.phases.resize(static_cast<std::size_t>(L));
  for (int r = 0; r < L; ++r) {
    double u = frac * L + r;  // position in samples of the fast rate, from the base index
    long carry = 0;
    if (u >= L) {
      u -= L;
      carry = 1;
    }
    Phase& ph = plan.phases[static_cast<std::size_t>(r)];
    const long lo = static_cast<long>(std::floor((u - m) / L)) - 1;
    const long hi = static_cast<long>(std::ceil((u + m) / L)) + 1;
    bool started = false;
    for (long j = lo; j <= hi; ++j) {
      const double tau = static_cast<double>(j) * L - u;
      if (!(std::abs(tau) <= m)) continue;
      if (!started) ph.start = j + carry;
      started = true;
      ph.taps.push_back(kernel(tau));
    }
    double sum = 0.0;
    for (double v : ph.taps) sum += v;
    for (double& v : ph.taps) v /= sum;
  }
  return plan;
}

std::size_t defaultOutputs(std::size_t n, const ResampleOptions& o) {
  const double span = static_cast<double>(n) - o.offset;
  if (!(span > 0.0)) return 0;
  if (o.offset == 0.0) {  // exact: ceil(n up / down)
    const std::uint64_t num = static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(o.up);
    return static_cast<std::size_t>((num + static_cast<std::uint64_t>(o.down) - 1) /
                                    static_cast<std::uint64_t>(o.down));
  }
  return static_cast<std::size_t>(std::ceil(span * o.up / o.down - 1e-9));
}

int threadCount(int requested, double work, std::size_t jobs) {
  int t = requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (work < 2e5) t = 1;  // not worth a thread
  return std::max(1, std::min<int>(t, static_cast<int>(jobs)));
}

// Runs job(0..count-1) on `threads` threads (the caller's included).
template <class Job>
void runJobs(std::size_t count, int threads, const Job& job) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < count; i = next++) job(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

// Outputs [kb, ke) of one channel through the polyphase FIR.
void firBlock(const FirPlan& plan, const std::vector<double>& x, std::size_t kb, std::size_t ke,
              double* y) {
  const Kernels& k = kernels();
  const long n = static_cast<long>(x.size());
  const std::uint64_t L = static_cast<std::uint64_t>(plan.up), M = static_cast<std::uint64_t>(plan.down);
  std::vector<double> scratch;
  // One output whose window may reach past the ends: gather the extended input first.
  auto edge = [&](const Phase& ph, long base) {
    const long len = static_cast<long>(ph.taps.size());
    if (base >= 0 && base + len <= n) return k.dot1(ph.taps.data(), len, x.data() + base);
    scratch.resize(static_cast<std::size_t>(len));
    for (long j = 0; j < len; ++j) scratch[static_cast<std::size_t>(j)] = extended(x, base + j);
    return dot1Portable(ph.taps.data(), len, scratch.data());
  };
  // Outputs k, k + up, k + 2 up, ... share a phase and lie `down` input samples apart.
  const std::size_t classes = std::min<std::size_t>(plan.up, ke - kb);
  for (std::size_t s = 0; s < classes; ++s) {
    const std::size_t k0 = kb + s;
    const std::uint64_t pos = static_cast<std::uint64_t>(k0) * M;
    const Phase& ph = plan.phases[static_cast<std::size_t>(pos % L)];
    const long len = static_cast<long>(ph.taps.size());
    long base = plan.whole + static_cast<long>(pos / L) + ph.start;
    const long stride = static_cast<long>(M);
    std::size_t kk = k0;
    for (; kk + 3 * plan.up < ke; kk += 4 * static_cast<std::size_t>(plan.up), base += 4 * stride) {
      if (base >= 0 && base + 3 * stride + len <= n) {
        double out[4];
        k.dot4(ph.taps.data(), len, x.data() + base, stride, out);
        for (int t = 0; t < 4; ++t) y[kk + static_cast<std::size_t>(t) * plan.up - kb] = out[t];
      } else {
        for (int t = 0; t < 4; ++t) y[kk + static_cast<std::size_t>(t) * plan.up - kb] = edge(ph, base + t * stride);
      }
    }
    for (; kk < ke; kk += static_cast<std::size_t>(plan.up), base += stride) y[kk - kb] = edge(ph, base);
  }
}

// Zero-phase Chebyshev: pad both ends by odd reflection, filter forward and backward, cut the
// padding, keep every down-th sample.
std::vector<double> chebyshevDecimate(const std::vector<double>& x, int r, std::size_t nOut) {
  const auto sections = chebyshevLowpass(8, 0.05, 0.8 * 0.5 / r);
  const long n = static_cast<long>(x.size());
  const long pad = std::min<long>(n - 1, 24L * r);
  std::vector<double> w;
  w.reserve(static_cast<std::size_t>(n + 2 * pad));
  for (long i = -pad; i < n + pad; ++i) w.push_back(extended(x, i));
  runBiquads(sections, w);
  std::reverse(w.begin(), w.end());
  runBiquads(sections, w);
  std::reverse(w.begin(), w.end());
  std::vector<double> y(nOut);
  for (std::size_t k = 0; k < nOut; ++k) {
    const std::size_t i = static_cast<std::size_t>(pad) + k * static_cast<std::size_t>(r);
    y[k] = i < w.size() ? w[i] : w.back();
  }
  return y;
}

}  // namespace

std::optional<RationalFactor> rationalFactor(double fromHz, double toHz, int maxFactor) {
  if (!(fromHz > 0.0) || !(toHz > 0.0) || !std::isfinite(fromHz) || !std::isfinite(toHz))
    throw std::invalid_argument("rationalFactor: rates must be positive and finite");
  const double ratio = toHz / fromHz;
  // Continued fraction convergents of the ratio until one is within 1e-9.
  long p0 = 0, q0 = 1, p1 = 1, q1 = 0;
  double v = ratio;
  for (int i = 0; i < 64; ++i) {
    const double a = std::floor(v);
    if (a > 1e12) break;
    const long ai = static_cast<long>(a);
    const long p2 = ai * p1 + p0, q2 = ai * q1 + q0;
    if (p2 > maxFactor || q2 > maxFactor) break;
    p0 = p1;
    q0 = q1;
    p1 = p2;
    q1 = q2;
    if (p1 > 0 && std::abs(static_cast<double>(p1) / static_cast<double>(q1) - ratio) <= 1e-9 * ratio) {
      const long g = std::gcd(p1, q1);
      return RationalFactor{static_cast<int>(p1 / g), static_cast<int>(q1 / g)};
    }
    const double f = v - a;
    if (f < 1e-15) break;
    v = 1.0 / f;
  }
  return std::nullopt;
}

bool ResampleOptions::isValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (up < 1 || down < 1) return fail("the up and down factors must be 1 or more");
  if (up > 10000 || down > 10000) return fail("the up and down factors must be at most 10000");
  if (!(offset >= 0.0) || !std::isfinite(offset)) return fail("the start offset must be 0 or more");
  if (!(stopbandDb >= 20.0 && stopbandDb <= 200.0))
    return fail("the stopband attenuation must lie between 20 and 200 dB");
  if (filter != AntiAliasFilter::Fir && (up != 1 || offset != 0.0))
    return fail("only the FIR anti-alias filter resamples by a rational factor or shifts the "
                "time base; the Chebyshev filter and no filter serve integer decimation");
  if (threads < 0) return fail("the thread count must be 0 (one per core) or more");
  return true;
}

int resampleFilterTaps(const ResampleOptions& o) {
  const double nyquist = 0.5 / std::max(o.up, o.down);
  return KaiserLowpass(0.8 * nyquist, nyquist, o.stopbandDb).taps();
}

std::vector<std::vector<double>> resample(const std::vector<const std::vector<double>*>& channels,
                                          const ResampleOptions& o) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("resample: " + why);
  std::vector<std::vector<double>> out(channels.size());
  if (channels.empty()) return out;
  const std::size_t n = channels.front()->size();
  for (const auto* c : channels)
    if (!c || c->size() != n) throw std::invalid_argument("resample: the channels differ in length");
  const std::size_t nOut = o.outputs ? o.outputs : defaultOutputs(n, o);
  if (n == 0 || nOut == 0) return out;
  if (o.up == o.down && o.offset == std::floor(o.offset)) {  // whole samples: a plain copy
    const long whole = static_cast<long>(o.offset);
    for (std::size_t c = 0; c < channels.size(); ++c) {
      out[c].assign(nOut, 0.0);
      for (std::size_t k = 0; k < nOut; ++k) out[c][k] = extended(*channels[c], whole + static_cast<long>(k));
    }
    return out;
  }
  for (auto& y : out) y.assign(nOut, 0.0);
  const std::size_t nc = channels.size();
  switch (o.filter) {
    case AntiAliasFilter::None:
      for (std::size_t c = 0; c < nc; ++c)
        for (std::size_t k = 0; k < nOut; ++k)
          out[c][k] = extended(*channels[c], static_cast<long>(k * static_cast<std::size_t>(o.down)));
      return out;
    case AntiAliasFilter::Chebyshev: {
      const int threads = threadCount(o.threads, 40.0 * static_cast<double>(n * nc), nc);
      runJobs(nc, threads, [&](std::size_t c) { out[c] = chebyshevDecimate(*channels[c], o.down, nOut); });
      return out;
    }
    case AntiAliasFilter::Fir: break;
  }
  const FirPlan plan = makeFirPlan(o);
  std::size_t taps = 0;
  for (const auto& ph : plan.phases) taps = std::max(taps, ph.taps.size());
  const double work = static_cast<double>(nOut) * static_cast<double>(nc) * static_cast<double>(taps);
  const int wanted = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // Enough blocks per channel that every thread stays busy to the end.
  const std::size_t perChannel =
      std::max<std::size_t>(1, std::min<std::size_t>(nOut / 1024 + 1, (8 * static_cast<std::size_t>(wanted) + nc - 1) / nc));
  const std::size_t block = (nOut + perChannel - 1) / perChannel;
  const std::size_t jobs = nc * perChannel;
  runJobs(jobs, threadCount(o.threads, work, jobs), [&](std::size_t j) {
    const std::size_t c = j / perChannel, b = j % perChannel;
    const std::size_t kb = b * block, ke = std::min(nOut, kb + block);
    if (kb < ke) firBlock(plan, *channels[c], kb, ke, out[c].data() + kb);
  });
  return out;
}

std::vector<double> resample(const std::vector<double>& x, const ResampleOptions& options) {
  return std::move(resample(std::vector<const std::vector<double>*>{&x}, options).front());
}

}  // namespace flexarm
