#pragma once
// Reproducible random numbers: std::mt19937_64 (its output sequence is fixed by the standard)
// with the uniform and normal distributions implemented here, because the std distributions
// may differ between library versions and the sample logs must regenerate bit-identically.
#include <cstdint>
#include <random>

namespace flexarm {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  std::uint64_t next() { return engine_(); }
  // Uniform on [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // Standard normal by the Box-Muller transform (the second value of a pair is kept).
  double normal();

 private:
  std::mt19937_64 engine_;
  bool haveSpare_ = false;
  double spare_ = 0.0;
};

}  // namespace flexarm
