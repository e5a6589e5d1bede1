#pragma once
// A model's output on prepared data (core/ident/fit_data.h), the one place FlexArm forms what
// a fit % (5.2) is computed on: the simulation or k-step prediction of a physical model (with
// its nonlinear effects) or of a black-box estimate, the deflection r phi_m - phi_a it predicts,
// and the errors the residual tests take. Compare, the residual analysis, the sensitivity
// study, the model list's report sections and the fit's evaluation all call these, so the same
// model on the same samples gives the same number wherever it is shown (FitBasis,
// core/ident/evaluation.h, says what the number is of).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit_data.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"

namespace flexarm {

// What a fit % is of: how the model's output was formed and on which samples. Every fit %
// FlexArm shows (panels, verbs, sessions, reports) is fitPercents (core/ident/evaluation.h) of
// the output modelFit below forms, printed beside fitBasisText. One definition per figure:
//   simulation (horizon 0): the output from the input alone, open loop, no measured output
//     used after the start: the seed's "simulated fit" (5.2) of Table 5.1 and Figure 5.11;
//   k-step prediction (horizon k >= 1): y(t | t - k) from the inputs up to t and the outputs
//     up to t - k; an output-error model (H = 1) predicts exactly what it simulates;
//   one-step prediction through the load observer (observerHz > 0): the predictor the
//     nonlinear fit and discovery minimise on closed-loop logs, which follows the measured
//     motor velocity with a slow PI torque; it is higher than the simulation wherever an
//     unmeasured load torque drifts (the simulation integrates it, the observer cancels it).
// Where the output starts: at the log's first sample (the validation figure: no start-up
// transient inside a range that starts later), or at the range's first sample (the fit's
// estimation figure: what the estimator saw and minimised, each experiment from its start).
enum class FitStart { LogStart, RangeStart };
struct FitBasis {
  int horizon = 0;           // 0: simulation; k >= 1: k-step prediction
  double observerHz = 0.0;   // > 0: through the load observer of that bandwidth
  FitStart start = FitStart::LogStart;
  bool effects = false;      // the model's nonlinear effects were in the simulation
  bool meansRemoved = true;  // the estimation range's means of input and output removed
  double rateHz = 0.0;       // the rate of the samples compared
  std::string data;          // which data, in a few words ("chirp.csv")
  std::string range;         // which samples ("validation 9-17.5 s")
  bool isSimulation() const { return horizon == 0 && !(observerHz > 0.0); }
  bool operator==(const FitBasis& o) const;
  bool operator!=(const FitBasis& o) const { return !(*this == o); }
};
// "simulation (open loop from the input) from the log's first sample, with the model's
// effects, means removed, at 200 Hz, on chirp.csv validation 9-17.5 s".
std::string fitBasisText(const FitBasis& basis);
// "simulation", "3-step prediction", "one-step prediction through the 4 Hz load observer".
std::string fitKindText(const FitBasis& basis);

// Which samples a figure is of, for FitBasis::range: "validation 9-17.5 s" (kind, then the
// times of the range's first and last sample of d).
std::string samplesLabel(const std::string& kind, const PreparedData& d, SampleRange range);

// One fit figure: the number both ways and what it is of.
struct FitFigure {
  FitPercents percent;
  FitBasis basis;
};

// A model as the evaluations take it: a physical model with the nonlinear effects switched on
// for it, or a black-box estimate, and the rate its fit ran at.
struct EvaluatedModel {
  std::string name;
  std::shared_ptr<const PhysicalModel> physical;      // null for a black-box estimate
  std::vector<Effect> effects;                        // physical models only
  std::shared_ptr<const PolynomialModel> polynomial;  // set exactly when physical is null
  // The decimation a physical model's fit ran at (1: the log's rate, as for a hand-made
  // model). A black-box estimate works at its own sample time instead.
  int decimation = 1;
  // The speed of the smooth signs the fit used (NonlinearPlant::setSmoothingSpeed; 0: the
  // plant's default).
  double smoothingSpeed = 0.0;
  // Its fit took the arm as a second output (the deflection predicted from the torque alone:
  // no load observer).
  bool armOutput = false;
  bool nonlinear() const { return physical && !effects.empty(); }
  bool isValid(std::string* why) const;
};

// The decimation that brings data sampled every dataSampleTime seconds to the model's rate:
// a physical model's decimation, T_model / T_data for a black-box estimate; 0 when that is no
// whole number (the model cannot be run on these data).
int decimationFor(const EvaluatedModel& model, double dataSampleTime);
// True when the model's output is the motor velocity (physical models with the default output;
// black-box estimates, identified from the velocity as the seed's Section 5.2), so that a
// logged motor angle is differentiated first.
bool wantsVelocity(const EvaluatedModel& model);

// The data preparation of the model's fit (prepareFitData): decimation by `decimation`
// (decimationFor) with a physical model's torque held as its mean over each new period, the
// motor velocity from a logged angle when the model gives the velocity, the estimation
// range's means removed for a linear model and kept with effects (friction and backlash act
// on the real velocity), as fitModel prepares them.
FitDataOptions modelDataOptions(const EvaluatedModel& model, int decimation,
                                const std::optional<SecondsRange>& estimation,
                                const std::optional<SecondsRange>& validation);

// The load observer a model's own fit predicts through on data d: kClosedLoopObserverHz for a
// model with effects on a closed-loop log (a log with a reference), where the controller
// answers an unmeasured load torque on the arm that an open-loop simulation integrates into a
// drift; 0 (simulation) otherwise and for a fit with the arm as an output. The one rule the
// fit (core/ident/fit.h) and every evaluation's default follow.
double fitObserverHz(const EvaluatedModel& model, const PreparedData& d);

// What a model's output over a range is: the samples, or why there are none.
enum class SignalFailure { None, RateMismatch, Diverged, Failed };
struct ModelSignal {
  Eigen::VectorXd y;  // over the range asked for (range.size() samples); empty: none
  // Why there is none: a black-box estimate of another sample time than the data's, a
  // simulation that blew up (an unstable model), another failure; and that as a clause.
  SignalFailure failure = SignalFailure::None;
  std::string message;
  bool ok() const { return y.size() > 0; }
};

// The model's output over range of d as basis asks: simulation (horizon 0) or k-step
// prediction (horizon k; an output-error model's is its simulation), through the load
// observer (observerHz > 0, a model with effects only), from the log's or the range's first
// sample. An output that leaves the measured output's scale by a factor of 1e6 (an unstable
// model) is reported as diverged, as one that overflows. A linear physical model is simulated
// by its zero-order hold (5.3) from zero
// deviation state, a model with effects by the nonlinear plant's Runge-Kutta predictor from
// rigid-body motion at the first sample's measured speed (core/ident/nonlinear_pem.h), a
// black-box estimate as B/(A F) u from zero state or predicted by predict (evaluation.h).
ModelSignal modelOutput(const EvaluatedModel& model, const PreparedData& d, SampleRange range,
                        const FitBasis& basis);

// The fit % of the model on range of d (fitPercents of the measured output against
// modelOutput), with the sums it comes from (several experiments pool them,
// fitPercentsFromSums) and its basis completed from the model and the data (effects, means,
// rate; an observer asked of a linear model dropped).
struct ModelFit {
  ModelSignal output;
  std::optional<FitFigure> figure;  // nullopt when there is no output
  double squaredErrors = 0.0, squaredDeviations = 0.0;
};
ModelFit modelFit(const EvaluatedModel& model, const PreparedData& d, SampleRange range, FitBasis basis);

// The errors the residual tests take over the whole of d: one-step prediction errors (4.5) of
// a black-box estimate, output errors y - G u of a linear physical model (K = 0), y minus the
// simulation of a model with effects.
ModelSignal residualsOf(const EvaluatedModel& model, const PreparedData& d);

// The deflection r phi_m - phi_a (rad, arm side) the model predicts from the torque alone over
// range of d: the linear part by simulateDeflection (fit.h), a model with effects by the
// nonlinear plant (its deflection as the arm encoder reads it, encoder_skew included), from
// the log's or the range's first sample.
ModelSignal predictedDeflection(const EvaluatedModel& model, const PreparedData& d, SampleRange range,
                                FitStart start);

// The deflection check of a physical model on range of d against the motor and arm-side
// encoders (measuredDeflection, fit.h, with the gear ratio r): both about their own means over
// the range (the encoders' zeros are unrelated), the fit % of the variation, the RMS of the
// error and of the measured deflection. nullopt with why without an arm-side encoder or when
// the prediction diverges.
struct DeflectionFit {
  FitFigure figure;
  Eigen::VectorXd measured, predicted;  // over the range, about their means (rad)
  double rmsError = 0.0, measuredRms = 0.0;
  double gearRatio = 0.0;
};
std::optional<DeflectionFit> deflectionFit(const EvaluatedModel& model, const PreparedData& d, SampleRange range,
                                           FitStart start, double gearRatio, std::string* why);

}  // namespace flexarm
