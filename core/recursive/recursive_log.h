#pragma once
// Recursive identification of a log, as the command line, the Recursive panel and sessions
// run it: the log prepared as for a fit (prepareFitData: the motor velocity from the angle by
// central differences at the log's rate, decimation to about 200 Hz behind the anti-alias
// FIR, the means removed), then the estimator over every sample of the range.
#include <optional>
#include <string>

#include "core/ident/fit_data.h"
#include "core/recursive/rpem.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

struct RecursiveDataOptions {
  // Decimation factor; 0: to the seed's 200 Hz, i.e. floor(rate / 200) (10 on a 2 kHz log, 1
  // on a 200 Hz one).
  int decimation = 0;
  // The part of the log the estimator runs over (default: all of it).
  std::optional<SecondsRange> range;
  // Channels by name; empty: the log's input and output (the output, when it is the motor
  // angle, is replaced by the motor velocity).
  std::string input, output;
  bool isValid(std::string* why) const;
};

// The decimation factor `decimation` means for a log of this rate.
int recursiveDecimation(int decimation, double sampleRateHz);

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
