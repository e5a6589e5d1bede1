#pragma once
// Polynomials in the backward shift q^{-1} as used by the black-box structures (4.8)-(4.10):
// p[0] + p[1] q^{-1} + ... + p[n] q^{-n}. Filtering, roots and reflection into the unit circle.
#include <complex>
#include <vector>

#include <Eigen/Dense>

namespace flexarm {

using Poly = std::vector<double>;

// y = num(q)/den(q) x with zero initial conditions; den[0] must be non-zero.
Eigen::VectorXd filter(const Poly& num, const Poly& den, const Eigen::VectorXd& x);

// x delayed by k samples (zeros shifted in).
Eigen::VectorXd delayed(const Eigen::VectorXd& x, int k);

// Product of two polynomials.
Poly polyMultiply(const Poly& a, const Poly& b);

// Roots z of p[0] z^n + p[1] z^{n-1} + ... + p[n] (the poles or zeros of p(q^{-1}) in z);
// trailing zero coefficients give no roots.
std::vector<std::complex<double>> polyRoots(const Poly& p);

// Monic polynomial 1 + c1 q^{-1} + ... whose roots in z are the given ones (conjugate pairs).
Poly polyFromRoots(const std::vector<std::complex<double>>& roots);

// p with every root outside the unit circle replaced by its mirror image 1/conj(z), and roots
// on the circle pulled inside to radius `maxRadius`; keeps p[0]. True if anything changed.
bool reflectIntoUnitCircle(Poly& p, double maxRadius = 0.999);

// Largest root magnitude of p (0 for a constant).
double maxRootMagnitude(const Poly& p);

// p evaluated at q^{-1} = e^{-i w}, w in radians per sample.
std::complex<double> polyEval(const Poly& p, double wPerSample);

}  // namespace flexarm
