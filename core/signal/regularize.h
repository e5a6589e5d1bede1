#pragma once
// Samples at irregular times put on a uniform grid: linear interpolation, PCHIP (monotone
// piecewise cubic, as scipy.interpolate.PchipInterpolator) or band-limited. The band-limited
// method assumes no content above 0.8 of the grid's Nyquist frequency: a sample off its grid
// point by jitter is moved there by a second-order Taylor step with the derivatives of the
// band-limited interpolant, and the grid points of a gap get the values that give the
// completed signal the least energy above that band (exact for short gaps of a band-limited
// signal; a gap of more than 512 points is bridged by PCHIP instead).
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class InterpolationMethod { Linear, Pchip, BandLimited };
const char* toString(InterpolationMethod m);
std::optional<InterpolationMethod> interpolationMethodFromString(std::string_view s);

// Piecewise linear and PCHIP interpolation of (t, x) at the times `at` (t strictly
// increasing, at least two points; outside [t0, tn] the end pieces are extended).
std::vector<double> interpolateLinear(const std::vector<double>& t, const std::vector<double>& x,
                                      const std::vector<double>& at);
std::vector<double> interpolatePchip(const std::vector<double>& t, const std::vector<double>& x,
                                     const std::vector<double>& at);

// What happened to the grid points.
struct GridFill {
  std::size_t exact = 0;    // a sample sits on the grid point (within 1e-6 of the interval)
  std::size_t retimed = 0;  // the nearest sample is off the point (jitter): value interpolated
  std::size_t filled = 0;   // no sample within half an interval (a gap): value interpolated
  std::size_t unused = 0;   // samples sharing a grid point with a nearer one (band-limited only)
  std::size_t pchipFallback = 0;  // band-limited: gap points bridged by PCHIP (too long a gap)
};

// Values of every channel at start + k interval, k = 0 .. points - 1, from samples at the
// strictly increasing times t (x[c] has one value per time). Throws std::invalid_argument for
// fewer than two samples, unsorted times or mismatched lengths.
std::vector<std::vector<double>> regularize(const std::vector<double>& t,
                                            const std::vector<const std::vector<double>*>& x,
                                            double start, double interval, std::size_t points,
                                            InterpolationMethod method, GridFill* fill = nullptr);

}  // namespace flexarm
