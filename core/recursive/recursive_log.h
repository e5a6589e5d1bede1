#pragma once
// Recursive identification of a log, as the command line, the Recursive panel and sessions
// run it: the log prepared as for a fit (prepareFitData: the motor velocity from the angle by
// central differences at the log's rate, the means removed), at the log's own rate up to
// 2 kHz, then the estimator over every sample of the range.
//
// Why the log's rate: the estimator samples the continuous-time model with a zero-order hold
// (6.27), which is exact for the torque the controller held at its own rate. Decimated to the
// seed's 200 Hz the torque is no longer held over a sample: as the anti-alias filter's output
// it lags the hold by half a sample, and on simulated three-mass logs from +20 % the estimates
// ended 5-6 % low in k_T; held as its mean over each period (what the fit does) they still
// ended 2 % low in k_T and J_a^-1. At 2 kHz the same runs end within 0.5 % (k_T, J_a^-1), at
// about 60 times real time. The seed's design variables keep their meaning at any rate: they
// are per 200 Hz sample (RecursiveOptions::designSampleTime).
#include <optional>
#include <string>

#include "core/ident/fit_data.h"
#include "core/recursive/rpem.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

struct RecursiveDataOptions {
  // Decimation factor; 0: the smallest that brings the rate to maxRateHz or below (1 on a
  // 2 kHz or a 200 Hz log, 5 on a 10 kHz one). A decimated torque is held as its mean over
  // each new period (FitDataOptions::DecimatedInput::HeldMean), the hold the model assumes.
  int decimation = 0;
  // The highest rate the estimator runs at when decimation is 0, Hz (sessions written before
  // it existed decimated to the seed's 200 Hz and read back with 200).
  double maxRateHz = 2000.0;
  // The part of the log the estimator runs over (default: all of it).
  std::optional<SecondsRange> range;
  // Channels by name; empty: the log's input and output (the output, when it is the motor
  // angle, is replaced by the motor velocity).
  std::string input, output;
  bool isValid(std::string* why) const;
};

// The decimation factor `decimation` means for a log of this rate (0: the smallest factor
// that brings it to maxRateHz or below).
int recursiveDecimation(int decimation, double sampleRateHz, double maxRateHz = 2000.0);

// The log's input and motor velocity ready for the estimator (its range: estimation). Data
// failures are a Failed result with a sentence; invalid options throw std::invalid_argument.
PreparedData prepareRecursiveData(const IdData& log, const RecursiveDataOptions& options);

struct RecursiveLogResult {
  RecursiveResult result;  // termination Failed with the data's sentence when preparing failed
  std::string preparation; // the steps taken, in words
  double sampleTime = 0.0; // after decimation
  int decimation = 1;
};

// prepareRecursiveData, then recursiveIdentification over the range's samples (times as in
// the log).
RecursiveLogResult recursiveIdentification(const IdData& log, const ParametricModel& nominal,
                                           const RecursiveDataOptions& data,
                                           const RecursiveOptions& options,
                                           const ProgressCallback& progress = {});

// The trajectory as CSV: time_s, then per theta entry its value and sigma (theta's names,
// e.g. "J_a^-1" and "sigma_J_a^-1"), then y, yhat, epsilon. False with a sentence when the file
// cannot be written (it is written whole or not at all).
bool writeTrajectoryCsv(const RecursiveResult& result, const std::string& path, std::string* why);

}  // namespace flexarm
