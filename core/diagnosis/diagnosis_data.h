#pragma once
// The signals a diagnosis works on, taken from a log as the seed's chapters 6 and 7 use them:
// u the torque reference, y the motor velocity (the log's velocity channel, else the motor
// angle differentiated by central differences, Section 5.2), r the position reference when
// the log has one (for the closed-loop fit of the plant); means removed, as for any
// output-error fit.
#include <optional>
#include <string>

#include <Eigen/Dense>

#include "core/signal/id_data.h"

namespace flexarm {

struct DiagnosisSignals {
  Eigen::VectorXd u, y, r;  // r empty when the log has no reference channel
  double sampleTime = 0.0;
  double startTime = 0.0;   // time of the first sample, s
  std::string output;       // where y came from, in words
  Eigen::Index size() const { return u.size(); }
  double timeAt(Eigen::Index i) const { return startTime + static_cast<double>(i) * sampleTime; }
};

// The signals of a log; nullopt with a sentence naming the problem (no torque reference, no
// motor angle or velocity, fewer than 10 samples, a non-finite value).
std::optional<DiagnosisSignals> diagnosisSignals(const IdData& log, std::string* why);

}  // namespace flexarm
