#pragma once
// Finding the missing effects: where the simulated physical model and the measured log
// disagree, which of the named effects (core/models/effects.h) explains the disagreement, a
// second method that confirms it, and the loop that adds it, refits and looks again until
// nothing is missing.
//
// Every model is compared through one nonlinear predictor, the one `flexarm fit --effect`
// fits with (core/ident/nonlinear_pem.h): the plant (the chapter-3 model, (3.13)/(3.21), with
// any effects) is integrated with Runge-Kutta at the data's own rate from the measured torque
// reference u, and its motor angle is differentiated exactly as the log's angle is (central
// differences, the seed's Section 5.2), so the prediction error
//   eps(t) = phi_m'(t) - phi_m'_hat(t | theta)                                      (4.3)
// is in rad/s. Closed-loop logs carry an unmeasured load torque on the arm (Figure 5.1) that
// the controller answers with u; a slow observer (a PI torque on the motor from the motor
// velocity error, bandwidth of about 1 Hz) keeps the simulation on the measured operating
// point. The parameters minimize V_N = (1/N) sum eps^2 (4.6) by Levenberg-Marquardt
// (4.17)-(4.21).
//
// The method's parts, one file each:
//   data.cpp           the data sets (a held-out end of the log when there is no validation)
//   disagreement.cpp   where the current model's error lives (locateDisagreement)
//   candidates.cpp     one candidate effect fitted together with the current model
//   verdict.cpp        significance, the choice among several, the evidence in words
//   confirmation.cpp   the second method: the held-out data and a test specific to the effect
//   loop.cpp           find, add, refit everything, find again (discoverMissingEffect)
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/ident/nonlinear_pem.h"
#include "core/ident/residuals.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"

namespace flexarm {

// The effects discovery looks for by default: every effect of the registry that is a
// candidate (core/models/effect_registry.h); those that need an arm encoder are tested only
// on logs that have one.
const std::vector<EffectKind>& discoveryCandidateKinds();

struct DiscoveryOptions {
  std::vector<EffectKind> candidates = discoveryCandidateKinds();  // effects to test
  // Effects the base model already has (their values the start): refitted with it, and not
  // tested again. extra_mass among them enlarges the structure.
  std::vector<Effect> startEffects;
  // Effects to find before stopping: 1 names the one missing effect; more runs the loop
  // (find, add, refit the base and every effect so far, find again) until "none".
  int maxEffects = 1;
  // Load observer, as `flexarm fit --effect` on closed-loop logs; 0: pure output error.
  double observerBandwidthHz = kClosedLoopObserverHz;
  double maxRateHz = 1100.0;  // faster data are decimated by block means of u (same impulse)
  int substeps = 0;           // Runge-Kutta steps per sample; 0 picks h <= 0.25 ms
  int baseIterations = 30;    // Levenberg-Marquardt iterations for the base model
  int candidateIterations = 12;
  double level = 0.99;        // confidence level of parameter intervals and of every test
  // An effect is named only if it lowers the held-out residual RMS by at least this part
  // (and the drop is significant at `level`).
  // Below it, a significant effect is too small to matter (a twentieth of a percent of beta
  // beside a backlash whose gap is 8 % off, a ripple where the motor barely turns).
  double minValidationImprovement = 0.04;
  // Without validation data, this part of the log's end is held out for the confirmation.
  double heldOutFraction = 0.3;
  // Two significant candidates whose held-out RMS differ by less than this part tie.
  double tieTolerance = 0.02;
  // An effect is named only when the torque it adds (RMS over the estimation log, motor side)
  // is at least this part of the model's own friction and gear spring torques there: an
  // effect of no size that the statistics still find (Coulomb friction of 0.003 N m beside a
  // backlash) is reported as tried, not as found.
  double minTorqueShare = 0.02;
  int threads = 2;            // candidates fitted in parallel
  bool isValid(std::string* why) const;
};

// An effect's size against the model it joins: the torque it adds, RMS over the estimation
// log on the motor side (NaN for an effect that is no torque: a structure, an encoder's lag),
// beside the base model's own friction torque f_m phi_m' and gear spring torque (motor side).
struct EffectSize {
  double torqueRms = NAN;
  double frictionRms = 0.0, springRms = 0.0;
  double share() const { return torqueRms / (frictionRms + springRms); }  // NaN without a torque
  bool measured() const { return std::isfinite(torqueRms); }
};

// Fit % and residual RMS of one model on the estimation and the validation data: fit % as
// the seed's (5.2) and as MATLAB compare's NRMSE fit (fitPercents, core/ident/evaluation.h).
struct DiscoveryScore {
  double fitPercent = 0.0, fitPercentValidation = 0.0;            // (5.2)
  double fitPercentNrmse = 0.0, fitPercentValidationNrmse = 0.0;  // NRMSE
  double rmsEstimation = 0.0, rmsValidation = 0.0;
};

// The second method behind a verdict, on data the fit did not see: the held-out residual
// (the validation log, else the held-out end of the log) before and after the effect, and a
// test specific to the effect (the residual against the sign of the velocity for friction,
// against the torque's rate of change for a delay, against sin(n phi_m) for ripple, against
// the gear's dead zone for backlash, against the cubic gear torque for a stiffening spring,
// against a small added mass's resonance for a mass), with its look-alikes and the base
// parameters' sensitivities as rival regressors.
struct Confirmation {
  bool ran = false;
  bool confirmed = false;
  std::string heldOutData;  // which data, in words
  double rmsBefore = 0.0, rmsAfter = 0.0;
  double heldOutZ = 0.0;    // the held-out residual against the change the effect predicts
  bool heldOutPasses = false;
  std::string test;         // what the specific test regresses on, in words
  double value = 0.0, std = 0.0, z = 0.0;  // the effect's size from the specific test
  double fitted = 0.0;      // the same parameter as the fit estimated it
  std::string unit;
  std::vector<std::string> rivals;  // the look-alikes regressed beside it
  bool specificPasses = false;
  std::string text;         // "confirmed: ..." or "not confirmed: ..." with the numbers
};

struct CandidateFit {
  EffectKind kind = EffectKind::CoulombFriction;
  Effect effect;                                    // fitted values
  // In effectParameters(effect) order, then the quantities derived from them (a ripple
  // harmonic's amplitude and phase).
  std::vector<EffectParameterEstimate> parameters;
  EffectParameterEstimate magnitude;  // the effect's size, whose interval must exclude 0
  EffectSize size;
  // Every effect of the fit (the current model's, then this one) and their estimates.
  std::vector<Effect> effects;
  std::vector<std::vector<EffectParameterEstimate>> effectEstimates;
  std::shared_ptr<const PhysicalModel> model;       // base parameters refitted with the effect
  int parameterCount = 0;  // estimated parameters, base ones included
  double lossEst = 0.0;    // V_N (4.6) on the estimation data, (rad/s)^2
  double aic = 0.0;        // N_eff log V_N + 2 p, N_eff from the residual correlation
  double fStatistic = 0.0, fThreshold = 0.0;  // F-test of the added parameters vs the base
  double heldOutZ = 0.0;   // the held-out residual against the change the effect predicts
  double rho = 0.0;  // correlation of the base residual with the effect's simulated share
  // Refitted together with the other significant candidates: the smallest F-test of this
  // effect's parameters with another one in the model (0 when not tested).
  double survivalF = 0.0;
  DiscoveryScore score;
  Confirmation confirmation;  // of a significant candidate the round tried to name
  bool intervalExcludesZero = false;
  bool matters = true;  // its torque share reaches minTorqueShare (or it is no torque)
  bool significant = false;
  std::string reason;  // why (not) significant, one sentence
  Termination termination = Termination::Failed;
};

// Where a model's error lives: the signals the panel plots against each other.
struct DisagreementMap {
  std::vector<double> time, residual, motorVelocity, gearDeflection, motorAngle;
  std::vector<double> spectrumHz, spectrum;    // residual amplitude spectrum
  std::vector<double> resonancesRadS;          // lightly damped poles of the model
  ResidualAnalysis tests;                      // whiteness and input cross-correlation
  double rms = 0.0, fitPercent = 0.0;            // of the whole residual, fit % (5.2)
  double rmsLowSpeed = 0.0, rmsHighSpeed = 0.0;  // |phi_m'| below / above its median
  double correlationSignVelocity = 0.0;          // rho(eps, sign phi_m')
  double spectrumPeakRadS = 0.0;                 // largest residual line above 5 rad/s
  std::string summary;                           // a few sentences for the user
};

// Measured and simulated motor velocity of one data set, for overlays.
struct DiscoveryTrace {
  std::vector<double> time, measured, base, augmented;
};

// One pass of the loop: the current model (the base with the effects found so far, all
// fitted together), where it disagrees, every candidate refitted with it, the verdict and its
// confirmation.
struct DiscoveryRound {
  std::vector<Effect> effects;                     // the current model's effects
  std::shared_ptr<const PhysicalModel> model;      // its base parameters
  int parameterCount = 0;
  double loss = 0.0, aic = 0.0;
  DiscoveryScore score;                            // of the current model
  std::vector<CandidateFit> candidates;
  int best = -1;                                   // index into candidates, -1 for none
  std::optional<EffectKind> effect;                // nullopt: "none"
  std::vector<EffectKind> tied;
  std::string decision;  // how the winner was chosen among several significant ones
  std::string evidence;  // plain words with numbers
  Confirmation confirmation;
  DisagreementMap disagreement;                    // of the current model, estimation data
  DiscoveryTrace estimation, validation;           // base = current, augmented = with effect
  DiscoveryScore augmented;                        // = score when none is named
};

// An effect the loop found, in the order found: one rung of the ladder.
struct FoundEffect {
  EffectKind kind = EffectKind::CoulombFriction;
  Effect effect;                                    // its values in the final model
  std::vector<EffectParameterEstimate> parameters;  // in the final model (everything refitted)
  EffectParameterEstimate magnitude;                // its size there
  EffectSize size;                                  // the torque it adds where it was named
  DiscoveryScore before, after;                     // the model without and with it
  std::string evidence;
  Confirmation confirmation;
};

struct DiscoveryResult {
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  double sampleTime = 0.0;  // of the data the fits ran on (after internal decimation)
  bool hasValidation = false;  // held-out data exist (a validation log or the log's end)
  bool heldOutSplit = false;   // the held-out data are the end of the estimation log
  // What every fit % of the result is of, in words: fitPercents (core/ident/evaluation.h) of
  // the motor velocity as discovery's predictor forms it (through the load observer, with
  // the model's effects, means kept, at the fitting rate).
  std::string fitBasis;
  std::string validationData;  // which, in words
  std::vector<DiscoveryRound> rounds;
  // Every effect named, in order: each significant, its size's interval excluding 0, its
  // torque mattering against the model, and confirmed on held-out data. The list ends with
  // the last one that holds.
  std::vector<FoundEffect> found;
  // What was tried and rejected: the significant candidates of each round that were not
  // named (no size, not confirmed, beaten by another), with the reason.
  struct Rejected {
    int round = 0;
    EffectKind kind = EffectKind::CoulombFriction;
    Effect effect;
    EffectParameterEstimate magnitude;
    EffectSize size;
    std::string reason;
  };
  std::vector<Rejected> alsoTried;
  std::string stopReason;          // why the loop ended
  // The first round, as one search gives it: the verdict, the base (with the start effects)
  // and the candidates.
  std::optional<EffectKind> effect;  // nullopt: "none"
  std::vector<EffectKind> tied;      // the other candidates that tie with effect
  std::string evidence;              // plain words with numbers
  std::shared_ptr<const PhysicalModel> baseModel;  // the base fitted by the same predictor
  int baseParameterCount = 0;
  double baseLoss = 0.0, baseAic = 0.0;
  std::vector<CandidateFit> candidates;
  int best = -1;  // index into candidates, -1 for none
  DisagreementMap disagreement;      // of the base model on the estimation data
  // The base and the final model (every effect found): scores and traces.
  DiscoveryScore base, augmented;
  DiscoveryTrace estimation, validation;
  // The final model for the model list: its base parameters and every effect, start effects
  // included (an extra mass stays an effect here; mergedModel() folds it into the structure).
  std::shared_ptr<const PhysicalModel> augmentedModel;
  std::vector<Effect> augmentedEffects;
};

// Runs the workflow on an estimation log and (optional, may be null) validation log; both
// need the torque reference (input) and the motor angle channel (or a motor velocity).
// `base` is the engineer's model (its values are the starting point). Throws
// std::invalid_argument for invalid options or a base model without a gear spring; data
// problems end as Failed with a sentence. Progress is reported per fitted candidate; Abort
// gives Cancelled, keeping the rounds completed before it.
DiscoveryResult discoverMissingEffect(const PhysicalModel& base, const IdData& estimation,
                                      const IdData* validation,
                                      const DiscoveryOptions& options = {},
                                      const ProgressCallback& progress = {});

// Where a given model (with its effects, not refitted) disagrees with a log, through the
// discovery predictor: the residual over time, against speed and deflection, in frequency.
// Data problems end in an empty map whose summary says why.
DisagreementMap locateDisagreement(const PhysicalModel& model, const std::vector<Effect>& effects,
                                   const IdData& data, const DiscoveryOptions& options = {});

// The model with an extra_mass among effects folded into its structure (addMass), and the
// other effects: what `flexarm fit --effect` and the model list take.
std::pair<std::unique_ptr<PhysicalModel>, std::vector<Effect>> mergedModel(
    const PhysicalModel& model, const std::vector<Effect>& effects);

// The F distribution's quantile (Wilson-Hilferty through chi-square), for the F-test.
double fQuantile(double probability, int d1, int d2);

}  // namespace flexarm
