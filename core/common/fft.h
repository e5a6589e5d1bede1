#pragma once
// The real-input DFT of FlexArm (FFTW): X(k) = sum_t x(t) e^{-i 2 pi k t / n}, k = 0..n/2,
// safe to use from any number of threads at once.
// FFTW's planner (making and destroying plans) is not thread-safe: two threads planning at
// the same moment can get a NULL or corrupt plan. Every FFTW plan in FlexArm is made and
// destroyed here, under one lock, and checked. The plan of a length, whose twiddle factors
// cost about two transforms to make, is made once and kept for the next calls of that length
// (the last few lengths are kept); executing a plan needs no lock.
#include <complex>

namespace flexarm {

// Writes the n / 2 + 1 values X(0..n/2) of the DFT of x[0..n) to X; x is left unchanged.
// Throws std::invalid_argument when n < 1 and std::runtime_error when FFTW cannot plan a
// transform of n points (out of memory).
void realDft(const double* x, int n, std::complex<double>* X);

}  // namespace flexarm
