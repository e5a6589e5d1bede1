#include "core/diagnosis/reference.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/common/text.h"
#include "core/diagnosis/diagnosis_temperature.h"
#include "core/diagnosis/simulate_like.h"
#include "core/ident/closed_loop_pem.h"
#include "core/ident/pem.h"
#include "core/recursive/rpem.h"

namespace flexarm {

namespace {

std::shared_ptr<const PhysicalModel> physicalCopy(const ParametricModel& m) {
  auto copy = m.clone();
  auto* physical = dynamic_cast<PhysicalModel*>(copy.get());
  if (!physical) throw std::invalid_argument("the diagnosis needs a physical model");
  copy.release();
  return std::shared_ptr<const PhysicalModel>(physical);
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Progress of a sub-task mapped into [from, to] of the caller's.
ProgressCallback share(const ProgressCallback& progress, double from, double to) {
  if (!progress) return {};
  return [progress, from, to](double f, const std::string& stage) {
    return progress(from + (to - from) * std::clamp(f, 0.0, 1.0), stage);
  };
}

}  // namespace

bool ReferenceOptions::isValid(std::string* why) const {
  if (maxIterations < 1 || maxIterations > 10000) {
    if (why) *why = "the fits need 1 to 10000 iterations";
    return false;
  }
  if (why) why->clear();
  return true;
}

Eigen::VectorXd outputErrors(const PhysicalModel& model, const DiagnosisSignals& data) {
  return data.output - simulate(*predictorModel(model, data), data.input, data.sampleTime);
}

double quietestMeanSquare(const Eigen::VectorXd& e) {
  if (e.size() == 0) return 0.0;
  const Eigen::Index quarter = std::max<Eigen::Index>(1, e.size() / 4);
  double quietest = e.squaredNorm() / static_cast<double>(e.size());
  for (Eigen::Index q = 0; q + quarter <= e.size(); q += quarter)
    quietest = std::min(quietest, e.segment(q, quarter).squaredNorm() / static_cast<double>(quarter));
  return quietest;
}

NominalFit fitNominalModel(const PhysicalModel& start, const DiagnosisSignals& data, bool closedLoop,
                           int maxIterations, const ProgressCallback& progress) {
  NominalFit fit;
  PemOptions pemOptions;
  pemOptions.noiseModel = NoiseModel::OutputError;
  pemOptions.maxIterations = maxIterations;
  PemResult r;
  if (closedLoop) {
    if (data.r.size() != data.u.size()) {
      fit.message = "the closed-loop fit needs the log's position reference";
      return fit;
    }
    ClosedLoopPemOptions o;
    o.method = ClosedLoopMethod::TwoStage;
    o.pem = pemOptions;
    DiagnosisSignals direct = data;
    direct.predictor = DiagnosisPredictor::Direct;
    r = pemClosedLoop(*predictorModel(start, direct), data.u, data.velocity, data.r,
                      data.sampleTime, o, progress).pem;
  } else {
    r = pem(*predictorModel(start, data), data.input, data.output, data.sampleTime, pemOptions,
            progress);
  }
  fit.termination = r.summary.ok() ? Termination::Converged : r.summary.termination;
  fit.message = r.summary.message;
  if (!r.summary.ok() || !r.model) return fit;
  fit.model = std::shared_ptr<const PhysicalModel>(plantOf(*r.model));
  fit.freeNames = r.freeNames;
  fit.covariance = r.covariance;
  // The monitored parameters' sigma_0 and the thresholds come from this covariance: a fit
  // whose Hessian is singular (data that cannot tell the parameters apart) has none to give.
  if (fit.covariance.rows() != static_cast<Eigen::Index>(fit.freeNames.size()) ||
      fit.covariance.cols() != fit.covariance.rows() || !fit.covariance.allFinite()) {
    fit.termination = Termination::Failed;
    fit.message = "the data cannot tell the parameters apart (the fit's Hessian is singular, so it gives "
                  "no covariance for sigma_0); a log with more excitation is needed";
    fit.model.reset();
    return fit;
  }
  fit.loss = outputErrors(*fit.model, data).squaredNorm() / static_cast<double>(data.size());
  if (!std::isfinite(fit.loss)) {
    fit.termination = Termination::Diverged;
    fit.message = "the fitted model's simulated output diverges";
  }
  return fit;
}

bool formInitialCovariances(DiagnosisReference& ref, const DiagnosisSignals& data,
                            const DiagnosisOptions& options, const std::string& where) {
  const auto predictor = predictorModel(*ref.nominal, data);
  const InitialCovariance all = steadyStateCovariance(*predictor, data.input, data.output, data.sampleTime,
                                                      estimatorOptions(options, options.parameters));
  if (all.termination != Termination::Converged) {
    ref.termination = Termination::Failed;
    ref.message = "P(0) could not be formed on " + where + ": " + all.message;
    return false;
  }
  ref.p0.assign(all.p0.data(), all.p0.data() + all.p0.size());
  ref.p0Single.clear();
  for (const auto& name : options.parameters) {
    const InitialCovariance one = steadyStateCovariance(*predictor, data.input, data.output,
                                                        data.sampleTime, estimatorOptions(options, {name}));
    if (one.termination != Termination::Converged || one.p0.size() != 1) {
      ref.termination = Termination::Failed;
      ref.message = "P(0) for " + name + " alone could not be formed on " + where + ": " + one.message;
      return false;
    }
    ref.p0Single.push_back(one.p0(0));
  }
  return true;
}

DiagnosisReference referenceFromSignals(const PhysicalModel& start, const DiagnosisSignals& healthy,
                                        const DiagnosisOptions& options,
                                        const ReferenceOptions& referenceOptions,
                                        const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("diagnosis: " + why);
  if (!referenceOptions.isValid(&why)) throw std::invalid_argument("diagnosis reference: " + why);
  for (const auto& name : options.parameters)
    if (start.indexOf(name) < 0)
      throw std::invalid_argument("the " + start.structureName() + " model has no parameter '" +
                                  name + "' to monitor");
  const auto begin = std::chrono::steady_clock::now();
  DiagnosisReference ref;
  const bool plantToo = referenceOptions.fitPlant && healthy.r.size() == healthy.u.size();

  // theta_0: the estimator's own criterion, output error from u (direct).
  const NominalFit nominal = fitNominalModel(start, healthy, false, referenceOptions.maxIterations,
                                             share(progress, 0.0, plantToo ? 0.4 : 0.8));
  if (nominal.termination != Termination::Converged) {
    ref.termination = nominal.termination == Termination::Cancelled ? Termination::Cancelled
                                                                     : Termination::Failed;
    ref.message = "the fit of the fault-free data failed: " + nominal.message;
    ref.seconds = seconds(begin);
    return ref;
  }
  ref.nominal = nominal.model;
  ref.predictor = healthy.predictor;
  ref.noiseVariance = nominal.loss;
  for (const auto& name : options.parameters) {
    const auto at = std::find(nominal.freeNames.begin(), nominal.freeNames.end(), name);
    double s = 0.0;
    if (at != nominal.freeNames.end()) {
      const auto i = static_cast<Eigen::Index>(at - nominal.freeNames.begin());
      s = std::sqrt(std::max(0.0, nominal.covariance(i, i)));
      const bool inverted =
          std::find(options.inverted.begin(), options.inverted.end(), name) != options.inverted.end();
      const double v = ref.nominal->value(name);
      if (inverted) s /= v * v;  // std of 1/v
    }
    ref.sigma0.push_back(s);
  }

  // The plant for the calibration: free of the closed-loop bias.
  ref.plant = ref.nominal;
  std::string plantNote = "the same fit";
  if (plantToo) {
    const NominalFit plant = fitNominalModel(start, healthy, true, referenceOptions.maxIterations,
                                             share(progress, 0.4, 0.8));
    if (plant.termination == Termination::Cancelled) {
      ref.termination = Termination::Cancelled;
      ref.message = "cancelled";
      return ref;
    }
    if (plant.termination == Termination::Converged) {
      ref.plant = plant.model;
      plantNote = "the two-stage closed-loop fit";
    } else {
      plantNote = "the direct fit (the two-stage fit failed: " + plant.message + ")";
    }
  }

  // P(0) as the seed forms it (Section 6.6.2), on the fault-free data: for the estimator of
  // every monitored parameter and for each one alone.
  if (reportProgress(progress, 0.8, "P(0)")) {
    ref.termination = Termination::Cancelled;
    ref.message = "cancelled";
    return ref;
  }
  if (!formInitialCovariances(ref, healthy, options, "the fault-free data")) {
    ref.seconds = seconds(begin);
    return ref;
  }
  ref.termination = Termination::Converged;
  ref.source = "theta_0 from the output-error fit of " + std::to_string(healthy.size()) +
               " fault-free samples, " + healthy.description + "; the plant for the calibration: " +
               plantNote;
  ref.message = ref.source;
  ref.seconds = seconds(begin);
  return ref;
}

DiagnosisReference withSeedFault(const DiagnosisReference& reference, const DiagnosisOptions& options,
                                 const std::string& name, double factor) {
  if (std::find(options.parameters.begin(), options.parameters.end(), name) == options.parameters.end())
    throw std::invalid_argument("a seed fault needs a monitored parameter, not " + inQuotes(name));
  if (!reference.nominal) throw std::invalid_argument("the reference has no theta_0");
  if (!(factor > 0.0) || !std::isfinite(factor))
    throw std::invalid_argument("a seed fault's factor must be a positive number");
  const bool inverted =
      std::find(options.inverted.begin(), options.inverted.end(), name) != options.inverted.end();
  auto copy = reference.nominal->clone();
  const double v = reference.nominal->value(name);
  copy->setParameter(name, inverted ? v / factor : v * factor);
  DiagnosisReference out = reference;
  out.nominal = physicalCopy(*copy);
  char buf[120];
  std::snprintf(buf, sizeof buf, "; a fault made as the seed does (Section 7.5): theta_0 of %s%s times %.4g",
                name.c_str(), inverted ? "^-1" : "", factor);
  out.source += buf;
  out.message = out.source;
  return out;
}

DiagnosisReference referenceFromLog(const PhysicalModel& start, const IdData& healthy,
                                    const DiagnosisOptions& options,
                                    const ReferenceOptions& referenceOptions,
                                    const ProgressCallback& progress) {
  std::string why;
  const auto signals = diagnosisSignals(healthy, options.predictor, &why);
  if (!signals) {
    DiagnosisReference ref;
    ref.message = "the fault-free log cannot be used: " + why;
    return ref;
  }
  DiagnosisReference ref = referenceFromSignals(start, *signals, options, referenceOptions, progress);
  ref.temperatureC = logTemperature(healthy).celsius;
  if (ref.ok() || ref.termination == Termination::Cancelled || options.predictor != DiagnosisPredictor::Auto ||
      signals->predictor != DiagnosisPredictor::Loop)
    return ref;
  // Auto: the loop could not be fitted (e.g. the model closed by the controller is unstable
  // without the controller's sampling); the direct predictor of the seed instead.
  const auto direct = diagnosisSignals(healthy, DiagnosisPredictor::Direct, &why);
  if (!direct) return ref;
  DiagnosisReference fallback = referenceFromSignals(start, *direct, options, referenceOptions, progress);
  if (!fallback.ok()) return ref;
  fallback.temperatureC = ref.temperatureC;
  fallback.source += " (the loop predictor could not be fitted: " + ref.message + ")";
  fallback.message = fallback.source;
  return fallback;
}

DiagnosisReference referenceFromModel(const PhysicalModel& model, const IdData& monitored,
                                      const DiagnosisOptions& options,
                                      const ReferenceOptions& referenceOptions,
                                      const ProgressCallback& progress) {
  const auto begin = std::chrono::steady_clock::now();
  std::string why;
  const auto conditions = logConditions(monitored, &why);
  const auto signals = diagnosisSignals(monitored, options.predictor, nullptr);
  if (!conditions || !signals) {
    // Nothing to simulate it with: the model itself, P(0) and lambda_0 from the monitored log.
    DiagnosisReference ref;
    ref.nominal = ref.plant = physicalCopy(model);
    if (signals) ref.predictor = signals->predictor;
    ref.sigma0.assign(options.parameters.size(), 0.0);
    ref.termination = Termination::Converged;
    ref.source = "theta_0 is the model as given (" + (conditions ? std::string("the log has no usable signals") : why) +
                 "); in closed loop the recursive estimates may settle off it (4.43) and show as a "
                 "deviation";
    ref.message = ref.source;
    ref.seconds = seconds(begin);
    return ref;
  }
  // The noise level: the model's output error on the quietest quarter of the monitored log (a
  // fault raises it where it acts).
  const double quietest = quietestMeanSquare(outputErrors(model, *signals));
  std::string noiseNote;
  const double scale = matchNoiseScale(model, model, *conditions, signals->predictor, quietest, &noiseNote);
  const auto run = simulateClosedLoop(model, {}, runOptions(*conditions, scale, 20240601));
  const auto healthy = run.termination == Termination::Converged
                           ? diagnosisSignals(run.data, signals->predictor, &why)
                           : std::nullopt;
  if (!healthy) {
    DiagnosisReference ref;
    ref.message = "the model could not be simulated under the log's conditions: " +
                  (run.termination == Termination::Converged ? why : run.message);
    return ref;
  }
  ReferenceOptions noPlant = referenceOptions;
  noPlant.fitPlant = false;
  DiagnosisReference ref = referenceFromSignals(model, *healthy, options, noPlant, progress);
  if (!ref.ok()) return ref;
  ref.plant = physicalCopy(model);
  ref.source = "theta_0 from the output-error fit of a fault-free run of the given model simulated "
               "with " + conditions->note + " and " + noiseNote + ", " + healthy->description +
               "; the plant for the calibration: the given model";
  ref.message = ref.source;
  ref.seconds = seconds(begin);
  return ref;
}

}  // namespace flexarm
