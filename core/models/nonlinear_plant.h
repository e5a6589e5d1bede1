#pragma once
// A physical model with effects switched on, as the nonlinear ODE
//   x' = A0 x + b_u k_T... (B of the model) u(t - T_d) + b_m tau_motor
//        + s_g (T_g(delta, delta') + tau_gear) + b_L (tau_load + tau_arm),   phi_m' = x_mv,
// where T_g is the gear spring torque (linear, with dead zone and/or stiffening), s_g its
// distribution over the velocity rows (dA/dk_g), b_m the motor torque column and b_L the
// arm-side load column; tau_motor, tau_gear and tau_arm are the sums of the effects' torque
// terms at each site (core/models/effect_registry.h: each effect's own file says what it adds
// where). The state is the model's core state (seed coordinates) followed by
// phi_m. Integration is classical Runge-Kutta with fine steps, without heap allocation.
#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/models/effect_registry.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"

namespace flexarm {

class NonlinearPlant {
 public:
  static constexpr int kMaxStates = 9;
  using State = std::array<double, kMaxStates>;

  // The model's parameters at their current values; extra_mass replaces the structure first.
  // Throws std::invalid_argument for an invalid or repeated effect, or a gear effect on a
  // model without a gear spring (rigid, two-mass-theta).
  NonlinearPlant(const PhysicalModel& model, const std::vector<Effect>& effects);
  NonlinearPlant(const NonlinearPlant& other);
  NonlinearPlant& operator=(const NonlinearPlant&) = delete;

  // The linear model after structural effects (extra_mass), velocity output.
  const PhysicalModel& model() const { return *model_; }
  const std::vector<Effect>& effects() const { return effects_; }
  int states() const { return n_ + 1; }
  int motorAngleState() const { return n_; }
  double inputDelay() const { return terms_.inputDelay; }

  // x' for the applied (already delayed) torque reference u and the arm-side load torque.
  void derivative(const double* x, double u, double load, double* dx) const;
  // One Runge-Kutta step of length h from time t; torqueAt(t) gives the applied torque
  // reference at any time (the caller applies the input delay).
  template <class TorqueAt>
  void step(State& x, double t, double h, const TorqueAt& torqueAt, double load) const;

  double motorAngle(const State& x) const { return x[static_cast<std::size_t>(n_)]; }
  double motorVelocity(const State& x) const { return x[static_cast<std::size_t>(mv_)]; }
  // phi_a'' at state x with applied torque u and load.
  double armAcceleration(const State& x, double u, double load) const;
  // Gear deflection (r phi_m - phi_g, arm side, rad) and the torque in the gear spring and
  // damper (N m); both 0 for the rigid model.
  double gearDeflection(const State& x) const;
  double gearTorque(const State& x) const;
  // The whole deflection r phi_m - phi_a (arm side, rad), the arm angle phi_a and its speed.
  double armDeflection(const State& x) const;
  double armAngle(const State& x) const;
  double armVelocity(const State& x) const;
  // The motor speed (rad/s) of the smooth sign tanh(phi_m'/v_s) of asymmetric_coulomb and,
  // through the gear, arm_friction: coulomb_friction's v_s when it is on, else this (default
  // 0.1, coulomb_friction's default). Throws std::invalid_argument unless positive.
  void setSmoothingSpeed(double speed);
  // The time by which the arm encoder's reading lags the motor's (encoder_skew; 0 without).
  double encoderSkew() const { return terms_.encoderSkew; }
  // The joint's signals at state x (every one, for an effect's size), with the motor torque
  // k_T u asked for now and applied.
  JointSignals jointSignals(const State& x, double torqueNow, double torqueApplied) const;
  // The motor's own viscous friction torque f_m phi_m' (N m) at x.
  double motorFriction(const State& x) const;

 private:
  std::unique_ptr<PhysicalModel> model_;
  std::vector<Effect> effects_;
  int n_ = 0, mv_ = 0, arm_ = 0, gear_ = -1;
  double armScale_ = 1.0;  // phi_a'' = armScale * x'_arm (r for the rigid model)
  double ratio_ = 1.0;     // r
  State armDeflection_{};  // the row of armDeflection over the core states
  std::array<double, kMaxStates * kMaxStates> A0_{};  // row-major, n x n
  State bu_{}, bm_{}, bl_{}, sg_{}, gearRate_{};
  bool gearNonlinear_ = false;
  double k_ = 0.0, d_ = 0.0, kT_ = 1.0, fm_ = 0.0;
  double smoothing_ = 0.1;  // the smooth signs' motor speed
  PlantTerms terms_;        // what the effects set up
  // The torque terms by site (raw pointers into terms_), and the signals they read.
  std::vector<const TorqueTerm*> motorTerms_, gearTerms_, armTerms_;
  unsigned needs_ = 0u;
  void collectTerms();
  double gearSpring(double delta, double rate) const;
  double gearRate(const double* x) const;
  void fillSignals(const double* x, JointSignals& s, unsigned needs) const;
};

template <class TorqueAt>
void NonlinearPlant::step(State& x, double t, double h, const TorqueAt& torqueAt,
                          double load) const {
  State k1, k2, k3, k4, y;
  const int m = states();
  // The end stages are nudged into the step so that an input held constant over the step
  // (changing at its ends) is seen with its value inside the step.
  const double inside = 1e-6 * h;
  derivative(x.data(), torqueAt(t + inside), load, k1.data());
  for (int i = 0; i < m; ++i) y[i] = x[i] + 0.5 * h * k1[i];
  const double uMid = torqueAt(t + 0.5 * h);
  derivative(y.data(), uMid, load, k2.data());
  for (int i = 0; i < m; ++i) y[i] = x[i] + 0.5 * h * k2[i];
  derivative(y.data(), uMid, load, k3.data());
  for (int i = 0; i < m; ++i) y[i] = x[i] + h * k3[i];
  derivative(y.data(), torqueAt(t + h - inside), load, k4.data());
  for (int i = 0; i < m; ++i) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

// Open-loop response of the plant to a sampled torque reference (held constant over each
// sample, then delayed by input_delay), logged at the same sample instants.
struct TorqueResponseOptions {
  int substeps = 20;  // Runge-Kutta steps per sample
  std::vector<double> initialState;  // empty: at rest; else states() values
  bool isValid(std::string* why) const;
};
struct TorqueResponse {
  std::vector<double> motorAngle, motorVelocity, armAcceleration, gearDeflection, gearTorque;
};
// Throws std::invalid_argument for sampleTime <= 0 or invalid options.
TorqueResponse simulateTorque(const NonlinearPlant& plant, const std::vector<double>& torque,
                              double sampleTime, const TorqueResponseOptions& options = {});

// The same simulation, handing the whole state at every sample instant k (before the step to
// k + 1), the applied torque there, to visit; visit returns false to stop early. Returns the
// number of samples visited.
using PlantStateVisitor =
    std::function<bool(std::size_t k, const NonlinearPlant::State& x, double appliedTorque)>;
std::size_t simulateTorque(const NonlinearPlant& plant, const std::vector<double>& torque,
                           double sampleTime, const TorqueResponseOptions& options,
                           const PlantStateVisitor& visit);

}  // namespace flexarm
