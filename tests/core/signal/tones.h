#pragma once
// Sinusoids and their measured amplitudes, shared by the filtering and resampling tests.
#include <cmath>
#include <complex>
#include <cstddef>
#include <vector>

namespace flexarm::testing {

inline constexpr double kPi = 3.14159265358979323846;

inline std::vector<double> tone(std::size_t n, double fs, double f, double amplitude, double phase = 0.3) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = amplitude * std::sin(2 * kPi * f * i / fs + phase);
  return x;
}

// Amplitude of the component at frequency f (Hz) in x sampled at fs, by projection on the
// interior samples [skip, n - skip).
inline double amplitudeAt(const std::vector<double>& x, double fs, double f, std::size_t skip) {
  std::complex<double> acc = 0;
  std::size_t count = 0;
  for (std::size_t i = skip; i + skip < x.size(); ++i, ++count)
    acc += x[i] * std::exp(std::complex<double>(0, -2 * kPi * f * i / fs));
  return 2.0 * std::abs(acc) / static_cast<double>(count);
}

}  // namespace flexarm::testing
