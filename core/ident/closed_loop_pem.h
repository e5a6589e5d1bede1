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
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/pem.h"

namespace flexarm {

enum class ClosedLoopMethod { Direct, TwoStage };  // pem on (u, y), or on (u_r, y)
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

struct ClosedLoopPemOptions {
  ClosedLoopMethod method = ClosedLoopMethod::TwoStage;
  ReferenceProjectionOptions projection;
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
// (u, y). Throws std::invalid_argument on misuse; data failures end in pem.summary.
ClosedLoopPemResult pemClosedLoop(const ParametricModel& model, const Eigen::VectorXd& u,
                                  const Eigen::VectorXd& y, const Eigen::VectorXd& r,
                                  double sampleTime, const ClosedLoopPemOptions& options = {},
                                  const ProgressCallback& progress = {});

}  // namespace flexarm
