#pragma once
// Putting logs on one uniform time base at any rate: the explicit resampling step of
// preprocessing. Channels whose time stamps jitter, skip, repeat or run backwards are first
// put on their own nominal grid (timing.h finds the places, regularize.h fills them with the
// chosen method); every channel then goes from its rate to the new one through the rational
// polyphase resampler (resample.h, the FIR with its stated stopband), starting where the new
// grid starts. Several logs of one experiment, or channels of one log sampled at different
// rates (NaN where a channel has no sample), end on the first log's time base, over the time
// they all cover.
#include <cstddef>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/signal/id_data.h"
#include "core/signal/regularize.h"
#include "core/signal/resample.h"
#include "core/signal/timing.h"

namespace flexarm {

// The memory a resampled log may take (its samples, every channel): a rate that would make
// more is refused before any work.
inline constexpr double kMaxResampledBytes = 1073741824.0;  // 1 GiB

struct UniformGridOptions {
  double rateHz = 0.0;  // the new sample rate; 0 keeps the first log's own (nominal) rate
  InterpolationMethod method = InterpolationMethod::BandLimited;  // for irregular time stamps
  double maxGapSeconds = 0.0;     // longest gap bridged; 0: ten intervals of the channel's grid
  double jitterTolerance = 0.01;  // a sample further off its grid point (fraction) is jitter
  double stopbandDb = 80.0;       // of the anti-alias FIR
  int threads = 0;                // 0: one per core
  bool isValid(std::string* why) const;
  bool operator==(const UniformGridOptions& o) const {
    return rateHz == o.rateHz && method == o.method && maxGapSeconds == o.maxGapSeconds &&
           jitterTolerance == o.jitterTolerance && stopbandDb == o.stopbandDb;
  }
};

// Channels of one log that share their sampling instants, and what was done to them.
struct ChannelGroup {
  std::size_t log = 0;                // index of the log
  std::vector<std::string> channels;  // names in the result
  bool irregular = false;             // time stamps off a uniform grid: regularised first
  TimingReport timing;                // of these channels' instants
  GridFill fill;                      // regularisation onto their grid (irregular only)
  double sourceRateHz = 0.0;          // rate of their (nominal) grid
  RationalFactor factor;              // to the new rate
  double offsetSamples = 0.0;         // start of the new grid, in samples of theirs
};

struct UniformGridResult {
  Termination termination = Termination::Failed;
  std::string message;  // what was done, or why it could not be
  double seconds = 0.0;
  IdData data;  // uniformly sampled, ranges of the first log carried over by time
  std::vector<ChannelGroup> groups;
  std::size_t filled = 0;   // grid points in gaps, interpolated
  std::size_t retimed = 0;  // jittered samples moved onto their grid point
  double longestGapBridged = 0.0;  // seconds
  double longestGapTime = 0.0;     // time of the sample after it
  std::string stopband;            // e.g. "80 dB from 750 Hz"
};

// Resamples the logs (the first one gives the time base, metadata, roles and ranges; the
// channels of the others follow, renamed "log2_<name>" ... when a name is taken). Data
// failures (a gap above the limit, no common time, a rate ratio that needs factors above
// 10000) come back as Failed with a sentence; invalid options or empty logs throw
// std::invalid_argument.
UniformGridResult resampleToUniform(const std::vector<const IdData*>& logs,
                                    const UniformGridOptions& options,
                                    const ProgressCallback& progress = {});
UniformGridResult resampleToUniform(const IdData& log, const UniformGridOptions& options,
                                    const ProgressCallback& progress = {});

}  // namespace flexarm
