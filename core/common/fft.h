#pragma once
// Real-to-complex discrete Fourier transform X(k) = sum_t x(t) e^{-i 2 pi k t / n},
// k = 0..n/2, through FFTW, safe to use from any number of threads at once.
// FFTW's planner (making and destroying plans) is not thread-safe: two threads planning at
// the same moment can get a NULL or corrupt plan. Every FFTW plan in FlexArm is made and
// destroyed here, under one lock, and checked; executing a plan needs no lock.
#include <complex>
#include <vector>

namespace flexarm {

class RealFft {
 public:
  // A transform of n >= 1 points. Throws std::invalid_argument for n < 1 and
  // std::runtime_error when FFTW cannot plan it (out of memory).
  explicit RealFft(int n);
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;

  int size() const { return n_; }
  int bins() const { return n_ / 2 + 1; }
  // The n input values; fill them, then call transform().
  double* input() { return in_; }
  // Transforms input() and returns bins() values (valid until the next call).
  const std::complex<double>* transform();

 private:
  int n_ = 0;
  double* in_ = nullptr;
  void* out_ = nullptr;   // fftw_complex[bins]
  void* plan_ = nullptr;  // fftw_plan
};

// One-shot transform of x[0..n-1]: the n/2 + 1 bins.
std::vector<std::complex<double>> realDft(const double* x, int n);

}  // namespace flexarm
