#include "core/diagnosis/diagnosis_data.h"

#include <cmath>
#include <stdexcept>

#include "core/diagnosis/loop_model.h"
#include "core/ident/fit_data.h"
#include "core/recursive/recursive_log.h"

namespace flexarm {


std::optional<DiagnosisSignals> diagnosisSignals(const IdData& log, DiagnosisPredictor predictor,
                                                 std::string* why) {
  auto fail = [why](const std::string& text) {
    if (why) *why = text;
    return std::nullopt;
  };
  if (!log.input()) return fail("the log has no input channel (the torque reference)");
  if (!log.output()) return fail("the log has no output channel (the motor angle or velocity)");
  // The fit's data preparation: the motor velocity from the angle at the log's rate,
  // decimation to the seed's 200 Hz behind the anti-alias filter, the means removed (the
  // reference and the angle go through the same filter, so that the loop's input and output
  // stay related as the loop relates them). The diagnosis stays at the seed's 200 Hz where the
  // recursive identification runs at the log's rate: its estimators compare with theta_0
  // fitted through the same predictor on the same samples, so what the rate does to the
  // estimates it does to theta_0 alike (the seed's table of Section 7.5.2 is reproduced so, and
  // the tests' thresholds are calibrated there), at a tenth of the cost of the six estimators.
  FitDataOptions f;
  f.velocityOutput = true;
  f.decimation = recursiveDecimation(0, log.sampleRateHz(), 200.0);
  f.removeMeans = true;
  const PreparedData prepared = prepareFitData(log, f);
  if (!prepared.ok()) return fail(prepared.message);
  DiagnosisSignals s;
  s.sampleTime = prepared.sampleTime;
  s.startTime = prepared.startTime;
  s.u = prepared.u;
  s.velocity = prepared.y;
  s.r = prepared.r;
  const std::string preparation = prepared.note();

  // The loop needs the reference, the angle and the controller.
  std::string missing;
  std::optional<ControllerOptions> controller = controllerFromMetadata(log, &missing);
  if (!prepared.closedLoop || prepared.r.size() != prepared.u.size())
    missing = "the log has no reference channel (angle_ref_rad)";
  else if (prepared.angle.size() != prepared.u.size())
    missing = "the log has no motor angle";
  const bool loop = predictor == DiagnosisPredictor::Loop ||
                    (predictor == DiagnosisPredictor::Auto && missing.empty());
  if (predictor == DiagnosisPredictor::Loop && !missing.empty())
    return fail("the loop predictor cannot be used: " + missing);
  if (loop) {
    s.predictor = DiagnosisPredictor::Loop;
    s.controller = controller;
    const double rest = prepared.angle(0);
    const Eigen::VectorXd reference = prepared.r.array() + prepared.referenceMean - rest;
    s.input = LoopModel::referenceSlopes(reference, prepared.sampleTime);
    s.output = prepared.angle.array() - rest;
    s.description = "the motor angle predicted from the position reference through the log's "
                    "controller (the loop, free of closed-loop bias; " + preparation + ")";
  } else {
    s.predictor = DiagnosisPredictor::Direct;
    s.input = s.u;
    s.output = s.velocity;
    s.description = "the motor velocity predicted from the torque reference (direct, as the seed; " +
                    preparation + ")";
    if (predictor == DiagnosisPredictor::Auto) s.description += " because " + missing;
  }
  if (!s.input.allFinite() || !s.output.allFinite())
    return fail("the log holds a value that is not a finite number");
  if (why) why->clear();
  return s;
}

std::unique_ptr<ParametricModel> predictorModel(const PhysicalModel& plant,
                                                const DiagnosisSignals& signals) {
  if (signals.predictor == DiagnosisPredictor::Loop) {
    if (!signals.controller) throw std::invalid_argument("the loop predictor needs the controller");
    return std::make_unique<LoopModel>(plant, *signals.controller);
  }
  auto copy = plant.clone();
  auto* p = dynamic_cast<PhysicalModel*>(copy.get());
  ModelOptions o = p->options();
  o.output = ModelOutput::MotorVelocity;
  o.armAcceleration = false;
  p->setOptions(o);
  return copy;
}

std::unique_ptr<PhysicalModel> plantOf(const ParametricModel& predictor) {
  if (const auto* loop = dynamic_cast<const LoopModel*>(&predictor)) return loop->plant();
  auto copy = predictor.clone();
  auto* p = dynamic_cast<PhysicalModel*>(copy.get());
  if (!p) throw std::invalid_argument("the predictor holds no physical model");
  copy.release();
  return std::unique_ptr<PhysicalModel>(p);
}

}  // namespace flexarm
