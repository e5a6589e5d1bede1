#pragma once
// The controller of a closed-loop log, identified from the log itself: the cascade of the
// seed's Figure 5.1 (P position loop, PI velocity loop on the backward difference of the
// measured angle, as core/sim/closed_loop.h runs it) at the log's rate. With the position
// error x1 = phi_ref - phi_m, the velocity estimate x2 = (phi_m(k) - phi_m(k-1)) / T and their
// sums x3 = T sum x1, x4 = T sum x2 from the log's first sample, the torque reference is
//   u = k_v k_p x1 - k_v x2 + (k_v k_p / T_i) x3 - (k_v / T_i) x4 + c,
// linear in its coefficients given the reference, the angle and the torque (c: the integral's
// state before the log starts). Least squares gives the coefficients; a Gauss-Newton refinement
// makes them the products of one (k_p, k_v, T_i); fit % (5.2) of the torque says how well the
// controller explains it. The indirect closed-loop fit (closed_loop_pem.h) needs that
// controller, and is refused when it does not explain the torque.
#include <string>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/sim/closed_loop.h"

namespace flexarm {

struct ControllerIdentOptions {
  // Below this fit % (5.2) of the torque the log's controller is not the cascade of Figure 5.1
  // at the log's rate (another structure, another rate, a filter in the loop), and the result
  // is refused.
  double minimumFitPercent = 99.0;
  bool isValid(std::string* why) const;
};

struct ControllerIdentResult {
  Termination termination = Termination::Failed;  // Converged: the controller explains the torque
  std::string message;  // a sentence: the gains and how well they explain the torque, or why not
  ControllerOptions controller;  // rateHz = 1 / T; ti = 0 when there is no integral action
  double offset = 0.0;           // c, N m
  double fitPercent = 0.0;       // (5.2) of the torque
  double seconds = 0.0;
  bool ok() const { return termination == Termination::Converged; }
};

// The torque reference the controller computes from the reference r and the measured angle a
// (both as logged, sampled at the controller's period T), plus the constant c = offset of the
// model above (c = 0: the integral starts at zero at the first sample, as in the simulator).
Eigen::VectorXd controllerTorque(const ControllerOptions& controller, const Eigen::VectorXd& r,
                                 const Eigen::VectorXd& a, double sampleTime, double offset = 0.0);

// Fit % (5.2) of the logged torque u by a known controller (e.g. from the log's metadata), the
// constant c estimated; NaN when the sizes differ or the torque is constant.
double controllerFitPercent(const ControllerOptions& controller, const Eigen::VectorXd& r,
                            const Eigen::VectorXd& a, const Eigen::VectorXd& u, double sampleTime);

// Identifies the controller from reference r, measured angle a and torque reference u, as
// logged (means kept), sampled at sampleTime. Data failures (sizes, non-finite values, no
// excitation, gains that are not positive, a torque it does not explain) end in Failed with
// a sentence; invalid options throw std::invalid_argument.
ControllerIdentResult identifyController(const Eigen::VectorXd& r, const Eigen::VectorXd& a,
                                         const Eigen::VectorXd& u, double sampleTime,
                                         const ControllerIdentOptions& options = {});

}  // namespace flexarm
