// Step 5 of the fit pipeline: fit % (5.2) on the estimation and validation experiments,
// residual tests, the frequency response with its band, notches and peaks (5.4), and the
// sentences the user reads beside the numbers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include "core/ident/evaluation.h"
#include "core/ident/fit_internal.h"

namespace flexarm::fit_detail {
namespace {

// Measured by bench/bench_fit_closed_loop.cpp (see intervalCaveats): Auto's two-stage fit of
// 40 two-mass and 40 three-mass logs decimated by 10 (175 of 400 intervals held the truth;
// J_m -6 % and -4 % off on average), and the direct fit of 6 two-mass logs at 2 kHz (8 of 30).
const char* const kDecimatedCoverage = "175 of 400";
const char* const kDecimatedBias = "4-6 % low";
const char* const kDirectCoverage = "8 of 30";

// The estimate's output over range of d, from the range's first sample, as every evaluation
// forms it (modelOutput, model_output.h): its predictor, the simulation, or for a model with
// effects on a closed-loop log the one-step prediction through the load observer
// (fitObserverHz). NaN where the simulation blows up.
Eigen::VectorXd simulated(const FitOptions& o, const FitResult& r, const PreparedData& d, SampleRange range) {
  const EvaluatedModel m = evaluatedModel(o, r);
  FitBasis basis;
  basis.start = FitStart::RangeStart;
  basis.observerHz = fitObserverHz(m, d);
  const ModelSignal y = modelOutput(m, d, range, basis);
  return y.ok() ? y.y : Eigen::VectorXd::Constant(static_cast<Eigen::Index>(range.size()), NAN);
}

// What an experiment's fit % is of: the estimate's output from `start` over range of d.
FitBasis basisOf(const FitOptions& o, const FitResult& r, const PreparedData& d, SampleRange range, FitStart start,
                 const char* kind) {
  const EvaluatedModel m = evaluatedModel(o, r);
  FitBasis b;
  b.start = start;
  b.observerHz = fitObserverHz(m, d);
  b.effects = m.nonlinear();
  b.meansRemoved = d.inputMean != 0.0 || d.outputMean != 0.0;
  b.rateHz = 1.0 / d.sampleTime;
  b.range = samplesLabel(kind, d, range);
  return b;
}

// Prediction errors for the residual tests: output errors y - G u of a physical model (one-step
// errors of its innovations form when K is estimated; with effects, of the nonlinear
// simulation), one-step errors (4.5) of a black-box one.
Eigen::VectorXd residualsOf(const FitOptions& o, const FitResult& r, const PreparedData& d) {
  if (r.physical && o.model.nonlinear())
    return d.y - simulated(o, r, d, SampleRange{0, static_cast<std::size_t>(d.u.size())});
  return r.physical ? predictionErrors(*r.physical, r.K, d.u, d.y, d.sampleTime)
                    : predictionErrors(*r.polynomial, d.u, d.y);
}

// The rate of the controller the log was recorded with, when known: the one the fit used,
// else the log's metadata; 0 when unknown.
double controllerRateHz(const FitOptions& o, const FitResult& r) {
  if (r.controller) return r.controller->rateHz;
  if (o.controller) return o.controller->rateHz;
  const auto meta = controllerFromMetadata(*o.estimation.front().data, nullptr);
  return meta ? meta->rateHz : 0.0;
}

// A rate as a person writes it: "2000", "1e+300" (never a wrapped integer).
std::string rateText(double hz) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", hz);
  return buf;
}

// Sentences beside the 99 % intervals of a physical fit where bench/bench_fit_closed_loop.cpp
// measured them to promise too much (simulated two- and three-mass logs at the sample logs'
// noise, 40 logs per case).
void intervalCaveats(const FitOptions& o, FitResult& r) {
  const PreparedData& d = r.data;
  const double controllerHz = controllerRateHz(o, r);
  const bool slower = controllerHz > 0.0 && controllerHz * d.sampleTime > 1.0 + 1e-6;
  if (d.decimation > 1 || slower) {
    char buf[600];
    std::snprintf(buf, sizeof buf,
                  "the data are sampled at %.4g Hz%s: the model holds the torque over each %.3g ms sample "
                  "(zero-order hold (5.3)) where the controller changed it every %.3g ms, and the 99 %% "
                  "intervals do not account for that approximation: on simulated two- and three-mass logs "
                  "decimated by 10 only %s such intervals held the truth (J_m %s); fit the log at its own "
                  "rate, where every interval of the indirect fit held",
                  1.0 / d.sampleTime,
                  slower ? (", below the " + rateText(controllerHz) + " Hz of the log's controller").c_str()
                         : " after decimation",
                  1e3 * d.sampleTime, controllerHz > 0.0 ? 1e3 / controllerHz : 1e3 * d.sampleTime / d.decimation,
                  kDecimatedCoverage, kDecimatedBias);
    r.warn(FitWarning::ZeroOrderHold, buf);
  }
}

}  // namespace

}  // namespace flexarm::fit_detail

namespace flexarm {

namespace fit_detail {

EvaluatedModel evaluatedModel(const FitOptions& o, const FitResult& r) {
  EvaluatedModel m;
  m.name = r.modelName();
  m.physical = r.physical;
  if (r.physical) m.effects = r.effects;
  m.polynomial = r.physical ? nullptr : r.polynomial;
  m.decimation = std::max(1, r.data.decimation);
  m.smoothingSpeed = r.smoothingSpeed;
  m.armOutput = o.model.armOutput;
  return m;
}

}  // namespace fit_detail

NotchesPeaks fitNotchesAndPeaks(const FitResult& r, const FrequencyResponse& response, double depthDb) {
  // FlexArm's one definition (core/models/analysis.h): extrema of |G(i w)|, refined on the
  // estimate's exact response, so a physical estimate gives what `flexarm model` gives.
  std::function<double(double)> exact;
  if (r.physical) {
    const StateSpace sys = r.physical->stateSpace();
    exact = [sys](double w) { return std::abs(frequencyResponse(sys, std::vector<double>{w}).front()); };
  } else if (r.polynomial) {
    const std::shared_ptr<const PolynomialModel> m = r.polynomial;
    exact = [m](double w) { return frequencyResponse(*m, std::vector<double>{w}).magnitude.front(); };
  }
  const bool nonparametric = !r.physical && !r.polynomial;
  return notchesAndPeaks(response, nonparametric ? kNonparametricNotchDepthDb : depthDb, exact);
}

}  // namespace flexarm

namespace flexarm::fit_detail {

void evaluate(const FitOptions& o, FitResult& r) {
  const bool parametric = r.physical || r.polynomial;
  const PreparedData& d = r.data;
  bool finite = true;
  if (parametric) {
    // Each estimation experiment simulated from its range's first sample, as the estimator
    // saw it; the whole fit % pools the errors and each experiment's own deviations.
    double errors = 0.0, deviations = 0.0;
    for (auto& e : r.estimation) {
      const Eigen::VectorXd yEst = e.data.estimationOutput();
      const Eigen::VectorXd ySim = simulated(o, r, e.data, e.data.estimation);
      const FitPercents fe = fitPercents(yEst, ySim);
      const SampleRange whole{0, static_cast<std::size_t>(e.data.u.size())};
      e.simulated = simulated(o, r, e.data, whole);  // from the log's first sample
      e.basis = basisOf(o, r, e.data, e.data.estimation, FitStart::RangeStart, "estimation");
      if (std::isfinite(fe.seed52)) {
        e.fitPercent = fe.seed52;
        e.fitPercentNrmse = fe.nrmse;
      } else {
        finite = false;
      }
      errors += (yEst - ySim).squaredNorm();
      deviations += (yEst.array() - yEst.mean()).square().sum();
    }
    r.simulated = r.estimation.front().simulated;
    const FitPercents fe = fitPercentsFromSums(errors, deviations);
    finite = finite && std::isfinite(fe.seed52);
    if (finite) {
      r.fitEstimation = fe.seed52;
      r.fitEstimationNrmse = fe.nrmse;
    }
    for (auto& v : r.validation) {
      v.simulated = simulated(o, r, v.data, SampleRange{0, static_cast<std::size_t>(v.data.u.size())});
      v.basis = basisOf(o, r, v.data, v.data.validation, FitStart::LogStart, "validation");
      const FitPercents fv = fitPercents(v.data.y, v.simulated, static_cast<Eigen::Index>(v.data.validation.begin),
                                         static_cast<Eigen::Index>(v.data.validation.end));
      if (std::isfinite(fv.seed52)) {
        v.fitPercent = fv.seed52;
        v.fitPercentNrmse = fv.nrmse;
      } else {
        finite = false;
      }
    }
    if (!finite) {
      r.fitEstimation.reset();
      r.fitEstimationNrmse.reset();
      for (auto* list : {&r.estimation, &r.validation})
        for (auto& v : *list) {
          v.fitPercent.reset();
          v.fitPercentNrmse.reset();
        }
      r.warn(FitWarning::Unstable, "the model's G is unstable, so its simulated output diverges and the fit % is "
                           "undefined; it can still predict one step ahead");
    }
    // Residual tests on the first validation experiment, else on the estimation range.
    const PreparedData& on = r.validation.empty() ? d : r.validation.front().data;
    const SampleRange range = r.validation.empty() ? d.estimation : on.validation;
    ResidualOptions ro;
    ro.level = 0.99;
    const auto b = static_cast<Eigen::Index>(range.begin), n = static_cast<Eigen::Index>(range.size());
    if (n >= 2 * ro.maxLag + 10) {
      const Eigen::VectorXd eps = residualsOf(o, r, on);
      if (eps.segment(b, n).allFinite()) {
        r.residuals = residualAnalysis(eps.segment(b, n), on.u.segment(b, n), ro);
        r.residualsOnValidation = !r.validation.empty();
      }
    }
  }
  r.response = fitResponse(r, fitFrequencyGrid(d, o.responsePoints), o.level);
  const bool nonparametric = !parametric;
  r.notches.clear();
  r.peaks.clear();
  if (!r.response.omega.empty()) {
    const auto np = fitNotchesAndPeaks(r, r.response, o.notchDepthDb);
    r.notches = np.notches;
    r.peaks = np.peaks;
  }
  if (nonparametric && !r.nonparametric.warning.empty()) r.warn(FitWarning::ClosedLoopBias, r.nonparametric.warning);
  if (r.method == ClosedLoopMethod::Direct && d.closedLoop &&
      (o.closedLoop == ClosedLoopChoice::Direct || o.model.nonlinear() ||
       (r.estimation.size() > 1 && o.noiseModel == NoiseModel::OutputError)))
    r.warn(FitWarning::ClosedLoopBias, std::string("the log was recorded in closed loop: only models with a flexible, "
                                     "independently parameterized noise model (BJ) are free of bias (4.43); "
                                     "on simulated logs at the sample logs' noise only ") +
                         kDirectCoverage + " of the direct fit's 99 % intervals held the truth");
  if (r.physical) {
    intervalCaveats(o, r);
    deflectionCheck(o, r);
  }
  if (r.polynomial && d.closedLoop && r.polynomial->structure != PolyStructure::Bj)
    r.warn(FitWarning::ClosedLoopBias, "the log was recorded in closed loop: only models with a flexible, independently "
                         "parameterized noise model (BJ) are free of bias (4.43)");
}

}  // namespace flexarm::fit_detail
