#include "core/ident/poly_predictor.h"

#include "core/common/simd.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace flexarm {

namespace {

// The past of one signal as the pass reads it, x(t - k) for k >= 1. Past<L> holds the last L
// values in locals (registers), so that a recursion never waits for its own store to reach
// memory; Past<0> reads them back from the stored signal x.
template <int L>
struct Past {
  double h[L] = {};
  double at(const double*, Eigen::Index, int k) const { return h[k - 1]; }
  void push(double now) {
    for (int k = L - 1; k > 0; --k) h[k] = h[k - 1];
    h[0] = now;
  }
};
template <>
struct Past<0> {
  double at(const double* x, Eigen::Index t, int k) const { return x[t - k]; }
  void push(double) {}
};

// x(t) + sum_{k=1}^{order} num[k] x(t - k) for a monic num, in the order of k (as filter()
// sums). Order > 0 fixes the count at compile time (coefficients beyond the order are zero).
template <int Order, class P>
inline double monic(double now, const double* num, const P& past, const double* x,
                    Eigen::Index t, int order) {
  const int m = Order > 0 ? Order : order;
  double s = now;
  for (int k = 1; k <= m; ++k) s += num[k] * past.at(x, t, k);
  return s;
}

// sum_{k < taps} num[k] x(t - k), in the order of k.
template <int Taps>
inline double fir(const double* num, const double* x, Eigen::Index t, int taps) {
  const int m = Taps > 0 ? Taps : taps;
  double s = num[0] * x[t];
  for (int k = 1; k < m; ++k) s += num[k] * x[t - k];
  return s;
}

// s - sum_{k=1}^{order} den[k] y(t - k), the lag-one term last: it is the only one that waits
// for the previous sample (filter()'s order of operations).
template <int Order, class P>
inline double iir(double s, const double* den, const P& past, const double* y, Eigen::Index t,
                  int order) {
  const int m = Order > 0 ? Order : order;
  for (int k = m; k >= 2; --k) s -= den[k] * past.at(y, t, k);
  return s - den[1] * past.at(y, t, 1);
}

// N consecutive samples of a signal (N = 2: a step of the two-sample recursions below).
template <int N>
struct Run {
  double x[N];
  double operator[](int i) const { return x[i]; }
  double& operator[](int i) { return x[i]; }
};

template <int N>
inline Run<N> load(const double* x, Eigen::Index t) {
  Run<N> r;
  for (int i = 0; i < N; ++i) r[i] = x[t + i];
  return r;
}

template <int N>
inline void store(double* x, Eigen::Index t, const Run<N>& r) {
  for (int i = 0; i < N; ++i) x[t + i] = r[i];
}

template <int N, class P>
inline void push(P& past, const Run<N>& r) {
  for (int i = 0; i < N; ++i) past.push(r[i]);
}

// B u over the record at t, t+1, ...
template <int N, int Taps>
inline Run<N> firRun(const double* num, const double* x, Eigen::Index t, int taps) {
  Run<N> r;
  for (int i = 0; i < N; ++i) r[i] = fir<Taps>(num, x, t + i, taps);
  return r;
}

// A y (monic) over the record.
template <int N, int Order>
inline Run<N> monicRun(const double* num, const double* x, Eigen::Index t, int order) {
  Run<N> r;
  for (int i = 0; i < N; ++i) r[i] = monic<Order>(x[t + i], num, Past<0>{}, x, t + i, order);
  return r;
}

// D x (monic) of a signal whose current samples are `now` and whose past is in `past`.
template <int N, int Order, class P>
inline Run<N> monicRun(const Run<N>& now, const double* num, const P& past, const double* x,
                       Eigen::Index t, int order) {
  Run<N> r;
  r[0] = monic<Order>(now[0], num, past, x, t, order);
  if constexpr (N == 2) {
    P next = past;
    next.push(now[0]);
    r[1] = monic<Order>(now[1], num, next, x, t + 1, order);
  }
  return r;
}

// The recursion x(t) = s(t) - sum_k den[k] x(t - k) for N samples. With N = 2 both come from
// the past before t, x(t+1) = s(t+1) - den[1] s(t) + sum_k den2[k] x(t - k) with
// den2[k] = den[1] den[k] - den[k+1] (the recursion applied twice): two samples per wait for
// the newest one instead of one, the same values up to rounding.
template <int N, int Order, class P>
inline Run<N> iirRun(const Run<N>& s, const double* den, const double* den2, const P& past,
                     const double* y, Eigen::Index t, int order) {
  Run<N> r;
  r[0] = iir<Order>(s[0], den, past, y, t, order);
  if constexpr (N == 2) {
    double x = s[1] - den[1] * s[0];
    for (int k = Order; k >= 2; --k) x += den2[k] * past.at(y, t, k);
    r[1] = x + den2[1] * past.at(y, t, 1);
  }
  return r;
}

// sums[k] += sum_{i < len} a[k][i] b[k][i] for G pairs, every sum in four running parts
// (samples 4m, 4m+1, 4m+2, 4m+3, in the lanes of vectors V) added up as ((0 + 1) + (2 + 3))
// with the tail after them: independent additions that need not wait for each other, and the
// same result for two or four lanes to a vector.
template <class V, int G>
inline __attribute__((always_inline)) void addProducts(const double* const* a,
                                                       const double* const* b, Eigen::Index len,
                                                       double* sums) {
  constexpr int L = simd::kLanes<V>, Q = 4 / L;
  V acc[G][Q];
  for (int k = 0; k < G; ++k)
    for (int q = 0; q < Q; ++q) acc[k][q] = V{};
  Eigen::Index i = 0;
  for (; i + 4 <= len; i += 4)
    for (int k = 0; k < G; ++k)
      for (int q = 0; q < Q; ++q) {
        V x, z;
        simd::load(x, a[k] + i + q * L);
        simd::load(z, b[k] + i + q * L);
        acc[k][q] += x * z;
      }
  for (int k = 0; k < G; ++k) {
    double part[4];
    for (int q = 0; q < Q; ++q) simd::store(part + q * L, acc[k][q]);
    double tail = 0.0;
    for (Eigen::Index j = i; j < len; ++j) tail += a[k][j] * b[k][j];
    sums[k] += ((part[0] + part[1]) + (part[2] + part[3])) + tail;
  }
}

template <class V>
inline __attribute__((always_inline)) void addProducts(const double* const* a,
                                                       const double* const* b,
                                                       std::size_t count, Eigen::Index len,
                                                       double* sums) {
  std::size_t k = 0;
  for (; k + 4 <= count; k += 4) addProducts<V, 4>(a + k, b + k, len, sums + k);
  for (; k < count; ++k) addProducts<V, 1>(a + k, b + k, len, sums + k);
}

FLEXARM_AVX2 void addProductsAvx2(const double* const* a, const double* const* b,
                                  std::size_t count, Eigen::Index len, double* sums) {
  addProducts<simd::Lanes4>(a, b, count, len, sums);
}

void addProducts(const double* const* a, const double* const* b, std::size_t count,
                 Eigen::Index len, double* sums) {
  if (simd::hasAvx2()) return addProductsAvx2(a, b, count, len, sums);
  addProducts<simd::Lanes2>(a, b, count, len, sums);
}

// p from index `first` on, zero-padded to at least `size` entries (and at least two).
std::vector<double> padded(const Poly& p, std::size_t first, std::size_t size) {
  std::vector<double> out(std::max<std::size_t>({size, 2, p.size() > first ? p.size() - first : 0}),
                          0.0);
  std::copy(p.begin() + static_cast<std::ptrdiff_t>(std::min(first, p.size())), p.end(),
            out.begin());
  return out;
}

}  // namespace

// The predictor's coefficients, zero-padded to the compile-time order K of the pass (K = 0:
// the model's own orders).
struct PolyPredictor::Coefficients {
  int nk = 0, lb = 0, la = 0, lc = 0, ld = 0, lf = 0, lcf = 0;
  std::vector<double> b, a, c, d, f, cf;

  Coefficients(const PolynomialModel& m, int K, bool noise) {
    const auto& o = m.orders;
    nk = o.nk;
    lb = K ? K : o.nb;
    la = K ? K : o.na;
    lc = K ? K : o.nc;
    ld = K ? K : o.nd;
    lf = K ? K : o.nf;
    lcf = K ? (noise ? 2 * K : K) : o.nc + o.nf;
    const std::size_t size = static_cast<std::size_t>(std::max(K, 1) * 2 + 1);
    b = padded(m.b, static_cast<std::size_t>(nk), size);
    f = padded(m.f, 0, size);
    a = padded(m.a, 0, size);
    c = padded(m.c, 0, size);
    d = padded(m.d, 0, size);
    cf = padded(polyMultiply(m.c, m.f), 0, size);
  }
};

Eigen::Index PolyPredictor::criterionStart(const PolyOrders& o, Eigen::Index samples) {
  return std::min<Eigen::Index>(std::max({o.na, o.nb + o.nk - 1, o.nc, o.nd, o.nf}), samples);
}

PolyPredictor::PolyPredictor(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                             const PolyOrders& orders)
    : u_(u), y_(y), orders_(orders), n_(y.size()), first_(criterionStart(orders, y.size())) {
  if (u.size() != y.size())
    throw std::invalid_argument("PolyPredictor: input and output differ in length");
  // The longest look back of any filter or column (the fixed-order passes read up to twice
  // four lags).
  const int top = std::max({4, orders.na, orders.nb, orders.nc, orders.nd, orders.nf});
  pad_ = orders.nk + 2 * top + 2;
  const Eigen::Index headLength = std::min(n_, pad_ + kBlock);
  uHead_.assign(static_cast<std::size_t>(pad_ + headLength), 0.0);
  yHead_.assign(uHead_.size(), 0.0);
  std::copy(u.data(), u.data() + headLength, uHead_.begin() + pad_);
  std::copy(y.data(), y.data() + headLength, yHead_.begin() + pad_);
}

template <int K, bool Noise, bool HasF, bool Gradient>
void PolyPredictor::pass(const Coefficients& c, double* epsOut) {
  constexpr int LB = K, LC = K, LF = K, LCF = K ? (Noise ? 2 * K : K) : 0;
  // Fixed orders: the coefficients as locals, which no store to a signal can change, so they
  // stay in registers; and those of the recursions applied twice (see iirRun).
  constexpr int S = K ? 2 * K + 1 : 1;
  double lb[S], lf[S], la[S], lc[S], ld[S], lcf[S], lf2[S], lc2[S], lcf2[S];
  if (K) {
    for (int k = 0; k < S; ++k) {
      lb[k] = c.b[k];
      lf[k] = c.f[k];
      la[k] = c.a[k];
      lc[k] = c.c[k];
      ld[k] = c.d[k];
      lcf[k] = c.cf[k];
    }
    const auto twice = [](const double* den, double* den2) {
      for (int k = 1; k < S; ++k) den2[k] = den[1] * den[k] - (k + 1 < S ? den[k + 1] : 0.0);
    };
    twice(lf, lf2);
    twice(lc, lc2);
    twice(lcf, lcf2);
  }
  const double* B = K ? lb : c.b.data();
  const double* F = K ? lf : c.f.data();
  const double* A = K ? la : c.a.data();
  const double* C = K ? lc : c.c.data();
  const double* D = K ? ld : c.d.data();
  // Without a noise model C F is F: one set of registers.
  const double* CF = Noise ? (K ? lcf : c.cf.data()) : F;
  const double* F2 = lf2;
  const double* C2 = lc2;
  const double* CF2 = Noise ? lcf2 : lf2;
  const auto& o = orders_;
  const bool hasA = o.na > 0;
  // Without a noise model uf = u/F comes first, also without the gradient: w = B/F u = B uf.
  constexpr bool ufFirst = !Noise && HasF;
  const bool doYf = Gradient && Noise && hasA, doUf = Gradient && Noise, doWf = Gradient && HasF,
             doEf = Gradient && Noise && o.nc > 0, doVf = Gradient && Noise && o.nd > 0;
  const auto out = [&](Signal s) { return block_[s].empty() ? nullptr : block_[s].data() + pad_; };
  double* __restrict w = out(W);
  double* __restrict e = out(E);
  double* __restrict v = out(V);
  double* __restrict yf = out(YF);
  double* __restrict uf = out(UF);
  double* __restrict wf = out(WF);
  double* __restrict ef = out(EF);
  double* __restrict vf = out(VF);
  // One loop for every signal: their recursions are independent chains that overlap.
  Past<K> pw, pv, pe, pyf, pef, pvf;
  Past<LCF> puf, pwf;
  for (Eigen::Index t0 = 0, len = 0; t0 < n_; t0 += len) {
    startBlock(t0, len);
    len = std::min<Eigen::Index>(n_ - t0, kBlock);
    const double* __restrict u = base_[U];
    const double* __restrict y = base_[Y];
    const double* __restrict uk = u - c.nk;
    // Samples t .. t+N-1 of every signal.
    const auto step = [&](auto samples, Eigen::Index t) {
      constexpr int N = decltype(samples)::value;
      Run<N> wr;  // w = B/F u
      if constexpr (ufFirst) {
        const Run<N> x = iirRun<N, LF>(load<N>(u, t), F, F2, puf, uf, t, c.lf);
        store(uf, t, x);
        push(puf, x);
        wr = firRun<N, LB>(B, uf - c.nk, t, c.lb);
      } else {
        wr = firRun<N, LB>(B, uk, t, c.lb);
        if (HasF) wr = iirRun<N, LF>(wr, F, F2, pw, w, t, c.lf);
      }
      store(w, t, wr);
      Run<N> vr = hasA ? monicRun<N, K>(A, y, t, c.la) : load<N>(y, t);  // v = A y - w
      for (int i = 0; i < N; ++i) vr[i] -= wr[i];
      Run<N> er = vr;  // eps = D/C v
      if (Noise) {
        store(v, t, vr);
        er = iirRun<N, LC>(monicRun<N, K>(vr, D, pv, v, t, c.ld), C, C2, pe, e, t, c.lc);
      }
      store(e, t, er);
      if (Gradient) {
        if (doYf) {
          const Run<N> x = iirRun<N, LC>(monicRun<N, K>(D, y, t, c.ld), C, C2, pyf, yf, t, c.lc);
          store(yf, t, x);
          push(pyf, x);
        }
        if (doUf) {
          const Run<N> in = monicRun<N, K>(D, u, t, c.ld);
          const Run<N> x = iirRun<N, LCF>(in, CF, CF2, puf, uf, t, c.lcf);
          store(uf, t, x);
          push(puf, x);
        }
        if (doWf) {
          const Run<N> in = Noise ? monicRun<N, K>(wr, D, pw, w, t, c.ld) : wr;
          const Run<N> x = iirRun<N, LCF>(in, CF, CF2, pwf, wf, t, c.lcf);
          store(wf, t, x);
          push(pwf, x);
        }
        if (doEf) {
          const Run<N> x = iirRun<N, LC>(er, C, C2, pef, ef, t, c.lc);
          store(ef, t, x);
          push(pef, x);
        }
        if (doVf) {
          const Run<N> x = iirRun<N, LC>(vr, C, C2, pvf, vf, t, c.lc);
          store(vf, t, x);
          push(pvf, x);
        }
      }
      push(pw, wr);
      push(pv, vr);
      push(pe, er);
    };
    Eigen::Index t = 0;
    if constexpr (K > 0)  // two samples a step while the past is held in registers
      for (; t + 2 <= len; t += 2) step(std::integral_constant<int, 2>{}, t);
    for (; t < len; ++t) step(std::integral_constant<int, 1>{}, t);
    if (!accumulate(t0, t0 + len, epsOut)) return;
  }
}

void PolyPredictor::startBlock(Eigen::Index t0, Eigen::Index previousLength) {
  for (std::size_t s = 0; s < kSignals; ++s) {
    auto& b = block_[s];
    if (b.empty()) continue;
    if (t0 == 0)  // the zero initial conditions
      std::fill(b.begin(), b.begin() + pad_, 0.0);
    else  // the last pad_ samples become the past of the next block
      std::copy(b.begin() + previousLength, b.begin() + previousLength + pad_, b.begin());
    base_[s] = b.data() + pad_;
  }
  // Inputs: the record itself once pad_ samples lie before the block, else the padded head.
  base_[U] = t0 >= pad_ ? u_.data() + t0 : uHead_.data() + pad_ + t0;
  base_[Y] = t0 >= pad_ ? y_.data() + t0 : yHead_.data() + pad_ + t0;
  blockStart_ = t0;
}

double PolyPredictor::run(const PolynomialModel& m, Eigen::MatrixXd* R, Eigen::VectorXd* g,
                          double bound) {
  return evaluate(m, R, g, bound, nullptr);
}

Eigen::VectorXd PolyPredictor::errors(const PolynomialModel& m) {
  Eigen::VectorXd eps(n_);
  evaluate(m, nullptr, nullptr, INFINITY, eps.data());
  return eps;
}

double PolyPredictor::evaluate(const PolynomialModel& m, Eigen::MatrixXd* R, Eigen::VectorXd* g,
                               double bound, double* epsOut) {
  const auto& o = m.orders;
  if (o.na != orders_.na || o.nb != orders_.nb || o.nc != orders_.nc || o.nd != orders_.nd ||
      o.nf != orders_.nf || o.nk != orders_.nk)
    throw std::invalid_argument("PolyPredictor: the model's orders differ from the predictor's");
  const auto sized = [](const Poly& p, int order) {
    return p.size() == static_cast<std::size_t>(order) + 1 && p[0] == 1.0;
  };
  if (!sized(m.a, o.na) || !sized(m.c, o.nc) || !sized(m.d, o.nd) || !sized(m.f, o.nf) ||
      m.b.size() != static_cast<std::size_t>(o.nk + o.nb))
    throw std::invalid_argument(
        "PolyPredictor: A, C, D and F must be monic and every polynomial of its order (4.8)");
  const bool noise = o.nc > 0 || o.nd > 0, hasF = o.nf > 0;
  const bool gradient = R != nullptr && g != nullptr;
  const int top = std::max({o.na, o.nb, o.nc, o.nd, o.nf});
  const int K = top <= 2 ? 2 : top <= 4 ? 4 : 0;
  const Coefficients c(m, K, noise);
  const auto need = [&](Signal s, bool used) {
    if (used && block_[s].empty()) block_[s].assign(static_cast<std::size_t>(pad_ + kBlock), 0.0);
  };
  need(W, true);
  need(E, true);
  need(V, noise);
  need(YF, gradient && o.na > 0 && noise);
  need(UF, noise ? gradient : hasF);
  need(WF, gradient && hasF);
  need(EF, gradient && o.nc > 0);
  need(VF, gradient && o.nd > 0);
  prepare(gradient, noise);
  bound_ = bound;
  const auto withGradient = [&](auto k, auto noiseModel, auto outputFilter) {
    constexpr int Kc = decltype(k)::value;
    constexpr bool N = decltype(noiseModel)::value, F = decltype(outputFilter)::value;
    gradient ? pass<Kc, N, F, true>(c, epsOut) : pass<Kc, N, F, false>(c, epsOut);
  };
  const auto go = [&](auto k) {
    using Yes = std::true_type;
    using No = std::false_type;
    if (noise)
      hasF ? withGradient(k, Yes{}, Yes{}) : withGradient(k, Yes{}, No{});
    else
      hasF ? withGradient(k, No{}, Yes{}) : withGradient(k, No{}, No{});
  };
  if (K == 2)
    go(std::integral_constant<int, 2>{});
  else if (K == 4)
    go(std::integral_constant<int, 4>{});
  else
    go(std::integral_constant<int, 0>{});
  if (gradient && !(sums_[0] > bound)) finish(*R, *g);
  return sums_[0];
}

void PolyPredictor::prepare(bool gradient, bool noise) {
  const auto& o = orders_;
  columns_.clear();
  direct_.clear();
  sums_.assign(1, 0.0);
  if (!gradient) return;
  int block = 0;
  const auto add = [&](Signal s, double sign, int firstLag, int count) {
    for (int k = 0; k < count; ++k) columns_.push_back({s, sign, firstLag + k, block});
    ++block;
    if (count > 0 && s != U && s != Y) head_[s].assign(static_cast<std::size_t>(first_ + 1), 0.0);
  };
  add(noise ? YF : Y, -1.0, 1, o.na);
  add(noise || o.nf > 0 ? UF : U, 1.0, o.nk, o.nb);
  add(EF, 1.0, 1, o.nc);
  add(VF, -1.0, 1, o.nd);
  add(WF, -1.0, 1, o.nf);
  // Within a pair of blocks R is Toeplitz up to the ends of the sum (see finish()): only the
  // entries whose upper-left neighbour lies in another block are summed over the samples.
  const int p = static_cast<int>(columns_.size());
  for (int i = 0; i < p; ++i)
    for (int j = i; j < p; ++j)
      if (!walks(i, j)) direct_.push_back({i, j});
  sums_.assign(1 + columns_.size() + direct_.size(), 0.0);
}

bool PolyPredictor::walks(int i, int j) const {
  const auto blockOf = [&](int k) { return columns_[static_cast<std::size_t>(k)].block; };
  return i > 0 && blockOf(i - 1) == blockOf(i) && blockOf(j - 1) == blockOf(j);
}

bool PolyPredictor::accumulate(Eigen::Index t0, Eigen::Index t1, double* epsOut) {
  const double* e = base_[E];
  if (epsOut) std::copy(e, e + (t1 - t0), epsOut + t0);
  // The first samples of each signal, for the Toeplitz walk's start terms.
  if (!columns_.empty())
    for (std::size_t s = W; s < kSignals; ++s)
      if (!head_[s].empty())
        for (Eigen::Index t = t0; t < std::min(t1, first_ + 1); ++t)
          head_[s][static_cast<std::size_t>(t)] = base_[s][t - t0];
  const Eigen::Index lo = std::max(t0, first_);
  if (lo >= t1) return true;
  const Eigen::Index off = lo - t0, len = t1 - lo;
  // One list of products: eps eps, each column with eps, and R's directly summed entries.
  const auto at = [&](int j) {
    const Column& c = columns_[static_cast<std::size_t>(j)];
    return base_[c.signal] + off - c.lag;
  };
  const double* eps = e + off;
  left_.assign(1, eps);
  right_.assign(1, eps);
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    left_.push_back(at(static_cast<int>(j)));
    right_.push_back(eps);
  }
  for (const auto& d : direct_) {
    left_.push_back(at(d[0]));
    right_.push_back(at(d[1]));
  }
  addProducts(left_.data(), right_.data(), left_.size(), len, sums_.data());
  return !(sums_[0] > bound_);  // the rest can only add to the sum of squares
}

double PolyPredictor::valueAt(Signal s, Eigen::Index t) const {
  if (t < 0) return 0.0;
  if (s == U) return u_[t];
  if (s == Y) return y_[t];
  if (t <= first_) return head_[s][static_cast<std::size_t>(t)];
  return base_[s][t - blockStart_];  // the end of the record: in the last block or its past
}

void PolyPredictor::finish(Eigen::MatrixXd& R, Eigen::VectorXd& g) const {
  const int p = static_cast<int>(columns_.size());
  const auto column = [&](int k) -> const Column& { return columns_[static_cast<std::size_t>(k)]; };
  R.resize(p, p);
  g.resize(p);
  for (int i = 0; i < p; ++i) g[i] = column(i).sign * sums_[1 + static_cast<std::size_t>(i)];
  for (std::size_t k = 0; k < direct_.size(); ++k) {
    const int i = direct_[k][0], j = direct_[k][1];
    R(i, j) = column(i).sign * column(j).sign * sums_[1 + columns_.size() + k];
  }
  // S(a, b) = sum_{t=n0}^{N-1} x(t-a) z(t-b) = S(a-1, b-1) + x(n0-a) z(n0-b) - x(N-a) z(N-b).
  const Eigen::Index n0 = first_;
  for (int i = 0; i < p; ++i)
    for (int j = i; j < p; ++j) {
      if (walks(i, j)) {
        const Column &ci = column(i), &cj = column(j);
        const int a = ci.lag, b = cj.lag;
        R(i, j) = R(i - 1, j - 1) +
                  ci.sign * cj.sign *
                      (valueAt(ci.signal, n0 - a) * valueAt(cj.signal, n0 - b) -
                       valueAt(ci.signal, n_ - a) * valueAt(cj.signal, n_ - b));
      }
      R(j, i) = R(i, j);
    }
}

}  // namespace flexarm
