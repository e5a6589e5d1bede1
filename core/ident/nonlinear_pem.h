#pragma once
// Nonlinear grey-box prediction-error estimation: a physical model of chapter 3 ((3.13),
// (3.21), (3.22)) with named effects switched on (core/models/effects.h), simulated by the
// nonlinear plant's Runge-Kutta integrator (core/models/nonlinear_plant.h) from the measured
// torque reference, and its free parameters (the model's and the effects') chosen to minimize
// V_N = (1/N) sum eps^2 (4.6) of eps(t) = y(t) - yhat(t | theta), the output error of (5.7)
// (or, with a load observer, a predictor that follows a slow disturbance), by
// Levenberg-Marquardt (4.17)-(4.21). The gradient psi comes from finite differences of the
// simulation, its columns computed in parallel. The one implementation for the fit pipeline
// (core/ident/fit.h: `flexarm fit --effect`, the Fit panel, the session part "fits") and for
// the discovery workflow (core/discovery), which builds its own problems from these parts.
#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/fit_data.h"
#include "core/ident/levenberg_marquardt.h"
#include "core/ident/pem.h"
#include "core/models/effects.h"
#include "core/models/nonlinear_plant.h"
#include "core/models/physical_models.h"

namespace flexarm {

// What the predictor's output is: the plant's motor velocity state, its motor angle, or its
// motor angle differentiated by central differences exactly as a logged angle is (Section 5.2).
enum class PredictedOutput { MotorVelocity, MotorAngle, DifferentiatedAngle };

// One experiment at the rate the fit runs at: the torque reference u held over each sample,
// the measured output y, and (optional) the measured motor angle.
struct NonlinearSeries {
  std::vector<double> u, y;
  // The measured motor angle (may be empty). With resetAngle the predictor starts each
  // sample's integration from it (it positions the torque ripple A sin(n phi_m)); else only
  // the first sample's angle is used.
  std::vector<double> phi;
  bool resetAngle = false;
  double Ts = 0.0;
  double startTime = 0.0;
  // The predictor starts in rigid-body motion at this motor speed (rad/s), springs relaxed.
  double initialSpeed = 0.0;
  // The torque each Runge-Kutta stage sees: held over each sample (changing at the sample
  // instants, as simulateTorque and the controller hold it), or averaged over one step around
  // the stage point, which moves smoothly with a delay (a held value jumps only when a sample
  // edge crosses a stage point, giving a zero gradient). An input delay always averages.
  bool averageTorque = false;
  // The arm as a second output: the measured deflection r phi_m - phi_a (motor and arm-side
  // encoders; empty: the motor output alone) and the weight of its errors against the first
  // output's (the ratio of their noise levels). Both are compared about their own means over
  // the experiment (the two encoders' zeros are unrelated); the arm's prediction is the plant's
  // deflection as the arm encoder reads it (encoder_skew).
  std::vector<double> deflection;
  double deflectionWeight = 1.0;
  // The output, then (with a deflection) the weighted deflection about its mean: what the
  // predictor's stacked output is compared with.
  std::vector<double> targets() const;
  // The samples whose errors enter the loss, ascending (empty: every sample): a log split
  // into fitted and held-out samples is still simulated whole.
  std::vector<std::size_t> fitSamples;
};

// A slow observer of an unmeasured arm-side load: a PI torque on the motor (in units of u)
// from the motor velocity error, bandwidth wo rad/s, gain in torque reference per unit of
// motor acceleration error. wo = 0: pure output error (simulation, (5.7)).
struct LoadObserver {
  double wo = 0.0;
  double gain = 0.0;
};

// The bandwidth of the load observer on closed-loop logs (a log with a reference channel):
// the one predictor `flexarm fit --effect` and discovery (core/discovery) both fit with. The
// load torque of a closed-loop log (Figure 5.1) drifts faster than a 1 Hz observer follows,
// and the residual it leaves biases the effects' values (Coulomb friction 0.02 +- 0.007 N m
// on a log whose truth is 0.05, where 4 Hz gives 0.041 +- 0.004).
constexpr double kClosedLoopObserverHz = 4.0;

// The observer of a model: bandwidth in Hz, its gain the axis's inertia seen from the motor
// over the torque constant (0 Hz: none, pure output error).
LoadObserver loadObserver(const PhysicalModel& model, double bandwidthHz);

// The series of the samples in range of prepared data (core/ident/fit_data.h): the torque
// held over each sample (averaged over each Runge-Kutta step only with a delay), the output, the measured motor angle when the
// data hold one (each step starts from it, so the ripple sees the real angle) and the first
// sample's speed. angleOutput: the output is the angle itself.
NonlinearSeries nonlinearSeries(const PreparedData& data, SampleRange range, bool angleOutput);

// The predicted output of a plant for one experiment; false when the simulation blows up.
// deflection, when given, receives the gear deflection at every sample; armDeflection the
// deflection r phi_m - phi_a as the arm encoder reads it (NonlinearPlant::armDeflection plus
// encoder_skew's T_o times the arm's speed).
// visit, when given, sees the plant's state at every sample with the torque reference asked
// for there and the one applied (after the input delay and with the observer's correction).
using PredictorVisitor =
    std::function<void(std::size_t k, const NonlinearPlant::State& x, double torqueNow, double torqueApplied)>;
bool predictOutput(const NonlinearPlant& plant, const NonlinearSeries& s, int substeps,
                   const LoadObserver& observer, PredictedOutput output, std::vector<double>& yhat,
                   std::vector<double>* deflection = nullptr, std::vector<double>* armDeflection = nullptr,
                   const PredictorVisitor* visit = nullptr);

// Runge-Kutta steps per sample for a step of at most 0.25 ms (and at least 2).
int defaultSubsteps(double sampleTime);

// How one search coordinate phi maps to a physical value.
enum class CoordinateMap { Log, Scaled, NonNegative, Fraction };
struct NonlinearCoordinate {
  bool base = true;  // a model parameter (index into parameters()) or an effect value
  int effect = 0;    // which effect (index into the problem's effects)
  int index = 0;     // parameter index in the model, or value index in the effect
  CoordinateMap map = CoordinateMap::Log;
  double scale = 1.0;
  double minPhi = -300.0, maxPhi = 300.0;  // bounds of logarithmic coordinates
  // A value the response moves with in small jumps at the integration grid (a dead zone, a
  // delay): its finite-difference step is about 1 % of its size, where a tiny step would see
  // a zero or a spike.
  bool rough = false;
  double toValue(double phi) const;
  double toPhi(double value) const;
  void project(double& phi) const;
  double step(double phi) const;   // finite-difference step
  double slope(double phi) const;  // d value / d phi, to carry covariances into physical units
};

// A model structure plus effects, parameterized by coordinates, over one or more experiments.
struct NonlinearProblem {
  const PhysicalModel* base = nullptr;
  std::vector<Effect> effects;  // values not in the coordinates keep these
  std::vector<NonlinearCoordinate> coords;
  std::vector<const NonlinearSeries*> series;  // the experiments the loss sums over
  int substeps = 4;
  LoadObserver observer;
  PredictedOutput output = PredictedOutput::DifferentiatedAngle;
  int threads = 1;  // gradient columns computed in parallel
  const std::atomic<bool>* cancel = nullptr;
  double smoothingSpeed = 0.0;  // NonlinearPlant::setSmoothingSpeed; 0: the default

  // Model and effects for a coordinate vector; throws std::invalid_argument when the values
  // leave the model's bounds.
  std::pair<std::unique_ptr<PhysicalModel>, std::vector<Effect>> build(const Eigen::VectorXd& phi) const;
  // The predicted output of one experiment (with a deflection, the weighted deflection about
  // its mean appended); false when the values are refused or it blows up.
  bool simulate(const Eigen::VectorXd& phi, const NonlinearSeries& s, std::vector<double>& yhat,
                std::vector<double>* deflection = nullptr) const;
  // Stacked prediction errors of every experiment and, when asked, psi = -d eps / d phi.
  bool evaluate(const Eigen::VectorXd& phi, Eigen::VectorXd& eps, Eigen::MatrixXd* psi) const;
  // Levenberg-Marquardt from phi0.
  LeastSquaresSolution solve(const Eigen::VectorXd& phi0, int iterations, double relativeTolerance = 1e-7,
                             const ProgressCallback& progress = {}) const;
  // The coordinates of the base model's values and the given effects' values.
  Eigen::VectorXd coordinatesOf(const std::vector<Effect>& effects) const;
};

// Coordinates of the free parameters of m (logarithmic for positive ones, else scaled).
std::vector<NonlinearCoordinate> baseCoordinates(const PhysicalModel& m);

// An effect in a fit: its (start) values and which of them are estimated.
struct FitEffect {
  Effect effect;
  // Per value of the effect (effectParameters(effect) order): estimated or held.
  std::vector<bool> free{true, false};
  // coulomb_friction: the fit sets v_s from the data's speed (1 % of the RMS motor speed,
  // whatever its units) instead of keeping the value given; false when v_s was given.
  bool scaleSmoothing = true;
  // The effect at its defaults, its values free as the registry says (EffectParameterInfo::
  // freeInFit: the sizes, not v_s of the Coulomb friction nor n of the ripple, a smoothing
  // speed and an integer the data hardly inform).
  static FitEffect defaults(EffectKind k);
  // The same for an effect's own values (its size: a ripple of several harmonics).
  static FitEffect of(const Effect& e);
  bool isFree(std::size_t k) const { return k < free.size() && free[k]; }
};

struct NonlinearPemOptions {
  int maxIterations = 100;
  double relativeTolerance = 1e-9;
  double level = 0.99;  // of the reported intervals
  int substeps = 0;     // Runge-Kutta steps per sample; 0: defaultSubsteps
  int threads = 2;      // gradient columns computed in parallel
  // MotorVelocity or DifferentiatedAngle for a velocity output (the latter where the series
  // holds the measured angle: the predicted angle through the same central differences).
  PredictedOutput output = PredictedOutput::MotorVelocity;
  // The motor speed of the smooth signs of asymmetric_coulomb and arm_friction
  // (NonlinearPlant::setSmoothingSpeed); 0: the default 0.1 rad/s.
  double smoothingSpeed = 0.0;
  // Load observer (loadObserver) for closed-loop data: kClosedLoopObserverHz; 0: output error.
  double observerBandwidthHz = 0.0;
  bool isValid(std::string* why) const;
};

struct NonlinearPemResult {
  EstimateSummary summary;
  std::unique_ptr<PhysicalModel> model;  // the estimated values
  std::vector<Effect> effects;           // the estimated values
  // Every model parameter, then every effect value (named as effectParameters() names them).
  std::vector<PemParameter> parameters;
  // Covariance of the free parameters (physical units): the model's (in freeIndices order)
  // then the effects' (in effectFree order), lambda (psi^T psi)^{-1} (4.37).
  Eigen::MatrixXd covariance;
  std::vector<int> freeIndices;                  // into model->parameters()
  std::vector<std::pair<int, int>> effectFree;   // (effect, value index) of free effect values
};

// Estimates the free parameters of start and effects from the experiments (each simulated
// from its own start, the loss summed over them). Throws std::invalid_argument on misuse (no
// experiment, an invalid or repeated effect, a gear effect on a model without a gear spring,
// no free parameter, a structural effect); data failures end as Failed with a sentence.
NonlinearPemResult nonlinearPem(const PhysicalModel& start, const std::vector<FitEffect>& effects,
                                const std::vector<NonlinearSeries>& experiments,
                                const NonlinearPemOptions& options = {}, const ProgressCallback& progress = {});

// The model with its effects simulated on one experiment as nonlinearPem predicts it; empty
// when the simulation blows up.
Eigen::VectorXd simulateNonlinear(const PhysicalModel& model, const std::vector<Effect>& effects,
                                  const NonlinearSeries& series, const NonlinearPemOptions& options = {});

}  // namespace flexarm
