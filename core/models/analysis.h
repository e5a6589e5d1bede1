#pragma once
// Analysis of linear models: transfer function, frequency response, poles, transmission
// zeros, notch and peak frequencies (antiresonances and resonances, as (5.4) and Table 5.5),
// and conversion to discrete time with zero-order or first-order hold.
#include <complex>
#include <optional>
#include <string_view>
#include <vector>

#include "core/common/state_space.h"

namespace flexarm {

// Transfer function num(s)/den(s) of one input-output pair; coefficients in descending powers,
// den monic. num has deg(den) - relative degree + 1 coefficients; {0} for a zero response.
struct TransferFunction {
  std::vector<double> num, den;
  // Value at a complex point (s, or z for a discrete model).
  std::complex<double> operator()(std::complex<double> s) const;
};

// C(sI - A)^-1 B + D of output `output` and input `input` (3.14 for the two-mass model), from
// poles, transmission zeros and the high-frequency gain. Throws std::invalid_argument for an
// invalid system or index.
TransferFunction transferFunction(const StateSpace& sys, int output = 0, int input = 0);

// Frequency response at the angular frequencies omega (rad/s): G(i omega) in continuous time,
// G(exp(i omega T)) for a discrete model.
std::vector<std::complex<double>> frequencyResponse(const StateSpace& sys,
                                                    const std::vector<double>& omega,
                                                    int output = 0, int input = 0);

// Eigenvalues of A.
std::vector<std::complex<double>> poles(const StateSpace& sys);
// Transmission zeros of one input-output pair: eigenvalues of the zero dynamics (A restricted
// to the kernel of C, CA, ..., CA^(k-1) under the output-zeroing feedback, k the relative
// degree), or of A - B C / D when D is not zero.
std::vector<std::complex<double>> zeros(const StateSpace& sys, int output = 0, int input = 0);

// A lightly damped complex pair: frequency is Im of the root as in (5.4) (rad/s),
// naturalFrequency |root|, damping -Re/|root| (negative for a root in the right half plane).
struct Mode {
  double frequency = 0.0;
  double naturalFrequency = 0.0;
  double damping = 0.0;
};
// The pairs with |damping| < maxDamping, by increasing frequency (one entry per pair).
std::vector<Mode> lightlyDamped(const std::vector<std::complex<double>>& roots,
                                double maxDamping = 0.3);
// Notches (antiresonances: lightly damped zero pairs) and peaks (resonances: lightly damped
// pole pairs) of a continuous-time model, rad/s.
std::vector<Mode> notchFrequencies(const StateSpace& sys, int output = 0, int input = 0,
                                   double maxDamping = 0.3);
std::vector<Mode> peakFrequencies(const StateSpace& sys, double maxDamping = 0.3);

enum class Discretization { ZeroOrderHold, FirstOrderHold };
const char* toString(Discretization d);  // "zoh", "foh"
std::optional<Discretization> discretizationFromString(std::string_view s);

// Discrete-time model with sample time T from the matrix exponential of an augmented matrix:
// ZOH: exp([A B; 0 0] T) = [Ad Bd; 0 I]. FOH (triangle hold, input linear between samples):
// exp([A B 0; 0 0 I/T; 0 0 0] T) = [Phi G1 G2; ...], Ad = Phi, Bd = G1 + (Phi - I) G2,
// Cd = C, Dd = D + C G2 (state shifted by G2 u). Throws std::invalid_argument when sys is
// discrete already or T <= 0.
StateSpace discretize(const StateSpace& sys, double T,
                      Discretization method = Discretization::ZeroOrderHold);

// Coefficients (descending powers) of prod (s - root_i); imaginary parts of conjugate pairs
// cancel and are dropped.
std::vector<double> polynomialFromRoots(const std::vector<std::complex<double>>& roots);

}  // namespace flexarm
