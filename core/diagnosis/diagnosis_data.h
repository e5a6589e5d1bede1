#pragma once
// The signals a diagnosis works on, taken from a log by the fit's data preparation as the
// recursive estimator of chapter 6 uses it (core/ident/fit_data.h: the motor velocity from the
// angle, decimation to the seed's 200 Hz behind the anti-alias filter, means removed), and the
// model the recursive estimators run on them (the predictor):
//  - direct, as the seed's chapters 6 and 7: input u the torque reference, output the motor
//    velocity; the plant itself predicts it;
//  - loop: input the position reference (as its slopes, a first-order hold), output the
//    measured motor angle, both relative to the first sample (the loop starts at rest); the
//    plant closed by the log's controller predicts it (loop_model.h).
// Beside them: u, the velocity and the reference with their means removed, for the two-stage
// closed-loop fit of the plant.
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Dense>

#include "core/diagnosis/diagnosis_options.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"
#include "core/sim/closed_loop.h"

namespace flexarm {

struct DiagnosisSignals {
  DiagnosisPredictor predictor = DiagnosisPredictor::Direct;  // Loop or Direct, resolved
  std::optional<ControllerOptions> controller;                // the loop's controller
  Eigen::VectorXd input, output;  // what the estimators see
  Eigen::VectorXd u, velocity, r; // means removed; r empty when the log has no reference
  double sampleTime = 0.0;
  double startTime = 0.0;         // time of the first sample, s
  std::string description;        // what input and output are, in words (and why, for Auto)
  Eigen::Index size() const { return input.size(); }
  double timeAt(Eigen::Index i) const { return startTime + static_cast<double>(i) * sampleTime; }
};

// The signals of a log for the predictor asked; nullopt with a sentence naming the problem (no
// input or output channel, too few samples, a non-finite value; for Loop: no reference
// channel, no motor angle, no controller in the metadata).
std::optional<DiagnosisSignals> diagnosisSignals(const IdData& log, DiagnosisPredictor predictor,
                                                 std::string* why);

// The model that predicts the signals' output from their input for the plant: the plant (its
// motor-velocity form) or the plant in the loop.
std::unique_ptr<ParametricModel> predictorModel(const PhysicalModel& plant,
                                                const DiagnosisSignals& data);
// The plant inside a predictor model (the inverse of predictorModel).
std::unique_ptr<PhysicalModel> plantOf(const ParametricModel& predictor);

}  // namespace flexarm
