#pragma once
// The real-input DFT of FlexArm (FFTW): X(k) = sum_t x(t) e^{-i 2 pi k t / n}, k = 0..n/2.
// The plan of a length, whose twiddle factors cost about two transforms to make, is made once
// and kept for the next call of that length. FFTW's planner is not thread-safe, so every plan
// in core is made here under one lock; transforms themselves run in parallel.
#include <complex>

namespace flexarm {

// Writes the n / 2 + 1 values X(0..n/2) of the DFT of x[0..n) to X; x is left unchanged.
// Throws std::invalid_argument when n < 1.
void realDft(const double* x, int n, std::complex<double>* X);

}  // namespace flexarm
