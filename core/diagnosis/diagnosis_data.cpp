#include "core/diagnosis/diagnosis_data.h"

#include <cmath>

#include "core/signal/preprocess.h"

namespace flexarm {

namespace {

Eigen::VectorXd centred(const std::vector<double>& v) {
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  return x.array() - x.mean();
}

}  // namespace

std::optional<DiagnosisSignals> diagnosisSignals(const IdData& log, std::string* why) {
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
  if (velocity) {
    s.y = centred(velocity->values);
    s.output = "the motor velocity channel";
  } else {
    s.y = centred(differentiate(angle->values, log.sampleTime));
    s.output = "the motor velocity by central differences of the motor angle (Section 5.2)";
  }
  if (const Channel* r = log.withRole(ChannelRole::Reference)) s.r = centred(r->values);
  if (!s.u.allFinite() || !s.y.allFinite() || !s.r.allFinite())
    return fail("the log holds a value that is not a finite number");
  if (why) why->clear();
  return s;
}

}  // namespace flexarm
