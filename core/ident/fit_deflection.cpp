// Step 5 of the fit pipeline on a log with an arm-side encoder: the deflection r phi_m - phi_a
// a physical estimate predicts from the torque alone, against the measured one (fit.h,
// DeflectionCheck).
#include <cmath>

#include "core/ident/evaluation.h"
#include "core/ident/fit_internal.h"
#include "core/signal/preprocess.h"

namespace flexarm::fit_detail {
namespace {

// The estimate's deflection over range of d, from the range's first sample as the output is
// (predictedDeflection, model_output.h); empty when the simulation blows up.
Eigen::VectorXd predictedDeflection(const FitOptions& o, const FitResult& r, const PreparedData& d, SampleRange range) {
  const ModelSignal y = flexarm::predictedDeflection(evaluatedModel(o, r), d, range, FitStart::RangeStart);
  return y.ok() ? y.y : Eigen::VectorXd();
}

Eigen::VectorXd aboutMean(const Eigen::VectorXd& x) { return x.array() - x.mean(); }

}  // namespace

void deflectionCheck(const FitOptions& o, FitResult& r) {
  if (!r.physical || r.estimation.empty()) return;
  const PreparedData& d = r.estimation.front().data;
  const double ratio = r.physical->value("r");
  const Eigen::VectorXd measured = measuredDeflection(d, ratio);
  if (measured.size() == 0) return;
  DeflectionCheck c;
  c.gearRatio = ratio;
  const auto b = static_cast<Eigen::Index>(d.estimation.begin), n = static_cast<Eigen::Index>(d.estimation.size());
  const Eigen::VectorXd predicted = predictedDeflection(o, r, d, d.estimation);
  if (predicted.size() != n) {
    r.warn(FitWarning::DeflectionDiverges, "the estimate's deflection diverges when simulated, so it cannot be checked against the "
                         "arm-side encoder");
    return;
  }
  const Eigen::VectorXd dm = aboutMean(measured.segment(b, n)), dp = aboutMean(predicted);
  c.measuredRms = std::sqrt(dm.squaredNorm() / static_cast<double>(n));
  const FitPercents f = fitPercents(dm, dp);
  c.fitPercent = f.seed52;
  c.fitPercentNrmse = f.nrmse;
  const Eigen::VectorXd e = dm - dp;
  c.rmsEstimation = std::sqrt(e.squaredNorm() / static_cast<double>(n));
  // The encoders' skew by least squares of the error on the measured arm velocity.
  const std::vector<double> arm(d.arm.data() + b, d.arm.data() + b + n);
  const std::vector<double> va = differentiate(arm, d.sampleTime);
  const Eigen::Map<const Eigen::VectorXd> v(va.data(), n);
  const double vv = v.squaredNorm();
  if (vv > 0.0) {
    c.skewSeconds = v.dot(e) / vv;
    const Eigen::VectorXd rest = e - c.skewSeconds * v;
    c.skewStd = std::sqrt(rest.squaredNorm() / std::max<double>(1.0, static_cast<double>(n - 1)) / vv);
    c.fitPercentWithoutSkew = fitPercents(dm, dp + c.skewSeconds * v).seed52;
  }
  // Whole logs for the plots, about the estimation range's means.
  const Eigen::VectorXd whole = predictedDeflection(o, r, d, SampleRange{0, static_cast<std::size_t>(d.u.size())});
  c.measured = measured.array() - measured.segment(b, n).mean();
  if (whole.size() == d.u.size()) c.predicted = whole.array() - whole.segment(b, n).mean();
  c.rmsValidation = NAN;
  if (!r.validation.empty()) {
    const PreparedData& v0 = r.validation.front().data;
    const Eigen::VectorXd mv = measuredDeflection(v0, ratio);
    const Eigen::VectorXd pv = predictedDeflection(o, r, v0, SampleRange{0, static_cast<std::size_t>(v0.u.size())});
    const auto vb = static_cast<Eigen::Index>(v0.validation.begin), vn = static_cast<Eigen::Index>(v0.validation.size());
    if (mv.size() == v0.u.size() && pv.size() == v0.u.size() && vn > 1) {
      const Eigen::VectorXd a = aboutMean(mv.segment(vb, vn)), p = aboutMean(pv.segment(vb, vn));
      const FitPercents fv = fitPercents(a, p);
      c.fitPercentValidation = fv.seed52;
      c.fitPercentValidationNrmse = fv.nrmse;
      c.rmsValidation = std::sqrt((a - p).squaredNorm() / static_cast<double>(vn));
      c.measuredValidation = mv.array() - mv.segment(vb, vn).mean();
      c.predictedValidation = pv.array() - pv.segment(vb, vn).mean();
    }
  }
  r.deflection = std::move(c);
}

}  // namespace flexarm::fit_detail

namespace flexarm {

double encoderSkewOf(const std::vector<Effect>& effects) {
  for (const auto& e : effects)
    if (e.kind == EffectKind::EncoderSkew) return e.value(0);
  return 0.0;
}

Eigen::VectorXd simulateDeflection(const PhysicalModel& model, const Eigen::VectorXd& u, double sampleTime,
                                   double encoderSkew) {
  auto m = std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(model.clone().release()));
  m->setOptions(ModelOptions{});
  StateSpace ss = m->stateSpace();
  ss.C = m->armDeflectionRow();
  const ModelTopology t = m->topology();
  if (t.armVelocityState >= 0) ss.C(0, t.armVelocityState) += encoderSkew;
  else ss.C(0, t.motorVelocityState) += encoderSkew * m->value("r");
  ss.D = Eigen::MatrixXd::Zero(1, 1);
  const StateSpace z = discretizeZoh(ss, sampleTime);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(z.A.rows()), y(u.size());
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    y[k] = (z.C * x)(0);
    x = z.A * x + z.B.col(0) * u[k];
  }
  return y;
}

Eigen::VectorXd measuredDeflection(const PreparedData& d, double r) {
  if (d.arm.size() != d.u.size()) return {};
  Eigen::VectorXd motor;
  if (d.angle.size() == d.u.size()) motor = d.angle;
  else if (!d.differentiated && d.outputName == columns::kMotorAngle) motor = d.y.array() + d.outputMean;
  else return {};
  return r * motor - d.arm;
}

}  // namespace flexarm
