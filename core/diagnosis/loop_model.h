#pragma once
// A physical model closed by the cascade controller of the seed's Figure 5.1, as one
// parametric model from the position reference phi_ref to the measured motor angle phi_m:
// the indirect approach of Section 4.4 in continuous time. Because the reference is
// independent of every noise source, an output-error fit or recursive estimate of the plant's
// parameters through this loop is free of the closed-loop bias (4.43) of the direct approach
// (torque reference to motor velocity), which on the sample logs moves f_m by 110 % and makes
// a 20 % change of it look like 4 %.
//
// With the plant x' = A x + B u, phi_m = c_a x, phi_m' = c_v x and the controller
//   e_v = k_p (phi_ref - phi_m) - phi_m',  I' = e_v,  u = k_v (e_v + I / T_i),
// the loop's state is (x, I):
//   A_cl = [A - k_v B (k_p c_a + c_v),  (k_v / T_i) B;  -(k_p c_a + c_v),  0],
//   B_cl = [k_v k_p B;  k_p],  C_cl = [c_a, 0],
// (without the integral when T_i = 0). The controller runs continuously here. The log's runs
// at 2 kHz; its hold (a quarter millisecond) is left out: as a first-order Pade delay it lowers
// the output error of a noise-free run by 10 % but its fast pole makes the recursive estimator
// seven times slower, and the estimates' response to a fault is the same.
//
// The reference reaches the model through a first-order hold: it is the loop's last state and
// the model's input is its slope, held over each sample, (r(k+1) - r(k)) / T. The loop reacts
// within one sample of a 200 Hz log, so a reference held constant over the sample (zero-order
// hold) is a poor description: on the sample logs it quadruples the output error of a
// noise-free run and moves the fitted J_a by 40 %.
// Parameters are the plant's, with the plant's derivatives (6.25).
#include <memory>
#include <string>

#include "core/models/physical_models.h"
#include "core/sim/closed_loop.h"

namespace flexarm {

class LoopModel : public ParametricModel {
 public:
  // The plant (any output: its motor-angle form is used) and the controller; throws
  // std::invalid_argument for an invalid controller.
  LoopModel(const PhysicalModel& plant, const ControllerOptions& controller);
  LoopModel(const LoopModel& other);
  LoopModel& operator=(const LoopModel&) = delete;

  std::string structureName() const override;  // "three-mass in the loop"
  std::unique_ptr<ParametricModel> clone() const override;
  const std::vector<ParameterInfo>& parameters() const override { return plant_->parameters(); }
  void setParameter(const std::string& name, double value) override { plant_->setParameter(name, value); }
  void setFree(const std::string& name, bool isFree) override { plant_->setFree(name, isFree); }
  StateSpace stateSpace() const override;
  StateSpaceDerivative derivative(int index) const override;

  // The plant at the current values, with the output it was given.
  std::unique_ptr<PhysicalModel> plant() const;
  const ControllerOptions& controller() const { return controller_; }

  // The model's input from a reference sampled every sampleTime: its slopes (the last one 0).
  static Eigen::VectorXd referenceSlopes(const Eigen::VectorXd& reference, double sampleTime);

 private:
  std::unique_ptr<PhysicalModel> plant_;  // motor-angle output
  ModelOutput originalOutput_ = ModelOutput::MotorVelocity;
  ControllerOptions controller_;
  Eigen::RowVectorXd ca_, cv_;
};

}  // namespace flexarm
