// Steps 2-4 of the fit pipeline for physical models with effects: the nonlinear grey-box
// estimator (nonlinear_pem.h, output error (5.7)) over every estimation experiment.
#include <cmath>
#include <cstdio>

#include "core/ident/fit_internal.h"
#include "core/signal/preprocess.h"

namespace flexarm::fit_detail {

namespace {
bool angleOutput(const FitResult& r) {
  return r.model.start && r.model.start->options().output == ModelOutput::MotorAngle;
}
}  // namespace

NonlinearPemOptions nonlinearOptions(const FitOptions& o, const FitResult& r) {
  NonlinearPemOptions no;
  no.smoothingSpeed = r.smoothingSpeed;
  no.maxIterations = o.maxIterations;
  no.level = o.level;
  // A velocity differentiated from the angle at the fit's rate is compared with the predicted
  // angle through the same central differences; a logged velocity, or one decimated behind
  // the anti-alias filter, with the velocity state.
  no.output = angleOutput(r) ? PredictedOutput::MotorAngle
              : r.data.differentiated && r.data.decimation == 1 && r.data.angle.size() > 0
                  ? PredictedOutput::DifferentiatedAngle
                  : PredictedOutput::MotorVelocity;
  // A closed-loop log carries a load torque on the arm that the controller answers: the
  // observer keeps the simulation on the measured operating point, as in discovery.
  // Not with the arm as an output: the deflection the arm encoder measures is to be predicted
  // from the logged torque alone, and an observer's torque would pass through the spring.
  no.observerBandwidthHz = fitObserverHz(evaluatedModel(o, r), r.data);
  return no;
}

NonlinearSeries nonlinearSeries(const FitResult& r, const PreparedData& d, SampleRange range) {
  NonlinearSeries s = flexarm::nonlinearSeries(d, range, angleOutput(r));
  // With the arm as an output the whole motion comes from the torque: a motor angle reset to
  // the measured one each sample would hand the measurement to the gravity torque
  // m g l sin(phi_a + phi_0) (and on KUKA axes 2 and 3 it takes the fit to a skew of 12 ms).
  if (r.model.armOutput) s.resetAngle = false;
  return s;
}

namespace {

double rms(const std::vector<double>& x) {
  double mean = 0.0, sum = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(std::max<std::size_t>(1, x.size()));
  for (double v : x) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / static_cast<double>(std::max<std::size_t>(1, x.size())));
}

// The RMS motor speed of the experiments (rad/s, or m/s on a prismatic axis), about zero.
double rmsSpeed(const std::vector<NonlinearSeries>& experiments, bool angleOut) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& s : experiments) {
    const std::vector<double> v = angleOut ? differentiate(s.y, s.Ts) : s.y;
    for (double x : v) sum += x * x;
    n += v.size();
  }
  return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

// The RMS of the motor output's and the deflection's errors of the estimate on the experiments.
bool outputNoise(const PhysicalModel& model, const std::vector<Effect>& effects, const std::vector<NonlinearSeries>& ex,
                 const NonlinearPemOptions& no, double& motor, double& arm) {
  std::vector<double> em, ea;
  try {
    NonlinearPlant plant(model, effects);
    if (no.smoothingSpeed > 0.0) plant.setSmoothingSpeed(no.smoothingSpeed);
    for (const auto& s : ex) {
      std::vector<double> yhat, d;
      const int substeps = no.substeps > 0 ? no.substeps : defaultSubsteps(s.Ts);
      if (!predictOutput(plant, s, substeps, loadObserver(model, no.observerBandwidthHz), no.output, yhat, nullptr, &d))
        return false;
      double md = 0.0, mp = 0.0;
      for (std::size_t k = 0; k < d.size(); ++k) md += s.deflection[k], mp += d[k];
      md /= static_cast<double>(d.size());
      mp /= static_cast<double>(d.size());
      for (std::size_t k = 0; k < d.size(); ++k) {
        em.push_back(s.y[k] - yhat[k]);
        ea.push_back((s.deflection[k] - md) - (d[k] - mp));
      }
    }
  } catch (const std::invalid_argument&) {
    return false;
  }
  motor = rms(em);
  arm = rms(ea);
  return motor > 0.0 && arm > 0.0;
}

}  // namespace

void fitNonlinear(const FitOptions& o, FitResult& r, const ProgressCallback& progress) {
  std::vector<NonlinearSeries> experiments;
  for (const auto& e : r.estimation) experiments.push_back(nonlinearSeries(r, e.data, e.data.estimation));
  // The start model with the start values and the fit's bounds, as for the linear fits.
  const std::shared_ptr<const PhysicalModel> start = fitStartModel(o, &r.warnings);
  const bool angleOut = o.model.start->options().output == ModelOutput::MotorAngle;
  // The smooth signs scaled to the data's speed, whatever its units.
  const double speed = rmsSpeed(experiments, angleOut);
  std::vector<FitEffect> effects = o.model.effects;
  if (speed > 0.0 && std::isfinite(speed)) {
    r.smoothingSpeed = 0.01 * speed;
    for (auto& f : effects)
      if (f.effect.kind == EffectKind::CoulombFriction && f.scaleSmoothing && !f.isFree(1)) {
        f.effect.values[1] = r.smoothingSpeed;
        char buf[160];
        std::snprintf(buf, sizeof buf, "coulomb_friction's smoothing speed v_s = %.3g, 1 %% of the data's RMS "
                      "motor speed %.3g", r.smoothingSpeed, speed);
        r.warn(FitWarning::SmoothingSpeed, buf);
      }
  }
  NonlinearPemOptions no = nonlinearOptions(o, r);
  if (o.model.armOutput) {
    // The measured deflection through the start's gear ratio (the log's), each experiment's.
    const double ratio = start->value("r");
    for (std::size_t i = 0; i < experiments.size(); ++i) {
      const PreparedData& d = r.estimation[i].data;
      const auto b = static_cast<Eigen::Index>(d.estimation.begin), n = static_cast<Eigen::Index>(d.estimation.size());
      if (d.arm.size() != d.u.size() || d.angle.size() != d.u.size()) {
        r.summary.termination = Termination::Failed;
        r.summary.message = std::string("the arm as an output needs the motor angle and the arm-side encoder's ") +
                            columns::kArmAngle + " in the log, and it has no " +
                            (d.arm.size() != d.u.size() ? columns::kArmAngle : columns::kMotorAngle);
        r.status = FitStatus::BadData;
        return;
      }
      experiments[i].deflection.resize(static_cast<std::size_t>(n));
      for (Eigen::Index k = 0; k < n; ++k)
        experiments[i].deflection[static_cast<std::size_t>(k)] = ratio * d.angle[b + k] - d.arm[b + k];
    }
    // First the outputs balanced by their spread, then weighted by the noise the first fit leaves.
    const double w0 = rms(experiments.front().y) / std::max(1e-300, rms(experiments.front().deflection));
    for (auto& s : experiments) s.deflectionWeight = w0;
    NonlinearPemResult first = nonlinearPem(*start, effects, experiments, no,
                                            [&progress](double f, const std::string& stage) {
                                              return progress ? progress(0.5 * f, stage) : ProgressAction::Continue;
                                            });
    double motor = 0.0, arm = 0.0;
    if (first.model && first.summary.ok() && outputNoise(*first.model, first.effects, experiments, no, motor, arm)) {
      for (auto& s : experiments) s.deflectionWeight = motor / arm;
      auto refined = std::shared_ptr<PhysicalModel>(static_cast<PhysicalModel*>(first.model->clone().release()));
      for (std::size_t i = 0; i < effects.size(); ++i) effects[i].effect = first.effects[i];
      NonlinearPemResult e = nonlinearPem(*refined, effects, experiments, no,
                                          [&progress](double f, const std::string& stage) {
                                            return progress ? progress(0.5 + 0.5 * f, stage) : ProgressAction::Continue;
                                          });
      first = std::move(e);
    }
    r.deflectionWeight = experiments.front().deflectionWeight;
    keepNonlinear(std::move(first), o, *start, r);
    return;
  }
  keepNonlinear(nonlinearPem(*start, effects, experiments, no, progress), o, *start, r);
}

void keepNonlinear(NonlinearPemResult&& e, const FitOptions& o, const PhysicalModel& start, FitResult& r) {
  r.summary = e.summary;
  if (!e.model) return;
  if (r.data.closedLoop) {
    r.method = ClosedLoopMethod::Direct;
    r.methodDescription = "direct fit of closed-loop data";
    const double observer = nonlinearOptions(o, r).observerBandwidthHz;
    char reason[200];
    if (observer > 0.0)
      std::snprintf(reason, sizeof reason,
                    "a fit with effects simulates the plant from the measured torque, through a %g Hz load "
                    "observer as discovery does",
                    observer);
    else
      std::snprintf(reason, sizeof reason,
                    "a fit with effects simulates the plant from the measured torque alone (no load observer: "
                    "the arm encoder's deflection is fitted too)");
    r.methodReason = reason;
  }
  std::size_t row = 0;
  for (; row < e.model->parameters().size(); ++row) {
    const auto& p = e.parameters[row];
    r.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, p.free, "", true, {}});
  }
  for (const auto& fx : e.effects)
    for (std::size_t k = 0; k < fx.values.size(); ++k, ++row) {
      const auto& p = e.parameters[row];
      r.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, p.free, toString(fx.kind), true, {}});
    }
  const auto pf = static_cast<Eigen::Index>(e.freeIndices.size());
  if (pf > 0 && e.covariance.rows() >= pf) {
    r.covariance = e.covariance.topLeftCorner(pf, pf);
    r.freeIndices = e.freeIndices;
  }
  r.fullCovariance = e.covariance;
  r.effects = e.effects;
  r.physical = std::shared_ptr<const PhysicalModel>(std::move(e.model));
  if (r.summary.ok()) boundWarnings(start, r);
  if (!r.effects.empty())
    r.warn(FitWarning::LinearPartResponse, "the frequency response, its notches and peaks are of the model's linear part (the "
                         "effects left out)");
  if (o.randomStarts > 0)
    r.warn(FitWarning::RandomStartsUnused, "random starts are not used by a fit with effects: it starts from the values given");
}

}  // namespace flexarm::fit_detail
