// Steps 2-4 of the fit pipeline for physical models with effects: the nonlinear grey-box
// estimator (nonlinear_pem.h, output error (5.7)) over every estimation experiment.
#include <cstdio>

#include "core/ident/fit_internal.h"

namespace flexarm::fit_detail {

namespace {
bool angleOutput(const FitResult& r) {
  return r.model.start && r.model.start->options().output == ModelOutput::MotorAngle;
}
}  // namespace

NonlinearPemOptions nonlinearOptions(const FitOptions& o, const FitResult& r) {
  NonlinearPemOptions no;
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
  no.observerBandwidthHz = r.data.closedLoop ? kClosedLoopObserverHz : 0.0;
  return no;
}

NonlinearSeries nonlinearSeries(const FitResult& r, const PreparedData& d, SampleRange range) {
  return flexarm::nonlinearSeries(d, range, angleOutput(r));
}

void fitNonlinear(const FitOptions& o, FitResult& r, const ProgressCallback& progress) {
  std::vector<NonlinearSeries> experiments;
  for (const auto& e : r.estimation) experiments.push_back(nonlinearSeries(r, e.data, e.data.estimation));
  // The start model with the start values and the fit's bounds, as for the linear fits.
  const std::shared_ptr<const PhysicalModel> start = fitStartModel(o, &r.warnings);
  const NonlinearPemOptions no = nonlinearOptions(o, r);
  NonlinearPemResult e = nonlinearPem(*start, o.model.effects, experiments, no, progress);
  r.summary = e.summary;
  if (!e.model) return;
  if (r.data.closedLoop) {
    r.method = ClosedLoopMethod::Direct;
    r.methodDescription = "direct fit of closed-loop data";
    char reason[160];
    std::snprintf(reason, sizeof reason,
                  "a fit with effects simulates the plant from the measured torque, through a %g Hz load "
                  "observer as discovery does",
                  no.observerBandwidthHz);
    r.methodReason = reason;
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
