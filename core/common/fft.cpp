#include "core/common/fft.h"

#include <fftw3.h>

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

namespace flexarm {

namespace {

// The one lock around FFTW's planner: fftw_plan_* and fftw_destroy_plan.
std::mutex& plannerMutex() {
  static std::mutex m;
  return m;
}

// A plan depends on the length and on the arrays' alignment (FFTW's SIMD code assumes the
// alignment the plan was made with, fftw_alignment_of); it is destroyed, under the planner's
// lock, when the cache has dropped it and no transform is running with it.
using Plan = std::shared_ptr<std::remove_pointer_t<fftw_plan>>;
using Key = std::tuple<int, int, int>;

Plan makePlan(int n, int inAlign, int outAlign) {
  // Arrays with the callers' alignment (in bytes past FFTW's alignment) to plan with;
  // FFTW_ESTIMATE neither reads nor writes them.
  const int pad = 8;
  double* in = fftw_alloc_real(static_cast<std::size_t>(n + pad));
  fftw_complex* out = fftw_alloc_complex(static_cast<std::size_t>(n / 2 + 1 + pad));
  if (!in || !out) {
    fftw_free(in);
    fftw_free(out);
    throw std::bad_alloc();
  }
  auto* inAt = reinterpret_cast<double*>(reinterpret_cast<char*>(in) + inAlign);
  auto* outAt = reinterpret_cast<fftw_complex*>(reinterpret_cast<char*>(out) + outAlign);
  fftw_plan p = fftw_plan_dft_r2c_1d(n, inAt, outAt, FFTW_ESTIMATE | FFTW_PRESERVE_INPUT);
  fftw_free(in);
  fftw_free(out);
  if (!p)
    throw std::runtime_error("FFTW could not plan a Fourier transform of " + std::to_string(n) +
                             " points (out of memory?)");
  return Plan(p, [](fftw_plan q) {
    std::lock_guard<std::mutex> lock(plannerMutex());
    fftw_destroy_plan(q);
  });
}

// The last few plans, most recently used first.
Plan cachedPlan(int n, int inAlign, int outAlign) {
  constexpr std::size_t kKept = 8;
  std::mutex& mutex = plannerMutex();  // made before the cache, so it outlives the cache
  static std::list<std::pair<Key, Plan>> cache;
  const Key key{n, inAlign, outAlign};
  Plan dropped;  // released after the lock: its deleter takes the lock itself
  std::lock_guard<std::mutex> lock(mutex);
  for (auto it = cache.begin(); it != cache.end(); ++it)
    if (it->first == key) {
      cache.splice(cache.begin(), cache, it);
      return it->second;
    }
  // (the plan is made under the lock: fftw_plan_* must not run concurrently)
  Plan p = makePlan(n, inAlign, outAlign);
  cache.emplace_front(key, p);
  if (cache.size() > kKept) {
    dropped = std::move(cache.back().second);
    cache.pop_back();
  }
  return p;
}

}  // namespace

void realDft(const double* x, int n, std::complex<double>* X) {
  if (n < 1) throw std::invalid_argument("a Fourier transform needs at least one point");
  auto* in = const_cast<double*>(x);  // FFTW_PRESERVE_INPUT: x is only read
  auto* out = reinterpret_cast<fftw_complex*>(X);  // double[2], as std::complex (FFTW 4.1.1)
  const Plan plan =
      cachedPlan(n, fftw_alignment_of(in), fftw_alignment_of(reinterpret_cast<double*>(out)));
  fftw_execute_dft_r2c(plan.get(), in, out);
}

}  // namespace flexarm
