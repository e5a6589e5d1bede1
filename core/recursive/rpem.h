#pragma once
// Recursive prediction-error identification of the physical parameters of a continuous-time
// model sampled with a zero-order hold (the seed's chapter 6): Algorithm 6.1 (forgetting
// factor, (6.12)-(6.15)) and Algorithm 6.2 (Kalman-filter gain, (6.17)-(6.20)), with the
// regularisation (6.8)/(6.9). The predictor is output error (6.21); its gradient psi comes
// from the continuous-time sensitivity system (6.22)-(6.27), sampled exactly (zero-order hold)
// at the current estimate every sample, or from the numerical differences (6.33).
//
// Two ways to use it, one implementation:
//  - sample by sample: RecursiveEstimator::update(u, y) consumes one sample and returns
//    theta(t), diag P(t), sigma(t) and the prediction error at once (a panel animates it, a
//    diagnosis tests it as data arrive);
//  - a whole log: recursiveIdentification(...) chooses P(0) as the seed does, runs the
//    estimator over every sample and returns the trajectory and a summary.
// The data are prepared vectors: u the torque reference, y the motor velocity, both sampled
// at sampleTime (means removed as for any output-error fit).
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/models/parametric_model.h"

namespace flexarm {

// How P is carried between samples: forgetting factor (6.6), Algorithm 6.1; or random-walk
// parameters with R1, R2 (6.7), Algorithm 6.2.
enum class RecursiveAlgorithm { ForgettingFactor, Kalman };
const char* toString(RecursiveAlgorithm a);  // "forgetting", "kalman"
std::optional<RecursiveAlgorithm> recursiveAlgorithmFromString(std::string_view s);

// How psi(t) = d yhat / d theta is formed: the sensitivity system (6.27) sampled exactly
// (Section 6.3.1, the seed's choice), or central differences of the one-step prediction
// (6.33) from the shared past state (Section 6.3.2; Example 6.1 shows why it can fail for an
// output-error predictor).
enum class RecursiveGradient { Sensitivity, Difference };
const char* toString(RecursiveGradient g);  // "sensitivity", "difference"
std::optional<RecursiveGradient> recursiveGradientFromString(std::string_view s);

// How the estimator follows parameters that change (the seed's 9.2 names the two beside the
// fixed design of Algorithms 6.1/6.2):
//  Fixed:    lambda (6.13) or R1 (6.18) as designed, the seed's.
//  Variable: information-constant forgetting (Fortescue, Kershenbaum and Ydstie, 1981): the
//            forgetting factor of each sample is chosen so that the information the estimate
//            rests on stays constant, lambda(t) = 1 - eps(t)^2 / (Sigma_0 (1 + psi^T P psi)),
//            Sigma_0 = sigma^2 / (1 - lambda): lambda on average while the model fits, lower
//            (down to lambdaMin) when the prediction errors grow after a change. Forgetting
//            factor algorithm only.
//  Bank:     estimators started at hypothesised change times (every bankSpacingS seconds, the
//            last bankSize of them kept), each from the running estimate with P(0) as if the
//            data before its start were not known; when one predicts the data since its start
//            better than the running estimate by more than bankThreshold noise variances (a
//            likelihood ratio of the change hypothesis, its squared errors summed per design
//            sample), once it has run bankMinAgeS, the change is accepted: the running
//            estimate becomes that estimator's and the change time is reported.
enum class RecursiveTracking { Fixed, Variable, Bank };
const char* toString(RecursiveTracking t);  // "fixed", "variable", "bank"
std::optional<RecursiveTracking> recursiveTrackingFromString(std::string_view s);

struct RecursiveOptions {
  // Model parameters in theta, by the model's names. A name written "NAME^-1" puts the inverse
  // of NAME in theta (the seed's J_a^-1); so does listing NAME in `inverted`. Empty: nothing is
  // estimated, the estimator is the fixed nominal predictor (its prediction errors only).
  std::vector<std::string> estimate = {"k_T", "J_a", "f_m"};
  // Estimated parameters theta holds as inverses, by model name (seed: J_a).
  std::vector<std::string> inverted = {"J_a"};

  RecursiveAlgorithm algorithm = RecursiveAlgorithm::ForgettingFactor;
  double lambda = 0.995;  // forgetting factor of (6.13), 0 < lambda <= 1 (seed: 0.995)
  // diag R1 of (6.18), one value per theta entry. Empty: the seed's (6.54), 1e-8 * (5, 50, 500)
  // for k_T, J_a^-1, f_m (a parameter without a seed value then needs r1 given).
  std::vector<double> r1;
  // The sample time lambda and R1 are designed for, s. The seed designs them per sample at
  // 200 Hz (0.005 s): a memory 1 / (1 - lambda) of 200 samples, one second, and a random walk
  // of variance R1 per 5 ms. Run at another sample time T, the estimator keeps that memory and
  // that random walk per second: lambda^(T / designSampleTime) and R1 T / designSampleTime
  // (perSample()). 0: lambda and R1 are per sample at whatever rate the data have.
  double designSampleTime = 0.005;
  double r2 = 1.0;  // R2 of (6.18) (the seed normalises it to 1)

  RecursiveTracking tracking = RecursiveTracking::Fixed;
  // Variable: the lowest forgetting factor a sample may use (per design sample, as lambda).
  double lambdaMin = 0.95;
  // Bank: a hypothesised change time every bankSpacingS seconds, the last bankSize kept (they
  // cover bankSize * bankSpacingS seconds back), accepted at bankThreshold noise variances.
  double bankSpacingS = 0.25;
  int bankSize = 6;
  double bankThreshold = 40.0;
  // Bank: a hypothesis is accepted only once it has run this long (s): an estimator started on
  // a short stretch of data fits its noise, which would be read as a change.
  double bankMinAgeS = 0.5;
  // Bank: P(0) of an estimator started at a hypothesised change, as a multiple of P(0).
  double bankCovarianceScale = 100.0;
  double mu = 0.0;  // regularisation (6.8)/(6.9), >= 0 (seed: 0, the excitation is good)

  RecursiveGradient gradient = RecursiveGradient::Sensitivity;
  double differenceStep = 1e-4;  // Delta of (6.33), relative to |theta_i| (absolute if 0)

  // theta(0) = startScale * theta_nominal (in theta's form: the seed starts 20 % above, 1.2).
  double startScale = 1.0;
  // theta(0) itself, one value per theta entry (theta's form); overrides startScale.
  std::vector<double> thetaStart;
  // diag P(0), one value per theta entry. Empty: recursiveIdentification chooses it as the
  // seed does (steadyStateCovariance); a RecursiveEstimator needs it given.
  std::vector<double> p0;
  // Samples of the data the P(0) pre-run uses (0: all of them).
  std::size_t p0Samples = 0;

  // lambda_0 of (7.8), the variance of the prediction errors: sigma_i = sqrt(lambda_0 P_ii / s)
  // with s = R2 for Algorithm 6.2 and 1 for Algorithm 6.1. 0: estimated recursively from the
  // prediction errors (weights 1/t, then 1 - lambda once t > 1 / (1 - lambda)).
  double noiseVariance = 0.0;

  // false: theta stays at theta(0) while P and psi are updated - the seed's pre-run for P(0)
  // (Section 6.6.2) and a fixed-model predictor for comparison (7.18).
  bool updateParameters = true;
  // P is taken as blown up when a diagonal element exceeds this multiple of its P(0) value.
  double covarianceLimit = 1e8;
  // An update that would take theta outside its bounds (the model's, e.g. f_m >= 0) is held
  // back: theta(t) = theta(t-1), the projection of Ljung and Soederstroem. When it keeps
  // pushing outside for this long (seconds), the estimate has left its bounds: Diverged.
  double maxHeldSeconds = 1.0;

  bool isValid(std::string* why) const;
};

// One entry of theta and how it relates to the model's parameter.
struct RecursiveParameter {
  std::string name;       // theta's name: "k_T", "J_a^-1"
  std::string modelName;  // the model's name: "k_T", "J_a"
  std::string unit;       // theta's unit: "1", "1/(kg m^2)"
  std::string modelUnit;  // the model's unit
  bool inverted = false;  // theta = 1 / model value
  int modelIndex = -1;    // index into the model's parameters()
  double nominal = 0.0;   // theta's nominal value (from the model given)
  double lower = 0.0, upper = 0.0;  // theta's bounds, from the model's bounds

  // The model's value for theta's value v (1/v when inverted).
  double toModel(double v) const { return inverted ? 1.0 / v : v; }
  // The model value's standard deviation for theta = v with std s (s / v^2 when inverted).
  double sigmaToModel(double v, double s) const { return inverted ? s / (v * v) : s; }
};

// The options as the estimator runs them on data sampled every sampleTime: lambda and R1 of a
// design for designSampleTime carried over to sampleTime (the same memory and random walk per
// second), R1 filled with the seed's (6.54) where it was empty and the Kalman gain runs, and
// designSampleTime 0 (the values are then per sample). params: theta's entries (for R1's seed
// values). Throws std::invalid_argument as kalmanR1 does.
RecursiveOptions perSample(const RecursiveOptions& options, double sampleTime,
                           const std::vector<RecursiveParameter>& params);
// What lambda and R1 are given per, in words: "per 200 Hz sample" (or "per sample").
std::string designRateText(const RecursiveOptions& options);

// What one sample of the recursion produced.
struct RecursiveStep {
  std::size_t index = 0;  // sample number, 0 for the first sample given
  double time = 0.0;      // seconds: startTime + index * sampleTime
  double u = 0.0, y = 0.0;
  double yhat = 0.0;     // yhat(t, theta(t-1)) (6.3)
  double epsilon = 0.0;  // y - yhat
  Eigen::VectorXd theta;      // theta(t) after the update (6.15)/(6.20)
  Eigen::VectorXd pDiagonal;  // diag P(t) as (6.13) resp. (6.18) define P(t)
  Eigen::VectorXd sigma;      // sqrt(lambda_0 P_ii(t) / s) (7.8), theta's units
  Eigen::VectorXd psi;        // psi(t), the gradient of yhat(t) in theta
  Eigen::VectorXd gain;       // K(t) of (6.14)/(6.19)
  double noiseVariance = 0.0; // lambda_0 used for sigma
  double lambda = 1.0;        // the forgetting factor this sample used (Variable: lambda(t))
  // Bank: a change was accepted at this sample; it happened at changeTime (s).
  bool change = false;
  double changeTime = 0.0;
  bool held = false;          // the update would have left the bounds and was held back
  bool ok = true;             // false once the estimate left its bounds or P blew up
};

// A recursive estimator fed one sample at a time. Copyable (a copy continues independently
// from the same state), so a bank of predictors or a what-if can branch off it.
class RecursiveEstimator {
 public:
  // Starts at theta(0) (options.thetaStart, else startScale * nominal) with P(0) =
  // diag(options.p0). Parameters not in theta stay at the model's values. Throws
  // std::invalid_argument on misuse: invalid options, a name the model lacks, p0 missing or of
  // the wrong size, r1 of the wrong size or without a seed default, a model with more than one
  // input or output, theta(0) outside the bounds.
  RecursiveEstimator(const ParametricModel& nominal, double sampleTime,
                     const RecursiveOptions& options, double startTime = 0.0);
  RecursiveEstimator(const RecursiveEstimator& other);
  RecursiveEstimator& operator=(const RecursiveEstimator& other);
  RecursiveEstimator(RecursiveEstimator&&) noexcept;
  RecursiveEstimator& operator=(RecursiveEstimator&&) noexcept;
  ~RecursiveEstimator();

  // Processes sample t: predicts yhat(t) with theta(t-1), forms psi(t), updates P and theta
  // (Algorithm 6.1 or 6.2, with (6.9)), then carries the predictor and its gradient to t+1 with
  // the model sampled at theta(t), u(t) held. Once the estimate has left its bounds or P has
  // blown up, nothing changes any more: the last step is returned with ok == false and
  // message() says what happened and when.
  const RecursiveStep& update(double u, double y);

  // yhat(t) of the next sample, from theta(t-1): known before y(t) arrives.
  double prediction() const;
  // The step update() last returned (index 0 with theta(0), P(0) before the first sample).
  const RecursiveStep& last() const;
  // Samples processed so far.
  std::size_t samples() const;
  double sampleTime() const;

  const std::vector<RecursiveParameter>& parameters() const;
  const Eigen::VectorXd& theta() const;
  const Eigen::MatrixXd& covariance() const;  // P(t)
  const Eigen::MatrixXd& initialCovariance() const;  // P(0)
  const Eigen::VectorXd& initialTheta() const;
  const RecursiveOptions& options() const;

  // True while the estimate is inside its bounds and P finite and below its limit.
  bool ok() const;
  // Diverged once ok() turned false, else Converged (the estimator ran well so far).
  Termination termination() const;
  // A sentence: how it ran, or what went wrong at which time.
  const std::string& message() const;

  // A copy of the model with theta's current values (the other parameters nominal).
  std::unique_ptr<ParametricModel> model() const;
  // Back to sample 0: theta(0), P(0), zero predictor state.
  void reset();

 private:
  struct Impl;
  friend class ImplCopy;
  std::unique_ptr<Impl> impl_;
};

// The trajectory of a run, one entry per sample, in columns ready to plot.
struct RecursiveTrajectory {
  std::vector<double> time, y, yhat, epsilon, noiseVariance, lambda;
  // Bank: the changes accepted, when (detected) and at which hypothesised time.
  std::vector<double> changeDetected, changeTime;
  std::vector<std::vector<double>> theta, pDiagonal, sigma;  // [parameter][sample]

  std::size_t size() const { return time.size(); }
  void reserve(std::size_t samples, std::size_t parameters);
  void append(const RecursiveStep& step);
  void clear();
};

// One theta entry at the end of a run, in theta's form and in the model's.
struct RecursiveEstimate {
  RecursiveParameter parameter;
  double start = 0.0, final = 0.0, sigma = 0.0;  // theta's form
  double modelNominal = 0.0, modelStart = 0.0, modelFinal = 0.0, modelSigma = 0.0;
  // Measured over the second half of the run: the standard deviation of theta(t) and the mean
  // of sigma(t). White prediction errors give spread / meanSigma near 1 / sqrt 2 for the
  // forgetting factor; a larger ratio means sigma understates the uncertainty.
  double spread = 0.0, meanSigma = 0.0;
};

// The seed's P(0) (Section 6.6.2): the P update is run with psi at the nominal theta, and the
// time means of P's diagonal form P(0). Also Q (6.53), whose diagonal is the variance of psi
// that (6.49) and Figure 6.4 discuss.
struct InitialCovariance {
  Termination termination = Termination::Failed;
  std::string message;
  Eigen::VectorXd p0;  // diag P(0)
  Eigen::MatrixXd Q;   // (6.53): mean of psi psi^T at the nominal theta
};
// Uses the first options.p0Samples samples (0: all). A data failure (too few samples, an input
// that does not excite a parameter so Q is singular, non-finite data) is a Failed result with a
// sentence. Throws std::invalid_argument on misuse, as the estimator does.
InitialCovariance steadyStateCovariance(const ParametricModel& nominal, const Eigen::VectorXd& u,
                                        const Eigen::VectorXd& y, double sampleTime,
                                        const RecursiveOptions& options);

struct RecursiveResult {
  // Converged: every sample was processed and the estimate stayed within its bounds;
  // Diverged: it left them or P blew up (the message says which and when; the trajectory
  // stops there); Cancelled; Failed: the data could not be used (a sentence says why).
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  std::size_t samples = 0;  // samples processed
  double sampleTime = 0.0;
  std::vector<RecursiveEstimate> estimates;  // theta's entries at the end
  RecursiveTrajectory trajectory;
  Eigen::VectorXd p0;     // diag P(0) used
  Eigen::MatrixXd Q;      // (6.53) from the pre-run (empty when P(0) was given)
  Eigen::MatrixXd P;      // P at the end
  double rmsEpsilon = 0.0;  // RMS of the prediction errors over the run
  double epsilonLag1 = 0.0; // their lag-1 autocorrelation (0 for white errors)
  // A sentence when sigma cannot be taken at its word: the prediction errors are coloured or
  // the estimates varied more than sigma says (empty otherwise).
  std::string caveat;
  std::shared_ptr<const ParametricModel> model;  // the model at the final estimate
  // The options as the estimator ran them (perSample: lambda and R1 per sample of the data).
  RecursiveOptions asRun;
};

// The two halves of recursiveIdentification, for a caller that feeds the samples itself (a
// panel that animates the run as the log plays): startRecursive checks the data and chooses
// P(0) as recursiveIdentification does and hands over the estimator at sample 0 (or a Failed
// result with a sentence); finishRecursive summarises the run as recursiveIdentification
// returns it. Misuse throws std::invalid_argument, as there.
struct RecursiveStart {
  RecursiveResult failed;  // termination Failed with a sentence when it could not start
  std::optional<RecursiveEstimator> estimator;
  Eigen::MatrixXd Q;  // (6.53) from the pre-run (empty when P(0) was given)
};
RecursiveStart startRecursive(const ParametricModel& nominal, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& y, double sampleTime,
                              const RecursiveOptions& options, double startTime = 0.0);
// trajectory: the steps the estimator returned (ok ones); totalSamples: how many the data had;
// cancelled: the caller stopped early. seconds is left for the caller.
RecursiveResult finishRecursive(const RecursiveEstimator& estimator, RecursiveTrajectory trajectory,
                                std::size_t totalSamples, bool cancelled,
                                const Eigen::MatrixXd& Q = {});

// Runs the estimator over a whole log: P(0) from options.p0, else steadyStateCovariance on the
// same data; then every sample. Progress is reported as the fraction of samples done.
RecursiveResult recursiveIdentification(const ParametricModel& nominal, const Eigen::VectorXd& u,
                                        const Eigen::VectorXd& y, double sampleTime,
                                        const RecursiveOptions& options,
                                        const ProgressCallback& progress = {},
                                        double startTime = 0.0);

}  // namespace flexarm
