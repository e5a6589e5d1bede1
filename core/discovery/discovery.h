#pragma once
// Finding the missing effect: where the simulated physical model and the measured log
// disagree, which of the named effects (core/models/effects.h) explains the disagreement,
// and how much the gap shrinks when that effect is added.
//
// Every model is compared through one nonlinear predictor: the plant (the chapter-3 model,
// (3.13)/(3.21), with any effects) is integrated with Runge-Kutta at the data's own rate from
// the measured torque reference u, and its motor angle is differentiated exactly as the log's
// angle is (central differences, the seed's Section 5.2), so the prediction error
//   eps(t) = phi_m'(t) - phi_m'_hat(t | theta)                                      (4.3)
// is in rad/s. Closed-loop logs carry an unmeasured load torque on the arm (Figure 5.1) that
// the controller answers with u; a slow observer (a PI torque on the motor from the motor
// velocity error, bandwidth of about 1 Hz) keeps the simulation on the measured operating
// point, so that friction and backlash are evaluated where the arm really was; the ripple is
// positioned by the measured motor angle. The parameters minimize V_N = (1/N) sum eps^2 (4.6)
// by Levenberg-Marquardt (4.17)-(4.21) with a finite-difference gradient psi: the nonlinear
// grey-box estimator of core/ident/nonlinear_pem.h, the same one `flexarm fit --effect` runs.
// The augmented model (base plus effect) is what the fit pipeline refines (FitModelSpec).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/ident/residuals.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/signal/id_data.h"

namespace flexarm {

struct DiscoveryOptions {
  std::vector<EffectKind> candidates = seedEffectKinds();  // effects to test
  double observerBandwidthHz = 1.0;  // load observer; 0 gives pure output error (simulation)
  double maxRateHz = 1100.0;  // faster data are decimated by block means of u (same impulse)
  int substeps = 0;           // Runge-Kutta steps per sample; 0 picks h <= 0.25 ms
  int baseIterations = 30;    // Levenberg-Marquardt iterations for the base model
  int candidateIterations = 12;
  double level = 0.99;        // confidence level of parameter intervals and the F-test
  // An effect is named only if it lowers the validation residual RMS by at least this part.
  double minValidationImprovement = 0.10;
  // Two significant candidates whose validation RMS differ by less than this part tie.
  double tieTolerance = 0.02;
  int threads = 2;            // candidates fitted in parallel
  bool isValid(std::string* why) const;
};

// An estimated effect parameter with its standard deviation and interval at `level`.
struct EffectParameterEstimate {
  std::string name, unit;
  double value = 0.0;
  double std = 0.0;
  double lower = 0.0, upper = 0.0;
  bool estimated = true;  // false: held at a value chosen by a grid (e.g. ripple periods n)
};

// Fit % and residual RMS of one model on the estimation and the validation data: fit % as
// the seed's (5.2) and as MATLAB compare's NRMSE fit (fitPercents, core/ident/evaluation.h).
struct DiscoveryScore {
  double fitPercent = 0.0, fitPercentValidation = 0.0;            // (5.2)
  double fitPercentNrmse = 0.0, fitPercentValidationNrmse = 0.0;  // NRMSE
  double rmsEstimation = 0.0, rmsValidation = 0.0;
};

struct CandidateFit {
  EffectKind kind = EffectKind::CoulombFriction;
  Effect effect;                                    // fitted values
  std::vector<EffectParameterEstimate> parameters;  // in effectParameters(kind) order
  std::shared_ptr<const PhysicalModel> model;       // base parameters refitted with the effect
  int parameterCount = 0;  // estimated parameters, base ones included
  double lossEst = 0.0;    // V_N (4.6) on the estimation data, (rad/s)^2
  double aic = 0.0;        // N_eff log V_N + 2 p, N_eff from the residual correlation
  double fStatistic = 0.0, fThreshold = 0.0;  // F-test of the added parameters vs the base
  double rho = 0.0;  // correlation of the base residual with the effect's simulated share
  DiscoveryScore score;
  bool intervalExcludesZero = false;
  bool significant = false;
  std::string reason;  // why (not) significant, one sentence
  Termination termination = Termination::Failed;
};

// Where the base model's error lives: the signals the panel plots against each other.
struct DisagreementMap {
  std::vector<double> time, residual, motorVelocity, gearDeflection, motorAngle;
  std::vector<double> spectrumHz, spectrum;    // residual amplitude spectrum
  std::vector<double> resonancesRadS;          // lightly damped poles of the base model
  ResidualAnalysis tests;                      // whiteness and input cross-correlation
  double rmsLowSpeed = 0.0, rmsHighSpeed = 0.0;  // |phi_m'| below / above its median
  double correlationSignVelocity = 0.0;          // rho(eps, sign phi_m')
  double spectrumPeakRadS = 0.0;                 // largest residual line above 5 rad/s
  std::string summary;                           // a few sentences for the user
};

// Measured and simulated motor velocity of one data set, for overlays.
struct DiscoveryTrace {
  std::vector<double> time, measured, base, augmented;
};

struct DiscoveryResult {
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  double sampleTime = 0.0;  // of the data the fits ran on (after internal decimation)
  std::optional<EffectKind> effect;  // nullopt: "none"
  std::vector<EffectKind> tied;      // the other candidates that tie with effect
  std::string evidence;              // plain words with numbers
  std::shared_ptr<const PhysicalModel> baseModel;  // the base fitted by the same predictor
  int baseParameterCount = 0;
  double baseLoss = 0.0, baseAic = 0.0;
  DiscoveryScore base, augmented;  // augmented = base when no effect is named
  std::vector<CandidateFit> candidates;
  int best = -1;  // index into candidates, -1 for none
  DisagreementMap disagreement;      // of the base model on the estimation data
  DiscoveryTrace estimation, validation;
  bool hasValidation = false;
  // The augmented model for the model list: the winner's refitted base and its effect.
  std::shared_ptr<const PhysicalModel> augmentedModel;
  std::vector<Effect> augmentedEffects;
};

// Runs the whole workflow on an estimation log and (optional, may be null) validation log;
// both need the torque reference (input) and the motor angle channel. `base` is the
// engineer's model (its values are the starting point). Throws std::invalid_argument for
// invalid options or a base model without a gear spring; data problems end as Failed with a
// sentence. Progress is reported per fitted candidate; Abort gives Cancelled.
DiscoveryResult discoverMissingEffect(const PhysicalModel& base, const IdData& estimation,
                                      const IdData* validation,
                                      const DiscoveryOptions& options = {},
                                      const ProgressCallback& progress = {});

// The F distribution's quantile (Wilson-Hilferty through chi-square), for the F-test.
double fQuantile(double probability, int d1, int d2);

}  // namespace flexarm
