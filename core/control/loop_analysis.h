#pragma once
// Loop analysis of chapter 8: the Nyquist curve of a loop gain with its encirclements
// counted by the winding number on an adaptive frequency grid (Section 8.6), sensitivity
// |S| = 1/|1 + L| (8.36), (8.38), Bode's integral (8.37), and the describing function of a
// saturation (8.30) with the points where -1/Y_f meets a Nyquist curve (Section 8.5).
#include <complex>
#include <functional>
#include <string>
#include <vector>

namespace flexarm {

using ComplexFunction = std::function<std::complex<double>(std::complex<double>)>;

struct NyquistOptions {
  int initialPoints = 300;      // log-spaced points before refinement
  int maxPoints = 6000;         // refinement stops here (gridLimitReached)
  double maxAngleStep = 0.2;    // rad: largest turn of f - point between neighbours
  double maxChordRatio = 0.25;  // largest |f_i+1 - f_i| / min(|f_i - point|, |f_i+1 - point|)
  // rad: largest turn of the curve's direction from one chord to the next, for chords longer
  // than bendMinChord |f_i - point|: the curve is sampled densely where it bends, so that it
  // is drawn smooth (a turn of 0.1 rad is a polygon the eye does not see).
  double maxBendStep = 0.1;
  double bendMinChord = 0.005;
  // Frequency range in rad/s; 0 picks it from the characteristic frequencies.
  double minFrequency = 0.0, maxFrequency = 0.0;
  bool isValid(std::string* why = nullptr) const;
};

// A Nyquist curve on positive frequencies and its encirclements of a point.
struct NyquistCurve {
  std::vector<double> frequencies;           // rad/s, increasing
  std::vector<std::complex<double>> values;  // f(i w)
  // Net counter-clockwise encirclements of the point by f over the whole Nyquist contour
  // (-i inf to +i inf, a small indentation right of the origin, closed through the right
  // half plane). By the argument principle this equals P - Z for f = L, point = -1 (P, Z:
  // right-half-plane poles of L and of the closed loop).
  int encirclements = 0;
  double windingError = 0.0;       // distance of the measured winding from the integer, in turns
  double indentationRadius = 0.0;  // rad/s
  bool gridLimitReached = false;
};

// Nyquist curve of f (real-rational, f(conj s) = conj f(s), tending to a finite limit as
// |s| -> inf) around `point`. characteristicFrequencies (magnitudes of poles and zeros,
// rad/s) seed the grid and, when the options leave it open, its range: from 1e-3 times the
// smallest non-zero one to 1e3 times the largest. Throws std::invalid_argument for invalid
// options or no positive characteristic frequency when the range is open.
NyquistCurve nyquist(const ComplexFunction& f, std::complex<double> point,
                     const std::vector<double>& characteristicFrequencies,
                     const NyquistOptions& options = {});

// Bode's sensitivity integral (8.37): the integral over 0..inf of log|S(i w)|,
// S = 1 / (1 + L), computed by Gauss-Legendre quadrature in log w on the panels of `grid`
// (increasing positive frequencies, e.g. a NyquistCurve's), with the analytic contributions of
// [0, w_0] (|S| ~ a w^m) and [w_N, inf) (log|S| ~ c w^-p, p > 1) added.
double bodeSensitivityIntegral(const ComplexFunction& loopGain, const std::vector<double>& grid);

// Describing function of a unit saturation (8.30): for amplitude C > 1,
// (2/pi)(asin(1/C) + (1/C) sqrt(1 - 1/C^2)); 1 for C <= 1.
double saturationDescribingFunction(double amplitude);

// A point where a Nyquist curve meets -1/Y_f(C), the negative real axis left of -1.
struct DescribingFunctionCrossing {
  double frequency = 0.0;  // rad/s
  double realPart = 0.0;   // of the curve at the crossing, <= -1
  double amplitude = 0.0;  // C with -1/Y_f(C) = realPart, relative to the saturation level
};

// Crossings of the curve f(i w) (sampled on curve.frequencies) with the negative real axis
// left of -1, each refined by bisection on f.
std::vector<DescribingFunctionCrossing> describingFunctionCrossings(const ComplexFunction& f,
                                                                    const NyquistCurve& curve);

}  // namespace flexarm
