#pragma once
// Preprocessing of robot logs as in the seed's Sections 5.1-5.2: motor velocity from the
// angle by differentiation, decimation by an integer factor behind an anti-alias low-pass
// filter, removal of means or linear trends, and range selection (IdData::select); before
// them, when asked, resampling onto a uniform grid at any rate (uniform_grid.h).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/signal/id_data.h"
#include "core/signal/resample.h"
#include "core/signal/uniform_grid.h"

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

struct DecimateOptions {
  int factor = 10;  // seed Section 5.1: 2000 Hz -> 200 Hz
  AntiAliasFilter filter = AntiAliasFilter::Fir;
  double stopbandDb = 80.0;  // FIR only
  bool isValid(std::string* why) const;
};

// Zero-phase low-pass filtering followed by keeping every factor-th sample (starting at 0):
// the resampler of resample.h with up = 1, which computes only the kept samples. Ends are
// extended by odd reflection so that the filter's transient does not show.
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

// Everything the Preprocess panel and `flexarm preprocess` apply, in this order: resample
// onto a uniform grid (the explicit step irregular time stamps need, or a rate change),
// differentiate, select range, decimate, detrend (the seed's order, Section 5.2).
struct PreprocessOptions {
  std::optional<UniformGridOptions> resample;  // put the log on a uniform grid first
  bool differentiateAngle = false;   // add motor_velocity_rad_s and make it the output
  std::optional<SampleRange> range;  // keep only these samples (after resampling)
  Detrend detrend = Detrend::None;
  DecimateOptions decimation{1, AntiAliasFilter::Fir, 80.0};
  bool isValid(std::string* why) const;
};

struct PreprocessResult {
  Termination termination = Termination::Failed;
  std::string message;  // why it failed, or what resampling did (empty without it)
  double seconds = 0.0;
  IdData data;
  // The resampling step's report (its data moved into `data`), when it ran, also when it
  // failed (e.g. the time-stamp report of a log with a gap above the limit).
  std::optional<UniformGridResult> resampling;
};

// Applies the steps. Data failures (irregular time stamps without a resampling step, a gap
// above the limit, ...) come back as Failed with a sentence; invalid options throw
// std::invalid_argument. Further logs of the same experiment (otherLogs) join the first on
// its time base in the resampling step, which they require.
PreprocessResult runPreprocess(const IdData& data, const PreprocessOptions& options,
                               const ProgressCallback& progress = {},
                               const std::vector<const IdData*>& otherLogs = {});
// The same, throwing std::invalid_argument with the sentence when the data do not allow it.
IdData preprocess(const IdData& data, const PreprocessOptions& options);

}  // namespace flexarm
