#pragma once
// Rate change by a rational factor up/down behind an anti-alias filter, the one mechanism
// behind decimation (up = 1), rational resampling (2000 -> 1500 Hz is 3/4) and putting a
// channel on another time base (a start offset of a fraction of a sample).
//
// The FIR case is a polyphase filter: the prototype is the Kaiser-window low-pass at the rate
// up x input (passband to 0.8 of the lower of the two Nyquist frequencies, stopband from it,
// >= stopbandDb), and each output is one dot product of one of its `up` phases with the
// input, so only the kept outputs are computed. Channels and blocks of outputs run in
// parallel. Ends are extended by odd reflection, so a constant or a ramp passes untouched.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/signal/fir_design.h"

namespace flexarm {

struct RationalFactor {
  int up = 1;
  int down = 1;
};

// up/down in lowest terms with toHz / fromHz = up / down to 1e-9 (relative) and both factors
// at most maxFactor; nullopt when the ratio needs larger factors. Throws
// std::invalid_argument unless both rates are positive and finite.
std::optional<RationalFactor> rationalFactor(double fromHz, double toHz, int maxFactor = 10000);

struct ResampleOptions {
  int up = 1;
  int down = 1;
  // Input position (in samples, >= 0) of output 0; output k lies at offset + k down / up.
  // Only the FIR supports a fractional offset.
  double offset = 0.0;
  // Number of outputs; 0: every position before the end of the input, ceil((n - offset) up /
  // down), as scipy.signal.resample_poly for offset 0.
  std::size_t outputs = 0;
  AntiAliasFilter filter = AntiAliasFilter::Fir;
  double stopbandDb = 80.0;  // FIR only
  int threads = 0;           // 0: one per core
  bool isValid(std::string* why) const;
};

// The input at the output positions, low-pass filtered (see the file comment). Chebyshev
// (zero phase, forward and backward) and None need up = 1 and offset 0. Throws
// std::invalid_argument when the options are invalid.
std::vector<double> resample(const std::vector<double>& x, const ResampleOptions& options);

// The same for several channels of equal length, in parallel.
std::vector<std::vector<double>> resample(const std::vector<const std::vector<double>*>& channels,
                                          const ResampleOptions& options);

// Number of taps of the FIR prototype for the options (at the rate up x input).
int resampleFilterTaps(const ResampleOptions& options);

}  // namespace flexarm
