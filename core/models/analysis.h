#pragma once
// Analysis of linear models: transfer function, frequency response, poles, transmission
// zeros, notch and peak frequencies (antiresonances and resonances, as (5.4) and Table 5.5),
// and conversion to discrete time with zero-order or first-order hold.
#include <complex>
#include <functional>
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

// Notches and peaks, FlexArm's one definition (used by `flexarm model`, `flexarm fit`, the
// panels and the reports): the frequencies (rad/s) of the local minima (notches) and maxima
// (peaks) of the magnitude |G(i w)|, each at least minDepthDb below (above) the highest
// (lowest) magnitude on both sides up to the neighbouring extremum of the other kind. This is
// what the seed's Figure 5.3 marks as omega_n and omega_p "in the Bode plot" and what a click
// on a Bode plot reads; for a lightly damped pair it lies near the imaginary part of the zero
// (notch) or pole (peak), which (5.4) approximates as sqrt(k / J_a), and it moves away from it
// as the damping grows (lightlyDamped above lists the roots themselves).
struct NotchesPeaks {
  std::vector<double> notches, peaks;
};
// The extrema of a magnitude sampled at increasing frequencies omega (> 0). With `exact`
// (|G| at any frequency) each extremum is refined on it to about 1e-9 relative, so that two
// grids give the same frequency; without, by a parabola through three points in dB over
// log-frequency.
NotchesPeaks magnitudeExtrema(const std::vector<double>& omega, const std::vector<double>& magnitude,
                              double minDepthDb = 1.0,
                              const std::function<double(double)>& exact = {});
// Of a continuous-time model's output-input pair, on 4000 log-spaced frequencies from a tenth
// of its smallest to ten times its largest non-zero pole or zero magnitude, refined on the
// exact response.
NotchesPeaks notchesAndPeaks(const StateSpace& sys, int output = 0, int input = 0,
                             double minDepthDb = 1.0);

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
