#pragma once
// The fit pipeline: one call from logs and choices to an estimated model and its evaluation,
// used unchanged by `flexarm fit` and `flexarm bode`, the Fit panel and the session part
// "fits" (front ends only collect choices, run it, and show or store what it returns):
//   1. data: prepareFitData (fit_data.h) of every estimation and validation experiment;
//      models whose output is the motor velocity (physical ones as built, black-box and
//      non-parametric ones as the seed does, Section 5.2) get it from a logged motor angle;
//   2. the closed-loop method of a physical output-error fit of a log with a reference
//      (closed_loop_pem.h): direct, two-stage or indirect, or Auto, which picks one by the
//      rule measured in bench/bench_fit_closed_loop.cpp and says which and why. The indirect
//      fit's controller is the log's (metadata) or, when the log does not name it, the
//      cascade of Figure 5.1 identified from the log (controller_ident.h);
//   3. start values: the start model's own, plus random ones and two whose notches and peaks
//      match the SPA estimate when random starts are asked for;
//   4. the estimator: pem (5.7) / pemClosedLoop for physical models, estimatePolynomial (4.6)
//      for black-box structures (4.8), spa (4.28) or etfe (4.24) for non-parametric ones;
//   5. evaluation: fit % (5.2) on the estimation and every validation experiment, residual
//      tests, the frequency response with its band, notches and peaks (5.4), and a sentence
//      beside the 99 % intervals where they are known to promise too much.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/blackbox.h"
#include "core/ident/closed_loop_pem.h"
#include "core/ident/controller_ident.h"
#include "core/ident/fit_data.h"
#include "core/ident/idim.h"
#include "core/ident/model_output.h"
#include "core/ident/nonlinear_pem.h"
#include "core/ident/nonparametric.h"
#include "core/ident/pem.h"
#include "core/ident/residuals.h"
#include "core/ident/subspace.h"
#include "core/models/physical_models.h"

namespace flexarm {

enum class FitModelKind { Physical, BlackBox, Spa, Etfe };
const char* toString(FitModelKind k);  // "physical", "black-box", "spa", "etfe"
std::optional<FitModelKind> fitModelKindFromString(std::string_view s);

// What to estimate.
struct FitModelSpec {
  FitModelKind kind = FitModelKind::BlackBox;
  // Physical: the start model (structure, output, start values, free flags).
  std::shared_ptr<const PhysicalModel> start;
  // Physical: named effects (core/models/effects.h) switched on in the start model, their
  // values free or fixed. Any effect makes the fit the nonlinear grey-box estimator
  // (core/ident/nonlinear_pem.h): the plant simulated by Runge-Kutta from the measured torque,
  // output error (5.7), each experiment from rigid-body motion at its first sample's speed,
  // the direct fit of closed-loop logs, the means of the data kept (friction acts on the real
  // velocity); not with the innovations form or the arm acceleration output. The response,
  // notches and peaks are the linear part's.
  std::vector<FitEffect> effects;
  // Physical: the arm as a second output (`--outputs motor,arm`), from a log with an arm-side
  // encoder: the deflection r phi_m - phi_a fitted together with the motor output by the
  // nonlinear estimator, each output's errors weighted by its noise level (estimated by a
  // first fit, then the fit refined).
  bool armOutput = false;
  // Black-box: the structure (4.8) and its orders.
  PolyStructure structure = PolyStructure::Oe;
  PolyOrders orders;
  // Spa: the lag window M; Etfe: the smoothing width; 0: the default.
  int windowWidth = 0;
  bool isValid(std::string* why) const;
  // "three-mass", "three-mass + coulomb_friction", "oe[2 2 1]", "spa", "etfe".
  std::string name() const;
  bool nonlinear() const { return kind == FitModelKind::Physical && (!effects.empty() || armOutput); }
  // The output the model gives is the motor velocity (Section 5.2), so a logged motor angle
  // is differentiated first.
  bool wantsVelocity() const;
};

// The closed-loop method a physical output-error fit uses on a log with a reference.
enum class ClosedLoopChoice { Auto, Direct, TwoStage, Indirect };
const char* toString(ClosedLoopChoice c);  // "auto", "direct", "two-stage", "indirect"
std::optional<ClosedLoopChoice> closedLoopChoiceFromString(std::string_view s);
// What the choice does, in a clause (help texts, tooltips).
const char* describe(ClosedLoopChoice c);

// How a physical model is estimated: by prediction error (the seed's (5.7), the default), or
// its rigid part by inverse dynamics in closed form (core/ident/idim.h): least squares
// (IDIM-LS) or, for closed-loop logs, instrumental variables from the reference (IDIM-IV).
enum class FitMethod { PredictionError, Idim, IdimIv };
const char* toString(FitMethod m);  // "pem", "idim", "idim-iv"
std::optional<FitMethod> fitMethodFromString(std::string_view s);
const char* describe(FitMethod m);

// A value of one physical parameter, by the name parameters() gives it (e.g. "J_m", "k_g").
struct ParameterValue {
  std::string name;
  double value = 0.0;
};

// The interval a fit searches one physical parameter in, by name.
struct ParameterBound {
  std::string name;
  double lower = 0.0, upper = 0.0;
};

// "J_m=1e-3" as a start value and "d_g=-inf:0" (LO <= HI, numbers or -inf/inf) as a bound;
// nullopt when the text is not of that form (the name is not checked here).
std::optional<ParameterValue> parameterValueFromText(const std::string& text);
std::optional<ParameterBound> parameterBoundFromText(const std::string& text);
// Comma-separated start values and bounds ("J_m=1e-3, d_g=-inf:inf"), as the Fit panel takes
// them; false with a sentence naming the item that is neither.
bool startsAndBoundsFromText(const std::string& text, std::vector<ParameterValue>& starts,
                             std::vector<ParameterBound>& bounds, std::string* why);
// The same as text: start values, then bounds.
std::string startsAndBoundsText(const std::vector<ParameterValue>& starts, const std::vector<ParameterBound>& bounds);

// Why a fit request (FitOptions) is refused: the rule it breaks, beside the sentence.
enum class FitIssue {
  None,
  NoStartModel,            // a physical fit without its start model
  NoFreeParameter,         // nothing to estimate
  InvalidEffect,           // an effect's values are not physical
  EffectTwice,
  EffectChangesStructure,  // extra_mass: fit the larger structure instead
  EffectNeedsGearSpring,   // backlash, nonlinear_spring on a model without a gear spring
  EncoderSkewNeedsArm,     // encoder_skew without the arm as an output
  ArmOutputNeedsVelocity,  // the arm as a second output goes with the motor velocity
  EffectsTakeOneOutput,    // effects with the arm acceleration output
  InvalidOrders,           // black-box orders (4.8)
  InvalidWindow,           // SPA / ETFE window
  NoEstimationData,        // no estimation experiment
  NoData,                  // an experiment without its log
  OneExperimentOnly,       // SPA, ETFE, two-stage, indirect and inverse dynamics take one
  EmptyRange,              // a range with start >= end
  OutOfRange,              // decimation, iterations, starts, level, points or depth out of range
  MethodNeedsPhysical,     // idim / idim-iv of a black-box model
  MethodExcludesEffects,
  MethodExcludesDecimation,
  InvalidMethodOptions,    // the inverse dynamics' filters
  ExcludesInnovations,     // an output-error method (two-stage, indirect, effects) and the innovations form
  IndirectExcludesDecimation,
  EffectsNeedDirect,       // effects and the two-stage or indirect fit
  InvalidController,       // the controller of the indirect fit or its identification
  UnknownParameter,        // a start value, bound or free name the model does not have
  OutsideBounds,           // a start value outside its bounds, or bounds LO > HI
  PhysicalOnly,            // start values, bounds, the innovations form, random starts or a
                           // closed-loop method asked of a black-box or non-parametric model
};
const char* toString(FitIssue i);  // "none", "no-start-model", ... (the enum in kebab case)

struct FitCheck {
  FitIssue issue = FitIssue::None;
  std::string message;  // empty when ok
  bool ok() const { return issue == FitIssue::None; }
};

// One experiment: a log and the part of it used.
struct FitExperiment {
  std::shared_ptr<const IdData> data;
  std::optional<SecondsRange> range;  // unset: the whole log
};

struct FitOptions {
  FitModelSpec model;
  // Estimation data: one experiment or several (logs, or ranges of one log). Each is prepared
  // on its own (its own means removed) and the estimator sums the loss (4.6) over them, each
  // predicted or simulated from zero state at its own first sample, so nothing carries across
  // from one experiment to the next (physical models by pem, black-box ones by
  // estimatePolynomial, with PemOptions / PolyEstimateOptions::experimentLengths); the
  // covariance comes from the stacked gradient. Several experiments take the direct fit of a
  // physical model (the two-stage and indirect closed-loop fits take one) and no SPA or ETFE.
  std::vector<FitExperiment> estimation;
  // Validation data: any number of experiments. Each has the means of the estimation
  // experiment on the same log (the same IdData) removed, else those of the first estimation
  // experiment (the model's operating point is the estimation data's).
  std::vector<FitExperiment> validation;
  // Preparation (fit_data.h): channels by name (empty: by role), decimation, means.
  std::string input, output, reference;
  int decimation = 1;
  bool removeMeans = true;
  // Physical models.
  FitMethod method = FitMethod::PredictionError;
  // The inverse-dynamics estimate's filters and friction model (method Idim, IdimIv, and the
  // start values below).
  IdimOptions idim;
  // A prediction-error fit of a flexible model whose start has no inertia given (no start
  // value of an inertia) first estimates the rigid part by IDIM-LS below the start model's
  // first notch; when the start model's total inertia is off by more than a factor of two,
  // its inertias, stiffnesses, dampings and f_m are scaled to match (resonances and damping
  // ratios kept), and the fit says so (the seed's 9.2 asks for good initial values).
  bool idimStart = true;
  NoiseModel noiseModel = NoiseModel::OutputError;
  ClosedLoopChoice closedLoop = ClosedLoopChoice::Auto;
  // The controller the log was recorded with, for the indirect fit; unset: the log's
  // metadata (controller_rate_hz, controller_kp, controller_kv, controller_ti), else the
  // cascade identified from the log.
  std::optional<ControllerOptions> controller;
  ControllerIdentOptions controllerIdent;
  // Start values replacing the start model's, by name; a fixed parameter is held at its start
  // value. A start value of the gear ratio r refers the start model to that ratio: the
  // parameters behind the gear that have no start value of their own (arm- and gear-side
  // inertias, stiffnesses and dampings) are scaled by (r_model / r)^2, which keeps the
  // model's dynamics from the motor (the same transfer function from torque to motor
  // velocity), so r = 1 (motor-side parameters) starts from a stable predictor.
  std::vector<ParameterValue> startValues;
  // Bounds replacing the defaults (fitBounds): a fit never leaves them, and a parameter that
  // ends on one gets a warning naming it and the bound. A start value outside its bounds is
  // invalid; a start model's value outside them is moved onto the bound, with a warning.
  std::vector<ParameterBound> bounds;
  int randomStarts = 0;  // > 0 adds two starts at the SPA notches and peaks as well
  unsigned seed = 1;
  // Physical and black-box models.
  int maxIterations = 100;
  double level = 0.99;  // of the parameter intervals and the response's band
  // Evaluation: points of the frequency response (2 pi / (N T) .. pi / T) and the depth an
  // extremum needs to count as a notch or peak (dB; non-parametric curves use 3).
  int responsePoints = 2000;
  double notchDepthDb = 1.0;
  // The request checked in one place, for every front end: the code of the first rule it
  // breaks and a sentence (FitCheck). checkExceptData: everything but the experiments' data
  // (what a session stores).
  FitCheck checkExceptData() const;
  FitCheck check() const;
  bool isValidExceptData(std::string* why) const;
  bool isValid(std::string* why) const;
};

// A parameter row as the seed's Tables 5.3-5.7 print it.
struct FitParameter {
  std::string name, unit;
  double value = 0.0, std = 0.0, lower = 0.0, upper = 0.0;  // interval at FitOptions::level
  bool free = false;
  std::string effect;  // the effect it belongs to ("coulomb_friction"); empty: the model's
  // A free parameter the data do not determine (fit_detail::assessDeterminacy): its std is 0
  // or not finite (the loss is flat or singular along it), it sits on a bound (the curvature's
  // interval does not hold there), or its interval is wider than its value. `undetermined`
  // says which, as a clause; std and the interval are then not to be quoted.
  bool determined = true;
  std::string undetermined;
};

// The evaluation on one experiment. Validation: data with the estimation data's means, fit %
// (5.2) on its validation range simulated from the log's first sample. Estimation: data as
// prepared (its own means), fit % on its estimation range simulated from the range's first
// sample, as the estimator saw it.
struct FitValidation {
  PreparedData data;
  // Its place in the experiment list as given (FitOptions::estimation or ::validation, from 0):
  // a repeated experiment is counted once, so a list may hold fewer than were given.
  std::size_t given = 0;
  std::optional<double> fitPercent;       // the seed's (5.2)
  std::optional<double> fitPercentNrmse;  // MATLAB compare's NRMSE fit (evaluation.h)
  FitBasis basis;  // what the fit % is of (model_output.h): the output, start, rate, samples
  Eigen::VectorXd simulated;  // the whole log, from its first sample
};

// How well a physical estimate predicts the deflection r phi_m - phi_a between motor and arm
// (arm side, rad) from the torque alone, against what the log's motor encoder and arm-side
// encoder (arm_angle_rad) measure: the estimate's deflection (PhysicalModel::armDeflectionRow,
// or the nonlinear plant's) simulated from the torque as the output is, r the estimate's gear
// ratio. Each signal is taken about its own mean over the range (the two encoders' zeros are
// unrelated), so a fit % says how much of the deflection's variation the model explains.
struct DeflectionCheck {
  std::optional<double> fitPercent, fitPercentNrmse;                      // estimation range
  std::optional<double> fitPercentValidation, fitPercentValidationNrmse;  // first validation
  double rmsEstimation = 0.0, rmsValidation = 0.0;  // of the prediction error (rad; NaN: none)
  double measuredRms = 0.0;  // of the measured deflection about its mean, estimation range (rad)
  double gearRatio = 0.0;
  // A sampling skew between the two encoders: the time T_o (s) by which the arm encoder's
  // reading lags (positive) the motor's, by least squares of the prediction error on the
  // measured arm velocity (d_measured = d_model + T_o phi_a'), with its std; and the fit %
  // (5.2) once that skew is taken out. A skew read as stiffness would make the spring look
  // softer (or harder) than it is.
  double skewSeconds = 0.0, skewStd = 0.0;
  std::optional<double> fitPercentWithoutSkew;
  // Over the whole first estimation log and the first validation log, about the estimation
  // range's means (the Compare panel overlays them); times are the data's.
  Eigen::VectorXd measured, predicted, measuredValidation, predictedValidation;
};

// The deflection r phi_m - phi_a the linear part of a physical model predicts from the torque
// u sampled every sampleTime: the zero-order hold (5.3) from zero state at the first sample,
// the output PhysicalModel::armDeflectionRow (all zero for the rigid model), plus, as an arm
// encoder reading encoderSkew seconds late sees it, encoderSkew times the arm's speed.
Eigen::VectorXd simulateDeflection(const PhysicalModel& model, const Eigen::VectorXd& u, double sampleTime,
                                   double encoderSkew = 0.0);
// The encoder_skew T_o among effects (0 without it).
double encoderSkewOf(const std::vector<Effect>& effects);
// The deflection the motor and arm-side encoders measure, r phi_m - phi_a over the whole of d
// (the logged motor angle, or an output that is the angle, and arm_angle_rad); empty without
// both.
Eigen::VectorXd measuredDeflection(const PreparedData& d, double gearRatio);

// What became of a fit, beside its sentence (FitResult::message).
enum class FitStatus {
  Ok,          // an estimate: converged, or at the iteration limit (a warning says so)
  BadRequest,  // the options ask for more than the data can carry (polynomial orders beyond
               // the samples or the work FlexArm allows): a request to change
  BadData,     // the data cannot carry the fit asked for (no usable channel or range, a
               // closed-loop method the log cannot run, a gear ratio that is no ratio)
  Failed,      // the estimator failed, diverged or met numerical trouble on usable data
  Cancelled,
};
const char* toString(FitStatus s);  // "ok", "bad-request", "bad-data", "failed", "cancelled"

// What a warning of a fit is about, beside its sentence (FitResult::warnings).
enum class FitWarning {
  Other,
  MaxIterations,       // the estimator stopped at its iteration limit
  OnBound,             // a parameter ended on one of its bounds
  SkippedStarts,       // random starts skipped for numerical trouble
  Unstable,            // G is unstable: no fit % of the simulated output
  ClosedLoopBias,      // a closed-loop log fitted by a method the feedback biases (4.43)
  ZeroOrderHold,       // decimated data: the intervals ignore the zero-order hold's error
  SmoothingSpeed,      // coulomb_friction's v_s set from the data's speed
  LinearPartResponse,  // the response of a fit with effects is its linear part's
  RandomStartsUnused,  // a fit with effects starts from the values given only
  DeflectionDiverges,  // the deflection check could not simulate the estimate
  RepeatedExperiment,  // an experiment holds the samples of another: counted once
};
const char* toString(FitWarning w);  // "other", "max-iterations", "on-bound", ...

struct FitResult {
  Termination termination = Termination::Failed;
  std::string message;  // a sentence: how it ended, or why it failed
  double seconds = 0.0;
  FitStatus status = FitStatus::Failed;

  FitModelSpec model;
  PreparedData data;  // the (first) estimation experiment as prepared
  // Every estimation experiment (the first's data are `data`), in FitOptions order.
  std::vector<FitValidation> estimation;
  std::vector<FitValidation> validation;

  // Physical fits of closed-loop logs: the method used and why (Auto states its rule), stage
  // 1's fit % of the input (two-stage), the controller the indirect fit closed around the model and where it
  // came from.
  std::optional<ClosedLoopMethod> method;
  std::string methodDescription;  // what the method did, e.g. "two-stage closed-loop fit: the
                                  // reference explains 45.1 % of the input, ..."
  std::string methodReason;       // why it was used ("asked for", or Auto's rule and evidence)
  std::optional<double> referenceFitPercent;
  std::optional<ControllerOptions> controller;
  std::string controllerSource;  // a sentence: metadata or identified, and its fit % of the torque
  std::optional<double> controllerFitPercent;

  // The inverse-dynamics estimate: the result of method Idim/IdimIv, or the one a
  // prediction-error fit started from (idimStart), with the sentence saying what it did.
  std::optional<IdimResult> idim;
  std::string idimNote;

  EstimateSummary summary;
  std::shared_ptr<const PhysicalModel> physical;  // physical estimate (the start's output)
  std::vector<Effect> effects;                    // the effects' estimated values
  // Nonlinear fits: the motor speed of the smooth signs, from the data (1 % of the RMS motor
  // speed), and with the arm as an output the weight its errors had.
  double smoothingSpeed = 0.0;
  double deflectionWeight = 0.0;
  Eigen::VectorXd K;                              // innovations gain (empty: output error)
  Eigen::MatrixXd covariance;                     // of physical->parameters()[freeIndices]
  // With effects: the covariance of every free parameter, the model's (freeIndices order)
  // then the effects' free values (in FitModelSpec::effects order).
  Eigen::MatrixXd fullCovariance;
  std::vector<int> freeIndices;
  CovarianceKind covarianceKind = CovarianceKind::White;
  std::shared_ptr<const PolynomialModel> polynomial;  // black-box estimate
  // A state-space fit (ss): the subspace estimate it started from, with its singular values
  // and the order chosen and why (core/ident/subspace.h).
  std::shared_ptr<const SubspaceEstimate> subspace;
  NonparametricEstimate nonparametric;                // spa / etfe
  std::vector<FitParameter> parameters;

  // Fit % (5.2) on the estimation range (simulated from its first sample), or nullopt when
  // the simulated output diverges (unstable G) or for non-parametric estimates. With several
  // experiments, of them all together: 1 - sum of every squared error / sum of every squared
  // deviation from its own experiment's mean (each experiment's own is in `estimation`).
  std::optional<double> fitEstimation;
  // The same errors as MATLAB's compare prints them: the NRMSE fit 1 - ||e|| / ||y - mean y||
  // (fitPercentsFromSums, evaluation.h), set exactly when fitEstimation is.
  std::optional<double> fitEstimationNrmse;
  // Of the first validation experiment, when there is one: (5.2) and NRMSE.
  std::optional<double> fitValidation() const;
  std::optional<double> fitValidationNrmse() const;
  Eigen::VectorXd simulated;  // of the whole estimation log, from its first sample
  // Prediction errors (one-step for black-box models, output errors for physical ones) of
  // the validation range (the estimation range without one), tested for whiteness and
  // independence of the input at 99 %; nullopt when the range is too short.
  std::optional<ResidualAnalysis> residuals;
  bool residualsOnValidation = false;
  FrequencyResponse response;
  std::vector<double> notches, peaks;  // rad/s (5.4)
  // Sentences for the user: biased method, unstable model, intervals to read with care; the
  // code of each in warningCodes (same order; warn() keeps them in step).
  std::vector<std::string> warnings;
  std::vector<FitWarning> warningCodes;
  void warn(FitWarning code, std::string text);
  // The code of warnings[i] (Other for one added without a code).
  FitWarning warningCode(std::size_t i) const;
  bool warned(FitWarning code) const;
  // Sentences beside the numbers of a physical fit whose parameters are physically absurd: an
  // interval wider than its value, an inertia or stiffness orders of magnitude outside the
  // range of robot axes, a resonance the data cannot see, a gear ratio the log never stated.
  // Empty: nothing absurd found.
  std::vector<std::string> plausibility;
  // When parameters are undetermined and the covariance says along what: the combination of
  // the free physical parameters the data fix least (the largest eigenvector of their
  // covariance relative to their values), "J_a +0.92, k_a -0.39"; empty otherwise.
  std::string undeterminedDirection;
  // A physical fit on a log with an arm-side encoder: the deflection it predicts.
  std::optional<DeflectionCheck> deflection;

  bool ok() const { return termination == Termination::Converged || termination == Termination::MaxIterations; }
  // "three-mass (K = 0)", "three-mass (innovations form)", "oe[2 2 1]", "spa".
  std::string modelName() const;
};

// The bounds a physical fit of options searches in, one per parameter of the start model in
// its order: the model's own, with non-negative dampings (d_*; the model allows the seed's
// negative ones, Tables 5.4 and 5.7, and a damping whose start value is negative keeps them)
// and positive inertias and stiffnesses, then
// options.bounds. Throws std::invalid_argument when the options are not a physical fit.
std::vector<ParameterBound> fitBounds(const FitOptions& options);

// The gear ratio a log states (metadata gear_ratio, arm turns per motor turn: "0.0039" or
// "1/256.86"); nullopt when it states none, or (with a sentence in why) when the value is not
// a ratio in (0, 1].
std::optional<double> logGearRatio(const IdData& data, std::string* why = nullptr);

// The start model of a physical fit: options.model.start with options.startValues (r's
// rescaling included), r from the first estimation log's gear_ratio when it states one and no
// start value names r (the log is the one source of r), the fit's bounds and its values moved
// into them. Sentences about
// values moved are appended to notes (may be null). Throws std::invalid_argument as fitBounds,
// or for a start value that is unknown or outside its bounds.
std::shared_ptr<PhysicalModel> fitStartModel(const FitOptions& options, std::vector<std::string>* notes = nullptr);

// Step 1 of the pipeline alone: the options with every repeated experiment counted once and
// each experiment prepared (fit_data.h) as the fit would see it, in result.data, .estimation
// and .validation. ok false with result.status BadData and a sentence when the data cannot be
// used. What an order scan (order_scan.h) runs on, so it sees the fit's own data.
struct PreparedFit {
  bool ok = false;
  FitOptions options;
  FitResult result;
};
PreparedFit prepareFit(const FitOptions& options);

// Runs the pipeline. Data failures (no usable data, a constant input, a method the log cannot
// support, a diverged or failed estimator) end in termination Failed or Diverged with a
// sentence; invalid options throw std::invalid_argument; Abort from progress gives Cancelled.
FitResult fitModel(const FitOptions& options, const ProgressCallback& progress = {});

// The estimate's frequency response at omega (rad/s) with bands at level: a physical model's
// continuous response with the covariance of its free parameters, a black-box model's up to
// its Nyquist frequency, or the non-parametric estimate recomputed on this grid (SPA leaves
// out frequencies where the input has no power).
FrequencyResponse fitResponse(const FitResult& result, const std::vector<double>& omega, double level);

// Frequency response of an estimate at omega (rad/s) with bands at level: a physical model's
// continuous response C (i w - A)^{-1} B + D with the covariance of its free parameters
// (freeIndices into its parameters(); empty: no bands), or a black-box model's (4.8) up to its
// Nyquist frequency. Exactly one of physical and polynomial is given.
FrequencyResponse estimateResponse(const PhysicalModel* physical, const Eigen::MatrixXd& covariance,
                                   const std::vector<int>& freeIndices, const PolynomialModel* polynomial,
                                   const std::vector<double>& omega, double level);

// Notches and peaks of an estimate on a response of it (FitResult::response, or another grid
// as `flexarm bode` draws): FlexArm's one definition (magnitudeExtrema, core/models/analysis.h),
// extrema at least depthDb deep (kNonparametricNotchDepthDb for SPA and ETFE, whose curves
// ripple), refined on the exact response of a physical or black-box estimate.
inline constexpr double kNonparametricNotchDepthDb = 3.0;
NotchesPeaks fitNotchesAndPeaks(const FitResult& result, const FrequencyResponse& response, double depthDb);

// The default frequency grid of a fit: responsePoints from 2 pi / (N T) to pi / T, N the
// estimation samples.
std::vector<double> fitFrequencyGrid(const PreparedData& data, int points);

}  // namespace flexarm
