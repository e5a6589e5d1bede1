#include "core/diagnosis/diagnosis_data.h"

#include <cmath>
#include <stdexcept>

#include "core/diagnosis/loop_model.h"
#include "core/signal/preprocess.h"

namespace flexarm {

namespace {

Eigen::VectorXd vector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

Eigen::VectorXd centred(const std::vector<double>& v) {
  Eigen::VectorXd x = vector(v);
  return x.array() - x.mean();
}

}  // namespace

std::optional<DiagnosisSignals> diagnosisSignals(const IdData& log, DiagnosisPredictor predictor,
                                                 std::string* why) {
  auto fail = [why](const std::string& text) {
    if (why) *why = text;
    return std::nullopt;
  };
  const Channel* torque = log.channel(columns::kTorqueRef);
  if (!torque) torque = log.input();
  if (!torque) return fail("the log has no torque reference (torque_ref_nm or an input channel)");
  const Channel* velocity = log.channel(columns::kMotorVelocity);
  const Channel* angle = log.channel(columns::kMotorAngle);
  if (!velocity && !angle)
    return fail("the log has neither motor_velocity_rad_s nor motor_angle_rad");
  if (log.samples() < 10) return fail("the log has fewer than 10 samples");
  if (!(log.sampleTime > 0.0) || !std::isfinite(log.sampleTime))
    return fail("the log's sample time is not a positive number");
  DiagnosisSignals s;
  s.sampleTime = log.sampleTime;
  s.startTime = log.startTime;
  s.u = centred(torque->values);
  std::string velocityText;
  if (velocity) {
    s.velocity = centred(velocity->values);
    velocityText = "the motor velocity channel";
  } else {
    s.velocity = centred(differentiate(angle->values, log.sampleTime));
    velocityText = "the motor velocity by central differences of the motor angle (Section 5.2)";
  }
  const Channel* reference = log.withRole(ChannelRole::Reference);
  if (reference) s.r = centred(reference->values);
  if (!s.u.allFinite() || !s.velocity.allFinite() || !s.r.allFinite())
    return fail("the log holds a value that is not a finite number");

  // The loop needs the reference, the angle and the controller.
  std::string missing;
  std::optional<ControllerOptions> controller = controllerFromMetadata(log, &missing);
  if (!reference) missing = "the log has no reference channel (angle_ref_rad)";
  else if (!angle) missing = "the log has no motor angle";
  const bool loop = predictor == DiagnosisPredictor::Loop ||
                    (predictor == DiagnosisPredictor::Auto && missing.empty());
  if (predictor == DiagnosisPredictor::Loop && !missing.empty())
    return fail("the loop predictor cannot be used: " + missing);
  if (loop) {
    s.predictor = DiagnosisPredictor::Loop;
    s.controller = controller;
    const double rest = angle->values.front();
    s.input = LoopModel::referenceSlopes(vector(reference->values).array() - rest, log.sampleTime);
    s.output = vector(angle->values).array() - rest;
    s.description = "the motor angle predicted from the position reference through the log's "
                    "controller (the loop, free of closed-loop bias)";
  } else {
    s.predictor = DiagnosisPredictor::Direct;
    s.input = s.u;
    s.output = s.velocity;
    s.description = velocityText + " predicted from the torque reference (direct, as the seed)";
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
