// Steps 2-4 of the fit pipeline for physical models with effects: the nonlinear grey-box
// estimator (nonlinear_pem.h, output error (5.7)) over every estimation experiment.
#include "core/ident/fit_internal.h"

namespace flexarm::fit_detail {

NonlinearPemOptions nonlinearOptions(const FitOptions& o) {
  NonlinearPemOptions no;
  no.maxIterations = o.maxIterations;
  no.level = o.level;
  no.output = o.model.start && o.model.start->options().output == ModelOutput::MotorAngle
                  ? PredictedOutput::MotorAngle
                  : PredictedOutput::MotorVelocity;
  return no;
}

NonlinearSeries nonlinearSeries(const FitResult& r, const PreparedData& d, SampleRange range) {
  NonlinearSeries s;
  const auto b = static_cast<Eigen::Index>(range.begin), n = static_cast<Eigen::Index>(range.size());
  s.Ts = d.sampleTime;
  s.startTime = d.timeAt(range.begin);
  s.u.assign(d.u.data() + b, d.u.data() + b + n);
  s.y.assign(d.y.data() + b, d.y.data() + b + n);
  const bool angleOut = r.model.start && r.model.start->options().output == ModelOutput::MotorAngle;
  if (angleOut) s.phi = s.y;
  else if (d.angle.size() == d.u.size()) s.phi.assign(d.angle.data() + b, d.angle.data() + b + n);
  // The start in rigid-body motion at the first sample's speed.
  if (angleOut) s.initialSpeed = n > 1 ? (s.y[1] - s.y[0]) / s.Ts : 0.0;
  else s.initialSpeed = n > 0 ? s.y[0] : 0.0;
  return s;
}

void fitNonlinear(const FitOptions& o, FitResult& r, const ProgressCallback& progress) {
  std::vector<NonlinearSeries> experiments;
  for (const auto& e : r.estimation) experiments.push_back(nonlinearSeries(r, e.data, e.data.estimation));
  // The start model with the start values and the fit's bounds, as for the linear fits.
  const std::shared_ptr<const PhysicalModel> start = fitStartModel(o, &r.warnings);
  NonlinearPemResult e = nonlinearPem(*start, o.model.effects, experiments, nonlinearOptions(o), progress);
  r.summary = e.summary;
  if (!e.model) return;
  if (r.data.closedLoop) {
    r.method = ClosedLoopMethod::Direct;
    r.methodDescription = "direct fit of closed-loop data";
    r.methodReason = "a fit with effects simulates the plant from the measured torque";
  }
  std::size_t row = 0;
  for (; row < e.model->parameters().size(); ++row) {
    const auto& p = e.parameters[row];
    r.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, p.free, ""});
  }
  for (const auto& fx : e.effects)
    for (std::size_t k = 0; k < effectParameters(fx.kind).size(); ++k, ++row) {
      const auto& p = e.parameters[row];
      r.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, p.free, toString(fx.kind)});
    }
  const auto pf = static_cast<Eigen::Index>(e.freeIndices.size());
  if (pf > 0 && e.covariance.rows() >= pf) {
    r.covariance = e.covariance.topLeftCorner(pf, pf);
    r.freeIndices = e.freeIndices;
  }
  r.fullCovariance = e.covariance;
  r.effects = e.effects;
  r.physical = std::shared_ptr<const PhysicalModel>(std::move(e.model));
  if (r.summary.ok()) boundWarnings(*start, r);
  r.warnings.push_back("the frequency response, its notches and peaks are of the model's linear part (the "
                       "effects left out)");
  if (o.randomStarts > 0)
    r.warnings.push_back("random starts are not used by a fit with effects: it starts from the values given");
}

}  // namespace flexarm::fit_detail
