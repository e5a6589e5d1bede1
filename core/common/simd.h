#pragma once
// Vectors of doubles for the few inner loops that gain from explicit SIMD (the vector
// extension of GCC and Clang): lane-wise IEEE arithmetic, so that sums kept in lanes and
// added up in a fixed order give the same result whether a vector holds two doubles (SSE2,
// every x86-64) or four (AVX2). A kernel is written once as an always-inline template over
// the vector type and instantiated twice: in a plain function with Lanes2 and in a function
// marked FLEXARM_AVX2 with Lanes4, chosen at run time by hasAvx2().
#include <cstring>

namespace flexarm::simd {

typedef double Lanes2 __attribute__((vector_size(16)));
typedef double Lanes4 __attribute__((vector_size(32)));

template <class V>
constexpr int kLanes = static_cast<int>(sizeof(V) / sizeof(double));

// Loads and stores at any alignment (vectors are passed by reference: a four-lane vector
// returned by value would change the calling convention of code built without AVX).
template <class V>
inline __attribute__((always_inline)) void load(V& v, const double* p) {
  std::memcpy(&v, p, sizeof v);
}
template <class V>
inline __attribute__((always_inline)) void store(double* p, const V& v) {
  std::memcpy(p, &v, sizeof v);
}

#if defined(__x86_64__) && defined(__GNUC__)
#define FLEXARM_AVX2 __attribute__((target("avx2")))
// True when the processor runs AVX2 code.
inline bool hasAvx2() {
  static const bool yes = [] {
    __builtin_cpu_init();  // needed when called before the runtime's own initialisation
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return yes;
}
#else
#define FLEXARM_AVX2
inline bool hasAvx2() { return false; }
#endif

}  // namespace flexarm::simd
