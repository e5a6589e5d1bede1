#include "core/common/fft.h"

#include <fftw3.h>

#include <algorithm>
#include <mutex>
#include <stdexcept>
#include <string>

namespace flexarm {
namespace {

// The one lock around FFTW's planner: fftw_plan_* and fftw_destroy_plan.
std::mutex& plannerMutex() {
  static std::mutex m;
  return m;
}

}  // namespace

RealFft::RealFft(int n) : n_(n) {
  if (n < 1) throw std::invalid_argument("a Fourier transform needs at least one point");
  in_ = fftw_alloc_real(static_cast<std::size_t>(n));
  fftw_complex* out = fftw_alloc_complex(static_cast<std::size_t>(bins()));
  out_ = out;
  fftw_plan plan = nullptr;
  if (in_ && out) {
    std::lock_guard<std::mutex> lock(plannerMutex());
    plan = fftw_plan_dft_r2c_1d(n, in_, out, FFTW_ESTIMATE);
  }
  if (!plan) {
    fftw_free(in_);
    fftw_free(out);
    throw std::runtime_error("FFTW could not plan a Fourier transform of " + std::to_string(n) +
                             " points (out of memory?)");
  }
  plan_ = plan;
}

RealFft::~RealFft() {
  {
    std::lock_guard<std::mutex> lock(plannerMutex());
    fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  }
  fftw_free(in_);
  fftw_free(out_);
}

const std::complex<double>* RealFft::transform() {
  fftw_execute(static_cast<fftw_plan>(plan_));
  // fftw_complex is double[2], laid out as std::complex<double> (FFTW manual, 4.1.1).
  return reinterpret_cast<const std::complex<double>*>(out_);
}

std::vector<std::complex<double>> realDft(const double* x, int n) {
  RealFft fft(n);
  std::copy(x, x + n, fft.input());
  const std::complex<double>* X = fft.transform();
  return std::vector<std::complex<double>>(X, X + fft.bins());
}

}  // namespace flexarm
