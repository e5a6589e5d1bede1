#pragma once
// Grey-box prediction-error estimation of continuous-time physical models (5.3)/(5.7):
// x' = A(theta) x + B(theta) u, y = C(theta) x + D(theta) u, sampled with a zero-order hold
// (the input is held constant between samples, as a torque reference from a digital
// controller is). Output-error form (K = 0) or innovations form with the discrete-time gain K
// estimated as extra parameters: x(t+1) = Ad x + Bd u + K eps(t), yhat = C x + D u.
// The gradient psi (4.20) comes from the sensitivity system (6.27) of the ZOH-sampled model,
// with d(Ad, Bd)/dtheta from the exact derivative of the matrix exponential.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/blackbox.h"
#include "core/ident/evaluation.h"
#include "core/models/parametric_model.h"

namespace flexarm {

enum class NoiseModel { OutputError, Innovations };  // K = 0, or K estimated
const char* toString(NoiseModel m);
std::optional<NoiseModel> noiseModelFromString(std::string_view s);

// How free parameters are searched: as they are, scaled by their initial magnitude, or as
// logarithms (positive parameters only: the search then keeps them positive).
enum class ParameterScaling { None, Scale, Log };
const char* toString(ParameterScaling s);
std::optional<ParameterScaling> parameterScalingFromString(std::string_view s);

// Ad = e^{A T}, Bd = int_0^T e^{A s} ds B of a continuous model (zero-order hold).
StateSpace discretizeZoh(const StateSpace& continuous, double sampleTime);

// The ZOH-sampled matrices of a one-input, one-output parametric model and, on request, their
// derivatives along each parameter of `free` (indices into parameters()), from the exact
// derivative of the matrix exponential: the ingredients of the sensitivity system (6.27).
struct SampledModel {
  Eigen::MatrixXd Ad, Bd, C, D;
  std::vector<Eigen::MatrixXd> dAd, dBd, dC, dD;  // one per free parameter
};
SampledModel sampleZoh(const ParametricModel& model, double sampleTime,
                       const std::vector<int>& free, bool withGradient);

struct PemEvaluation;
// Output errors y - yhat of a sampled model driven by u from zero state and, when asked,
// psi = -d eps / d theta from its sampled derivatives (the sensitivity system (6.27)), e.g.
// of a closed loop assembled from a sampled plant. stable: the spectral radius of Ad is < 1.
PemEvaluation evaluateSampled(const SampledModel& sampled, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& y, bool withGradient);

// An output-error predictor in place of the open-loop simulation: the prediction errors and,
// when asked, psi = -d eps / d theta_free (physical units, columns in `free` order), e.g. of
// a closed loop driven by a reference. Must throw std::invalid_argument for values the model
// rejects.
using OutputErrorPredictor = std::function<PemEvaluation(
    const ParametricModel& model, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
    double sampleTime, const std::vector<int>& free, bool withGradient)>;

// How the covariance of the estimate is formed: lambda R^{-1} assuming white prediction
// errors (4.37), or the sandwich R^{-1} Q R^{-1} that also holds for coloured errors
// independent of the input (e.g. output error on the noise-free input of a closed loop).
enum class CovarianceKind { White, Sandwich };
const char* toString(CovarianceKind k);
std::optional<CovarianceKind> covarianceKindFromString(std::string_view s);

struct PemOptions {
  NoiseModel noiseModel = NoiseModel::OutputError;
  // Log applies to parameters whose lower bound is >= 0 and value > 0; others are scaled.
  ParameterScaling scaling = ParameterScaling::Log;
  int maxIterations = 100;
  double relativeTolerance = 1e-9;
  double initialDamping = 1e-3;
  // Extra starting points: full parameter vectors in parameters() order (free ones are used).
  std::vector<std::vector<double>> userStarts;
  // Random starts: free parameters multiplied by exp(U(-ln f, ln f)), f = randomFactor.
  int randomStarts = 0;
  double randomFactor = 2.0;
  unsigned seed = 1;
  // Starts from non-parametric notches and peaks (rad/s): among `screenCandidates` random
  // points (factor screenFactor), the `notchPeakStarts` whose model notches and peaks lie
  // closest (in log frequency) to these are fitted.
  std::vector<double> targetNotches, targetPeaks;
  int notchPeakStarts = 0;
  int screenCandidates = 300;
  double screenFactor = 4.0;
  double level = 0.99;  // confidence level of the reported intervals
  CovarianceKind covariance = CovarianceKind::White;
  // Lag window M of the sandwich (Bartlett weights over |tau| <= M); 0: a tenth of the
  // record (automaticCovarianceLags).
  int covarianceLags = 0;
  // When set, the loss is formed with this predictor instead of the ZOH simulation of the
  // model from u (output error only).
  OutputErrorPredictor predictor;
  // Several experiments: u and y hold them one after another and these are their sample
  // counts (they sum to the samples of u); empty: one experiment. The loss (4.6) is summed
  // over the experiments, each predicted from zero state at its own first sample (no
  // transient across a seam), and the covariance comes from the stacked gradient. Once a
  // first fit has estimated each experiment's noise variance lambda_k, the fit is refined
  // with each experiment's errors weighted by sqrt(lambda / lambda_k) (lambda the pooled
  // one), the likelihood's loss for experiments of different noise levels; the reported loss
  // is that weighted one.
  std::vector<Eigen::Index> experimentLengths;
  bool isValid(std::string* why) const;
};

struct PemParameter {
  std::string name, unit;
  double value = 0.0;
  bool free = false;
  double std = 0.0;  // 0 for fixed parameters
  double lower = 0.0, upper = 0.0;  // value -+ z std at the options' level
};

struct PemResult {
  std::unique_ptr<ParametricModel> model;  // a clone holding the estimated values
  Eigen::VectorXd K;                       // innovations gain (empty for output error)
  std::vector<PemParameter> parameters;    // every physical parameter, then K1..Kn
  // Covariance of the free parameters (physical units) in the order of freeNames.
  Eigen::MatrixXd covariance;
  std::vector<std::string> freeNames;
  std::vector<int> freeIndices;  // indices into model->parameters() (K entries excluded)
  double sampleTime = 0.0;
  EstimateSummary summary;
  int starts = 0;        // number of starting points tried
  int bestStart = -1;    // 0: the model's own values; then user, notch/peak and random ones
  std::vector<double> startLosses;
  CovarianceKind covarianceKind = CovarianceKind::White;
  int covarianceLags = 0;  // lag window used by the sandwich covariance
};

// Estimates the free parameters of model from u and y sampled at sampleTime (the data's rate).
// Throws std::invalid_argument on misuse (sizes, options, no free parameter).
PemResult pem(const ParametricModel& model, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
              double sampleTime, const PemOptions& options = {},
              const ProgressCallback& progress = {});

// Prediction errors of the model (K empty: output error, i.e. y minus the ZOH simulation).
Eigen::VectorXd predictionErrors(const ParametricModel& model, const Eigen::VectorXd& K,
                                 const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                 double sampleTime);

// ZOH simulation of the model's output from zero initial state.
Eigen::VectorXd simulate(const ParametricModel& model, const Eigen::VectorXd& u,
                         double sampleTime);

// Continuous-time frequency response C (i w - A)^{-1} B + D with bands from the covariance of
// the free parameters (freeIndices into parameters(); empty covariance: no bands).
FrequencyResponse frequencyResponse(const ParametricModel& model,
                                    const std::vector<double>& omega,
                                    const Eigen::MatrixXd& covariance = {},
                                    const std::vector<int>& freeIndices = {},
                                    double level = 0.99);

// Loss (4.6) and psi of the free parameters in physical units, for checks and studies.
struct PemEvaluation {
  Eigen::VectorXd eps;
  Eigen::MatrixXd psi;  // -d eps / d theta_free, columns in freeIndices order (then K)
  bool stable = true;   // predictor stable
};
PemEvaluation evaluatePredictor(const ParametricModel& model, const Eigen::VectorXd& K,
                                const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                double sampleTime, const std::vector<int>& freeIndices,
                                bool withGradient, bool gradientOfK);

}  // namespace flexarm
