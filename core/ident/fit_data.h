#pragma once
// Data preparation of the fit pipeline (the seed's Sections 5.1-5.2), one call for every
// estimator that learns from a log: the fit (core/ident/fit.h), the recursive estimator of
// chapter 6, and the panels that simulate models on the same samples. In this order:
//   1. channels: input, output and reference, by name or by the log's roles;
//   2. the motor velocity from the motor angle by central differences, when asked and the
//      output is the angle (the physical models' output, Section 5.2);
//   3. decimation behind the anti-alias FIR (Section 5.1: 2 kHz -> 200 Hz);
//   4. the estimation and validation ranges, given in seconds, as sample ranges of the
//      decimated data;
//   5. the means of the estimation range removed from every sample (Section 5.2).
// Signals stay whole-log long: a model simulated from the log's first sample has no start-up
// transient inside a validation range that starts later.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/signal/id_data.h"
#include "core/signal/preprocess.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

struct FitDataOptions {
  // Channels by name; empty: the log's input, output and reference roles. A reference is
  // optional (its absence means the log was not recorded in closed loop).
  std::string input, output, reference;
  // Replace an output that is the motor angle by the motor velocity (central differences).
  bool velocityOutput = false;
  // Decimation factor (1: none) and the anti-alias filter's stopband attenuation.
  int decimation = 1;
  double stopbandDb = 80.0;
  // What a decimated input sample is. Filtered: the anti-alias FIR's output at the sample, as
  // for every other channel (zero phase: centred on the sample). HeldMean: the mean of the
  // input over the new sample period that starts at the sample, which is what a zero-order
  // hold of that period (5.3) must hold to give the same impulse as the torque the controller
  // held at the log's rate; the filtered input lags it by half a period, a phase error of
  // w T / 2 at every frequency w for a continuous-time model sampled with a zero-order hold.
  enum class DecimatedInput { Filtered, HeldMean };
  DecimatedInput decimatedInput = DecimatedInput::Filtered;
  // Estimation range; unset: every sample. (The ranges a log stores, IdData::estimationRange
  // and validationRange, are not used: a front end passes them here when it means them.)
  std::optional<SecondsRange> estimation;
  // Validation range; unset: none.
  std::optional<SecondsRange> validation;
  // Remove the estimation range's means of input, output and reference from every sample.
  bool removeMeans = true;
  // Fewest samples the estimation range must hold after decimation.
  int minimumSamples = 20;
  bool isValid(std::string* why) const;
};

struct PreparedData {
  Termination termination = Termination::Failed;  // Converged: usable
  std::string message;                            // why not, as a sentence
  bool ok() const { return termination == Termination::Converged; }

  // The whole log after steps 1-3 and 5. r is empty when the log has no reference.
  Eigen::VectorXd u, y, r;
  // The measured motor angle after step 3, its mean kept (empty when the log has none): what
  // a controller sees, for the indirect closed-loop fit.
  Eigen::VectorXd angle;
  // The arm-side encoder's angle (arm_angle_rad) after step 3, its mean kept; empty when the
  // log has none. With the motor angle it gives the measured deflection r phi_m - phi_a.
  Eigen::VectorXd arm;
  SampleRange estimation;  // never empty when ok()
  SampleRange validation;  // empty without a validation range
  double sampleTime = 1.0;
  double startTime = 0.0;  // of sample 0, s
  // What step 5 removed (zero when the means were kept): the logged values are u + inputMean.
  double inputMean = 0.0, outputMean = 0.0, referenceMean = 0.0;
  std::string inputName, outputName, referenceName;  // the channels used
  bool closedLoop = false;  // the log has a reference channel
  bool differentiated = false;
  int decimation = 1;
  // The steps taken, in words, e.g. "motor velocity from the angle (central differences)".
  std::vector<std::string> steps;

  std::string note() const;  // the steps joined with ", "
  // The estimation range's samples of u, y and r (r empty without a reference).
  Eigen::VectorXd estimationInput() const;
  Eigen::VectorXd estimationOutput() const;
  Eigen::VectorXd estimationReference() const;
  double timeAt(std::size_t i) const { return startTime + static_cast<double>(i) * sampleTime; }
};

// Runs steps 1-5 on data. Data failures (a missing channel, a range outside the log, too few
// samples, non-finite values) end in termination Failed with a sentence naming the problem;
// invalid options throw std::invalid_argument.
PreparedData prepareFitData(const IdData& data, const FitDataOptions& options);

}  // namespace flexarm
