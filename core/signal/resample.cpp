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

// out[t os] = sum_j g[j] x[t stride + j], t = 0..3.
void dot4Portable(const double* g, long len, const double* x, long stride, double* out, long os) {
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
  out[os] = a1;
  out[2 * os] = a2;
  out[3 * os] = a3;
}

#ifdef FLEXARM_AVX2_KERNELS
// The AVX2 kernels need the tap count to be a multiple of 8 (the plan pads the phases with
// zeros). Each output sums two interleaved halves of its taps lane by lane and then adds the
// lanes as (0 + 1) + (2 + 3); dot1Avx2 is one lane of dot4Avx2, the same sums in the same
// order, so that an output does not depend on whether it was computed alone or in a group.
__attribute__((target("avx2,fma"))) double dot1Avx2(const double* g, long len, const double* x) {
  __m256d a = _mm256_setzero_pd(), b = _mm256_setzero_pd();
  for (long j = 0; j < len; j += 8) {
    a = _mm256_fmadd_pd(_mm256_loadu_pd(g + j), _mm256_loadu_pd(x + j), a);
    b = _mm256_fmadd_pd(_mm256_loadu_pd(g + j + 4), _mm256_loadu_pd(x + j + 4), b);
  }
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, _mm256_add_pd(a, b));
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

// Stores the four sums to out[t os] (straight from the registers: reading them back from a
// vector store would stall).
__attribute__((target("avx2,fma"))) inline void store4(__m256d sum, double* out, long os) {
  if (os == 1) {
    _mm256_storeu_pd(out, sum);
    return;
  }
  const __m128d lo = _mm256_castpd256_pd128(sum), hi = _mm256_extractf128_pd(sum, 1);
  _mm_storel_pd(out, lo);
  _mm_storeh_pd(out + os, lo);
  _mm_storel_pd(out + 2 * os, hi);
  _mm_storeh_pd(out + 3 * os, hi);
}

// Output t is the sum of the lanes of a_t + b_t, as (0 + 1) + (2 + 3); hadd gives those pairs
// of two outputs side by side, so the four sums come at once.
__attribute__((target("avx2,fma"))) inline void finish4(__m256d a0, __m256d b0, __m256d a1, __m256d b1,
                                                        __m256d a2, __m256d b2, __m256d a3, __m256d b3,
                                                        double* out, long os) {
  const __m256d s01 = _mm256_hadd_pd(_mm256_add_pd(a0, b0), _mm256_add_pd(a1, b1));
  const __m256d s23 = _mm256_hadd_pd(_mm256_add_pd(a2, b2), _mm256_add_pd(a3, b3));
  store4(_mm256_add_pd(_mm256_permute2f128_pd(s01, s23, 0x20), _mm256_permute2f128_pd(s01, s23, 0x31)), out, os);
}

// out[t os] = sum_j g[j] x[t stride + j], t = 0..3.
__attribute__((target("avx2,fma"))) void dot4Avx2(const double* g, long len, const double* x,
                                                   long stride, double* out, long os) {
  const double *x0 = x, *x1 = x + stride, *x2 = x + 2 * stride, *x3 = x + 3 * stride;
  __m256d a0 = _mm256_setzero_pd(), a1 = _mm256_setzero_pd(), a2 = _mm256_setzero_pd(),
          a3 = _mm256_setzero_pd(), b0 = _mm256_setzero_pd(), b1 = _mm256_setzero_pd(),
          b2 = _mm256_setzero_pd(), b3 = _mm256_setzero_pd();
  for (long j = 0; j < len; j += 8) {
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
  finish4(a0, b0, a1, b1, a2, b2, a3, b3, out, os);
}

// dot4Avx2 for stride 4 (e.g. 2000 -> 1500 Hz): window t at taps j..j+3 is window t + 1 at
// taps j - 4..j - 1, so each input vector is loaded once and passed on; the same sums in
// the same order as dot4Avx2.
__attribute__((target("avx2,fma"))) void dot4Stride4Avx2(const double* g, long len, const double* x, double* out,
                                                          long os) {
  __m256d a0 = _mm256_setzero_pd(), a1 = _mm256_setzero_pd(), a2 = _mm256_setzero_pd(),
          a3 = _mm256_setzero_pd(), b0 = _mm256_setzero_pd(), b1 = _mm256_setzero_pd(),
          b2 = _mm256_setzero_pd(), b3 = _mm256_setzero_pd();
  __m256d v0 = _mm256_loadu_pd(x), v1 = _mm256_loadu_pd(x + 4), v2 = _mm256_loadu_pd(x + 8);
  for (long j = 0; j < len; j += 8) {
    const __m256d h = _mm256_loadu_pd(g + j), k = _mm256_loadu_pd(g + j + 4);
    const __m256d v3 = _mm256_loadu_pd(x + j + 12), v4 = _mm256_loadu_pd(x + j + 16);
    a0 = _mm256_fmadd_pd(h, v0, a0);
    a1 = _mm256_fmadd_pd(h, v1, a1);
    a2 = _mm256_fmadd_pd(h, v2, a2);
    a3 = _mm256_fmadd_pd(h, v3, a3);
    b0 = _mm256_fmadd_pd(k, v1, b0);
    b1 = _mm256_fmadd_pd(k, v2, b1);
    b2 = _mm256_fmadd_pd(k, v3, b2);
    b3 = _mm256_fmadd_pd(k, v4, b3);
    v0 = v2;
    v1 = v3;
    v2 = v4;
  }
  finish4(a0, b0, a1, b1, a2, b2, a3, b3, out, os);
}
#endif

struct Kernels {
  double (*dot1)(const double*, long, const double*) = dot1Portable;
  void (*dot4)(const double*, long, const double*, long, double*, long) = dot4Portable;
  long tapMultiple = 1;  // the phases' tap counts are padded with zeros to a multiple of this
  void (*dot4Stride4)(const double*, long, const double*, double*, long) = nullptr;  // when available
};

const Kernels& kernels() {
  static const Kernels k = [] {
    Kernels s;
#ifdef FLEXARM_AVX2_KERNELS
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
      s.dot1 = dot1Avx2;
      s.dot4 = dot4Avx2;
      s.tapMultiple = 8;
      s.dot4Stride4 = dot4Stride4Avx2;
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
    // Zero taps at the end leave every sum as it is and let the kernels skip their tails.
    const long multiple = kernels().tapMultiple;
    while (static_cast<long>(ph.taps.size()) % multiple) ph.taps.push_back(0.0);
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

// Outputs [kb, ke) of one channel, phase by phase (see firBlock).
template <class Edge>
void firStretch(const FirPlan& plan, const std::vector<double>& x, std::size_t kb, std::size_t ke, double* y,
                const Edge& edge) {
  const Kernels& k = kernels();
  const long n = static_cast<long>(x.size());
  const std::uint64_t L = static_cast<std::uint64_t>(plan.up), M = static_cast<std::uint64_t>(plan.down);
  const std::size_t up = static_cast<std::size_t>(plan.up);
  const long stride = static_cast<long>(M);
  const std::size_t classes = std::min<std::size_t>(up, ke - kb);
  for (std::size_t s = 0; s < classes; ++s) {
    const std::size_t k0 = kb + s;
    const std::uint64_t pos = static_cast<std::uint64_t>(k0) * M;
    const Phase& ph = plan.phases[static_cast<std::size_t>(pos % L)];
    const double* taps = ph.taps.data();
    const long len = static_cast<long>(ph.taps.size());
    const long first = plan.whole + static_cast<long>(pos / L) + ph.start;  // window of output k0
    const long count = static_cast<long>((ke - k0 + up - 1) / up);          // outputs of this phase
    double* out = y + s;
    // Groups of four whose windows all lie inside the input: [g0, g1).
    const long g0 = first >= 0 ? 0 : (-first + 4 * stride - 1) / (4 * stride);
    const long room = n - len - 3 * stride - first;  // base + 3 stride + len <= n
    const long g1 = std::min(count / 4, room < 0 ? 0 : room / (4 * stride) + 1);
    long t = 0;
    for (; t < std::min(4 * g0, count); ++t) out[static_cast<std::size_t>(t) * up] = edge(ph, first + t * stride);
    const double* xp = x.data() + first + t * stride;
    const long os = static_cast<long>(up);
    if (stride == 4 && k.dot4Stride4) {
      for (; t < 4 * g1; t += 4, xp += 16) k.dot4Stride4(taps, len, xp, out + static_cast<std::size_t>(t) * up, os);
    } else {
      for (; t < 4 * g1; t += 4, xp += 4 * stride) k.dot4(taps, len, xp, stride, out + static_cast<std::size_t>(t) * up, os);
    }
    for (; t < count; ++t) out[static_cast<std::size_t>(t) * up] = edge(ph, first + t * stride);
  }
}

// Outputs [kb, ke) of one channel through the polyphase FIR.
void firBlock(const FirPlan& plan, const std::vector<double>& x, std::size_t kb, std::size_t ke,
              double* y) {
  const Kernels& k = kernels();
  const long n = static_cast<long>(x.size());
  std::vector<double> scratch;
  // One output whose window may reach past the ends: gather the extended input first.
  auto edge = [&](const Phase& ph, long base) {
    const long len = static_cast<long>(ph.taps.size());
    if (base >= 0 && base + len <= n) return k.dot1(ph.taps.data(), len, x.data() + base);
    scratch.resize(static_cast<std::size_t>(len));
    for (long j = 0; j < len; ++j) scratch[static_cast<std::size_t>(j)] = extended(x, base + j);
    return dot1Portable(ph.taps.data(), len, scratch.data());
  };
  // Outputs k, k + up, k + 2 up, ... share a phase and lie `down` input samples apart. The
  // phases take turns over short stretches of output, so that the input they share is read
  // from the cache rather than from memory once per phase.
  const std::size_t stretch = 256 * static_cast<std::size_t>(plan.up);
  for (std::size_t sb = kb; sb < ke; sb += stretch) {
    const std::size_t se = std::min(ke, sb + stretch);
    firStretch(plan, x, sb, se, y + (sb - kb), edge);
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
