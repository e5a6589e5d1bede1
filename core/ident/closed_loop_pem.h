#pragma once
// Grey-box estimation from closed-loop data by the two-stage (projection) method (Van den Hof
// and Schrama; Forssell and Ljung), which removes the bias the seed's (4.43) predicts for an
// output-error fit on closed-loop data, where the noise reaches the input through the
// controller.
//   Stage 1: the part of the input u that the reference r explains, u_r = S r (S the
//            sensitivity from r to u), by least squares of u on a non-causal FIR of r.
//   Stage 2: the output-error grey-box pem (5.3)/(5.7) on (u_r, y). u_r is uncorrelated with
//            the noise, so the estimate is consistent whatever the noise is; the prediction
//            errors are then coloured (they hold G (u - u_r) and the output noise), so the
//            covariance is the sandwich R^{-1} Q R^{-1} (longRunCovariance), and it carries
//            the uncertainty of stage 1 as well: with n = u - u_r, the estimate's error is
//            R^{-1} (psi^T eps - W^T n), where W = Z (Z^T Z)^{-1} (G Z)^T psi maps the FIR's
//            error through the model G onto the gradient (Z: the FIR's regressors).
// Hold: the plant sees the logged input held between samples (zero-order hold). At the
// controller's own rate this is exact; after decimation it is an approximation.
// A third way, the indirect approach of the seed's Section 4.4 (Ljung, System
// Identification, sec. 13.5), needs no stage 1 when the controller is known (the seed's
// industrial controller was not; the simulator's is): the output-error fit of the whole
// closed loop from the reference r to the measured output, with the plant G(theta) inside
// it, is consistent (r is independent of every noise source) and keeps the physical
// parameters. It uses neither u nor an estimate of it, so nothing of
// the noise leaks into the model's input.
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/pem.h"
#include "core/sim/closed_loop.h"

namespace flexarm {

// pem on (u, y), on (u_r, y), or of the closed loop on (r, y)
enum class ClosedLoopMethod { Direct, TwoStage, Indirect };
const char* toString(ClosedLoopMethod m);
std::optional<ClosedLoopMethod> closedLoopMethodFromString(std::string_view s);

// The non-causal FIR of stage 1: u_r(t) = sum_{k=-future}^{past} h_k r(t - k), with r taken
// as zero outside the record (the loop is at rest before the log starts). The taps up to lag
// fineS are free; beyond it they follow a cubic B-spline with knots knotS apart. The loop's
// impulse response needs a long FIR (it settles in about half a second), but every free tap
// also fits some noise into u_r, which correlates with the output noise and biases stage 2;
// the smooth tail keeps the long memory with a fraction of the free taps.
struct ReferenceProjectionOptions {
  double pastS = 0.5;      // length of the causal part, s (covers the loop's settling)
  double futureS = 0.005;  // length of the anti-causal part, s
  double fineS = 0.02;     // taps up to this lag (s) are all free
  double knotS = 0.005;    // knot spacing of the tail's cubic B-spline, s (0: every tap free)
  double ridge = 1e-9;     // Tikhonov term relative to the mean diagonal of the normal matrix
  bool isValid(std::string* why) const;
};

struct ReferenceProjection {
  Eigen::VectorXd inputFromReference;  // u_r, same length as u
  Eigen::VectorXd taps;                // h_{-future} .. h_{past}
  int pastTaps = 0, futureTaps = 0;
  int freeParameters = 0;  // free taps plus spline coefficients
  Eigen::MatrixXd basis;    // taps = basis * coefficients (rows: lags -future .. past)
  double fitPercent = 0.0;  // (5.2) of u_r against u: how much of u the reference explains
  bool ok = false;
  std::string message;      // why not, when !ok
};

// Stage 1: least squares of u on the FIR of r (normal equations, Cholesky). u and r must
// have the same length and their means removed; throws std::invalid_argument on misuse.
ReferenceProjection projectOnReference(const Eigen::VectorXd& u, const Eigen::VectorXd& r,
                                       double sampleTime,
                                       const ReferenceProjectionOptions& options = {});

// What the indirect method compares: the measured motor angle itself (the default: on 24
// simulated logs its 99 % intervals missed 3 of 192 truths), or its backward difference (the
// velocity the controller forms), which weighs the resonances more and the slow load
// disturbance less, with slightly narrower intervals that missed 7 of 192.
enum class LoopOutput { MotorAngle, MotorVelocity };
const char* toString(LoopOutput o);  // "motor-angle", "motor-velocity"
std::optional<LoopOutput> loopOutputFromString(std::string_view s);

// The cascaded controller of Figure 5.1 (ControllerOptions, as the simulator runs it) closed
// around the ZOH-sampled plant at the controller's rate: at tick k the angle a_k = C x_k is
// read, v_k = (a_k - a_{k-1}) / T, e_k = k_p (r_k - a_k) - v_k, I_k = I_{k-1} + T e_k,
// u_k = k_v (e_k + I_k / T_i), x_{k+1} = A_d x_k + B_d u_k, from rest (x_0 = 0, a_{-1} = 0,
// I_{-1} = 0). Returns the loop's output (angle, or its backward difference) for the
// reference r. The model's output must be the motor angle (D = 0); throws
// std::invalid_argument otherwise or when the sample time is not the controller's period.
Eigen::VectorXd simulateLoop(const ParametricModel& model, const ControllerOptions& controller,
                             const Eigen::VectorXd& r, double sampleTime,
                             LoopOutput output = LoopOutput::MotorAngle);

// Output errors of that loop against the measured angle y (relative to the angle at rest, as
// r) compared as `output`, and, when asked, psi = -d eps / d theta for the parameters `free`
// (indices into parameters()) from the loop's sensitivity system (6.27). Throws like
// simulateLoop.
PemEvaluation evaluateLoop(const ParametricModel& model, const ControllerOptions& controller,
                           const Eigen::VectorXd& r, const Eigen::VectorXd& y, double sampleTime,
                           const std::vector<int>& free, bool withGradient, LoopOutput output);

struct ClosedLoopPemOptions {
  ClosedLoopMethod method = ClosedLoopMethod::TwoStage;
  ReferenceProjectionOptions projection;
  // Indirect: the controller the log was recorded with, and the output compared.
  ControllerOptions controller;
  LoopOutput loopOutput = LoopOutput::MotorAngle;
  // Indirect: the first samples of (r, y) that the loop runs through from rest but the loss
  // leaves out, for an estimation range that starts after the log's first sample.
  Eigen::Index loopWarmup = 0;
  // Options of the pem run; with TwoStage the noise model is output error and the covariance
  // the sandwich (these two fields are overridden).
  PemOptions pem;
  // Adds the uncertainty of the stage-1 FIR to the covariance (the W^T n term above).
  bool stage1Uncertainty = true;
  bool isValid(std::string* why) const;
};

struct ClosedLoopPemResult {
  ClosedLoopMethod method = ClosedLoopMethod::Direct;
  ReferenceProjection projection;  // filled with TwoStage
  PemResult pem;                   // summary.message explains a failure of either stage
};

// Estimates the free parameters of model from the closed-loop record (u, y, r) at sampleTime
// by the chosen method. Direct ignores r (it may be empty) and runs pem(options.pem) on
// (u, y). Indirect ignores u: y is the measured motor angle and r the position reference as
// logged (means kept, from the start of the log, where the loop is at rest), at the
// controller's rate, its loss over the samples after loopWarmup; a physical model whose output is the motor velocity is fitted with the
// motor angle as output and returned with its own output. Its covariance is the sandwich.
// Throws std::invalid_argument on misuse; data failures end in pem.summary.
ClosedLoopPemResult pemClosedLoop(const ParametricModel& model, const Eigen::VectorXd& u,
                                  const Eigen::VectorXd& y, const Eigen::VectorXd& r,
                                  double sampleTime, const ClosedLoopPemOptions& options = {},
                                  const ProgressCallback& progress = {});

}  // namespace flexarm
