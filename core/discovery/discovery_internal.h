#pragma once
// What the parts of the discovery method share (core/discovery/*.cpp): the prepared data, a
// model with effects fitted by the discovery predictor, and small numeric helpers. Not API.
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/discovery/discovery.h"
#include "core/ident/levenberg_marquardt.h"
#include "core/ident/nonlinear_pem.h"

namespace flexarm::discovery_detail {

// The data and the predictor every fit of one discovery run shares.
struct Context {
  const DiscoveryOptions* options = nullptr;
  // The estimation log; when it is split, its fitSamples are the fitted ones and heldOut the
  // others (whole blocks), and the log is still simulated whole.
  NonlinearSeries est;
  std::optional<NonlinearSeries> valLog;  // the validation log, if there is one
  std::vector<std::size_t> heldOut;
  std::vector<double> estY, valY;  // measured output of the fitted and the held-out samples
  bool heldOutSplit = false;
  std::string validationData;          // which, in words
  // The series the held-out samples come from, and the picks of a simulation of it (or of
  // the estimation log) at the held-out (fitted) samples.
  const NonlinearSeries& valSeries() const { return valLog ? *valLog : est; }
  std::vector<double> pickVal(const std::vector<double>& full) const;
  std::vector<double> pickEst(const std::vector<double>& full) const;
  int substeps = 4;
  LoadObserver observer;
  std::shared_ptr<const PhysicalModel> nominal;  // the engineer's base, free flags as given
  std::atomic<bool>* cancel = nullptr;
  std::function<void(double, const std::string&)> report;  // thread-safe progress
  bool cancelled() const { return cancel && cancel->load(); }
};

// Bounds of effect coordinates that depend on the data: the widest backlash gap the data can
// show, the current model's highest resonance (an added mass resonates near it).
using EffectBounds = EffectSearchBounds;

// A base model with effects, its free parameters fitted together by the discovery predictor.
struct ModelFit {
  std::shared_ptr<const PhysicalModel> start;  // owns what problem.base points at
  NonlinearProblem problem;
  LeastSquaresSolution sol;
  std::shared_ptr<const PhysicalModel> model;  // fitted base parameters
  std::vector<Effect> effects;                 // fitted effects
  int parameterCount = 0;                      // coordinates plus grid-chosen values
  int gridParameters = 0;
  double loss = 0.0;       // V_N (4.6) on the estimation data
  double inflation = 1.0;  // variance inflation of the correlated residual
  // The simulation of the whole estimation log, of the held-out samples (aligned with
  // Context::valY) and of the whole series they come from.
  std::vector<double> yhatEst, yhatVal, yhatValFull, deflection;
  DiscoveryScore score;
  std::vector<std::vector<EffectParameterEstimate>> estimates;  // per effect (parameters, then derived)
  std::vector<EffectParameterEstimate> magnitudes;              // per effect: its size
  bool ok() const { return model && !yhatEst.empty(); }
};

// data.cpp: the log as the predictor's series (decimated, the angle differentiated as the
// predictor differentiates its own); nullopt with a sentence.
std::optional<NonlinearSeries> makeSeries(const IdData& data, double maxRateHz, std::string* why);
// Prepares the data of ctx (without validation data, blocks of the log are held out).
bool prepareContext(Context& ctx, const IdData& estimation, const IdData* validation, std::string* why);

// candidates.cpp
// Adds the search coordinates of effect `index` of pr (already in pr.effects); returns the
// number of its values chosen on a grid instead (counted as parameters).
int addEffectCoordinates(NonlinearProblem& pr, int index, const EffectBounds& bounds);
// The model with effects fitted from start (phi0 given, or the start's values), scored on the
// estimation and validation data, with the effects' estimates.
ModelFit fitModel(const Context& ctx, std::shared_ptr<const PhysicalModel> start,
                  const std::vector<Effect>& effects, const EffectBounds& bounds, int iterations,
                  int threads, const Eigen::VectorXd* phi0 = nullptr);
// One candidate effect added to the current model: screening fits from a few starts (a grid
// for backlash and ripple, or `warm`, a fit of the same effects from the previous round),
// then the full refit of everything. Fills fit and the candidate's fields.
struct CandidateWork {
  CandidateFit fit;
  ModelFit outcome;
};
void fitCandidate(const Context& ctx, EffectKind kind, const ModelFit& current, const EffectBounds& bounds,
                  double residualPeakRadS, const ModelFit* warm, CandidateWork& w);
// The fit of current + first + second (the pair test), started from both candidates' values.
ModelFit fitPair(const Context& ctx, const CandidateWork& first, const CandidateWork& second,
                 const EffectBounds& bounds);

// disagreement.cpp: the map of a model's residual on the estimation data.
DisagreementMap mapDisagreement(const NonlinearSeries& est, const std::vector<double>& yhat,
                                const std::vector<double>& deflection, const PhysicalModel& model,
                                const std::vector<Effect>& effects, const DiscoveryScore& score,
                                bool hasValidation);
EffectBounds effectBounds(const NonlinearSeries& est, const std::vector<double>& deflection,
                          const PhysicalModel& model, const std::vector<Effect>& effects);

// size.cpp: the torque effect `index` of fit adds against the model's own (RMS over the
// estimation log), and the sentence that says it ("" for an effect that is no torque).
EffectSize effectSize(const Context& ctx, const ModelFit& fit, std::size_t index);
std::string sizeText(const EffectSize& s);

// verdict.cpp: the statistics of every candidate against the current model, the choice among
// several significant ones (pair refits), and the round's verdict and evidence.
void judgeCandidates(const Context& ctx, const ModelFit& current, std::vector<CandidateWork>& work);
// The significant candidates, the one to name first at the front (by what survives refitting
// with another in the model, then by the held-out residual); pairFits receives the pair
// refits (warm starts of the next round), tied the candidates that cannot be told from the
// first.
std::vector<std::size_t> rankSignificant(const Context& ctx, const ModelFit& current, std::vector<CandidateWork>& work,
                                         const EffectBounds& bounds, std::vector<ModelFit>& pairFits,
                                         std::string& decision, std::vector<EffectKind>& tied);
std::string roundEvidence(const Context& ctx, const DiscoveryRound& round, const CandidateWork* winner);

// confirmation.cpp
Confirmation confirmEffect(const Context& ctx, const ModelFit& current, const ModelFit& augmented,
                           EffectKind kind, const std::vector<CandidateWork>& rivals);

// Helpers.
double rms(const std::vector<double>& a, const std::vector<double>& b);
void setFit(DiscoveryScore& s, bool validation, const std::vector<double>& y, const std::vector<double>& yhat);
double correlation(const std::vector<double>& a, const std::vector<double>& b);
double correlationInflation(const Eigen::VectorXd& e);
double conditionalVariance(const LeastSquaresSolution& sol, Eigen::Index j);
// Whether the change from model a's prediction to model b's explains a's error on y: the
// coefficient of y - a regressed on b - a over its standard error (Bartlett-corrected for the
// correlated remainder); 1 when b predicts the change exactly.
double heldOutZ(const std::vector<double>& y, const std::vector<double>& a, const std::vector<double>& b);
double percentile99(const std::vector<double>& a);
bool hasGearSpring(const PhysicalModel& m);
// The covariance of a block of coordinates (lambda times the block of (psi^T psi)^{-1}, formed
// from the part of the block's columns the others do not explain); infinite when singular.
Eigen::MatrixXd blockCovariance(const LeastSquaresSolution& sol, const std::vector<Eigen::Index>& block);
std::string number(double v, int digits = 3);
std::string plusMinus(const EffectParameterEstimate& p, double factor = 1.0);
// The structure the effects give the base (extra_mass adds one mass).
std::string structureWith(const PhysicalModel& base, const std::vector<Effect>& effects);
bool hasEffect(const std::vector<Effect>& effects, EffectKind k);
// Whether effect k can join the current model: not in it, nor held by (or holding) one of its
// effects; a gear effect needs a gear spring, a structural one a structure below four-mass, an
// arm-encoder effect a log with an arm encoder.
bool canJoin(const Context& ctx, const ModelFit& current, EffectKind k);

}  // namespace flexarm::discovery_detail
