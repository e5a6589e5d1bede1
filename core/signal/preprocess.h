#pragma once
// Preprocessing of robot logs as in the seed's Sections 5.1-5.2: motor velocity from the
// angle by differentiation, decimation by an integer factor behind an anti-alias low-pass
// filter, removal of means or linear trends, and range selection (IdData::select).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/signal/id_data.h"

namespace flexarm {

// Derivative of a uniformly sampled signal by central differences (second-order accurate;
// one-sided second-order differences at the two ends).
std::vector<double> differentiate(const std::vector<double>& x, double sampleTime);

// Adds the derivative of channel `from` as channel `to` (replacing it if present). With the
// defaults it forms motor_velocity_rad_s from motor_angle_rad and makes it the output, as the
// seed does before identification (Section 5.2). Throws std::invalid_argument if `from` is
// missing.
IdData addDerivative(const IdData& data, const std::string& from = columns::kMotorAngle,
                     const std::string& to = columns::kMotorVelocity, bool makeOutput = true);

enum class AntiAliasFilter {
  Fir,        // linear-phase Kaiser-window FIR, passband to 0.8 of the new Nyquist frequency,
              // stopband from the new Nyquist frequency on, attenuation >= stopbandDb
  Chebyshev,  // order-8 Chebyshev type I (0.05 dB ripple) at 0.8 of the new Nyquist
              // frequency, run forward and backward (zero phase), as MATLAB's decimate
  None,       // plain down-sampling (aliasing!)
};
const char* toString(AntiAliasFilter f);
std::optional<AntiAliasFilter> antiAliasFilterFromString(std::string_view s);

struct DecimateOptions {
  int factor = 10;  // seed Section 5.1: 2000 Hz -> 200 Hz
  AntiAliasFilter filter = AntiAliasFilter::Fir;
  double stopbandDb = 80.0;  // FIR only
  bool isValid(std::string* why) const;
};

// Low-pass FIR taps (odd length, unit DC gain) by the Kaiser window method. Frequencies are
// in cycles per sample (0..0.5).
std::vector<double> designLowpassFir(double passEdge, double stopEdge, double attenuationDb);

// Zero-phase low-pass filtering followed by keeping every factor-th sample (starting at 0).
// Ends are extended by odd reflection so that the filter's transient does not show.
std::vector<double> decimate(const std::vector<double>& x, const DecimateOptions& options);
// Decimates every channel; sample time, metadata and ranges follow. Throws
// std::invalid_argument when the options are invalid.
IdData decimate(const IdData& data, const DecimateOptions& options);

enum class Detrend { None, Mean, Linear };
const char* toString(Detrend d);
std::optional<Detrend> detrendFromString(std::string_view s);

std::vector<double> detrend(const std::vector<double>& x, Detrend kind);
// Removes means or linear trends from the input and output channels (all channels when
// allChannels is true).
IdData detrend(const IdData& data, Detrend kind, bool allChannels = false);

// Amplitude spectrum by Welch's method (Hann window, 50 % overlap): a sinusoid of amplitude a
// shows as a peak of height close to a. segmentLength 0 picks a power of two <= 8192.
struct AmplitudeSpectrum {
  std::vector<double> frequencyHz;
  std::vector<double> amplitude;
};
AmplitudeSpectrum amplitudeSpectrum(const std::vector<double>& x, double sampleTime,
                                    int segmentLength = 0);

// Everything the Preprocess panel and `flexarm preprocess` apply, in this order:
// differentiate, select range, decimate, detrend (the seed's order, Section 5.2).
struct PreprocessOptions {
  bool differentiateAngle = false;   // add motor_velocity_rad_s and make it the output
  std::optional<SampleRange> range;  // keep only these samples
  Detrend detrend = Detrend::None;
  DecimateOptions decimation{1, AntiAliasFilter::Fir, 80.0};
  bool isValid(std::string* why) const;
};
IdData preprocess(const IdData& data, const PreprocessOptions& options);

}  // namespace flexarm
