// Steps 2-4 of the fit pipeline for physical models: the closed-loop method, the starts and
// the prediction-error estimator (5.7).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/ident/evaluation.h"
#include "core/ident/fit_internal.h"
#include "core/ident/residuals.h"

namespace flexarm::fit_detail {
namespace {

// Why Auto takes the indirect fit when it can (bench/bench_fit_closed_loop.cpp, 6 logs per
// level of the two-mass arm at 2 kHz, noise 0.03 to 10 times the sample logs'): it was
// unbiased at every level (mean errors within a tenth of their spread but for d_a's small
// share) with every one of its 180 intervals holding the truth, where the direct fit was
// biased beyond its spread at every level (the differentiated angle at low noise, the
// feedback (4.43) above it; 37 of 180 intervals held) and the two-stage fit at the lowest and
// the highest levels (162 of 180), at three to six times the indirect fit's time.
const char* const kIndirectEvidence =
    "the loop from the reference is consistent in closed loop; on simulated logs it was unbiased with "
    "honest 99 % intervals at every noise level, where the direct fit was biased beyond its spread at every "
    "level and the two-stage fit at the lowest and the highest";

std::string percent(double v, int decimals = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f %%", decimals, v);
  return buf;
}

std::string hz(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g Hz", v);
  return buf;
}

// What the indirect fit closes its loop with: reference, measured angle and torque as logged
// from the log's first sample to the end of the estimation range, and the controller.
struct Loop {
  Eigen::VectorXd reference, angle, torque;
  Eigen::Index warmup = 0;  // samples before the estimation range
  ControllerOptions controller;
  std::string source;  // a sentence: where the controller comes from, how well it explains u
  double fitPercent = 0.0;
};

// The loop for the indirect fit, or nullopt with the reason it cannot run.
std::optional<Loop> loopOf(const FitOptions& o, const PreparedData& d, std::string* why) {
  auto refuse = [why](const std::string& text) -> std::optional<Loop> {
    *why = text;
    return std::nullopt;
  };
  if (o.noiseModel != NoiseModel::OutputError)
    return refuse("the indirect closed-loop fit is output error; it excludes the innovations form");
  if (d.decimation > 1)
    return refuse("the indirect closed-loop fit runs the controller at its own rate, and the data are "
                  "decimated");
  if (d.r.size() == 0) return refuse("the indirect closed-loop fit needs a reference channel, and the log has none");
  if (d.angle.size() == 0)
    return refuse(std::string("the indirect closed-loop fit needs the motor angle channel ") +
                  columns::kMotorAngle + ", and the log has none");
  Loop loop;
  const auto end = static_cast<Eigen::Index>(d.estimation.end);
  loop.warmup = static_cast<Eigen::Index>(d.estimation.begin);
  loop.reference = d.r.head(end).array() + d.referenceMean;
  loop.angle = d.angle.head(end);
  loop.torque = d.u.head(end).array() + d.inputMean;
  const double T = d.sampleTime;
  std::string metaWhy;
  std::optional<ControllerOptions> known = o.controller;
  std::string from = "the controller given";
  if (!known) {
    known = controllerFromMetadata(*o.estimation.front().data, &metaWhy);
    from = "the controller of the log's metadata";
    // A log whose metadata names a controller the cascade of Figure 5.1 is not (feed-forward,
    // a velocity filter) is not guessed at by identifying that cascade.
    const IdData& log = *o.estimation.front().data;
    if (!known && (!log.meta("controller_velocity_feedforward").empty() || !log.meta("controller_velocity_filter_hz").empty()))
      return refuse("the indirect closed-loop fit needs the log's controller, and " + metaWhy);
  }
  if (known) {
    if (std::abs(known->rateHz * T - 1.0) > 1e-6)
      return refuse("the indirect closed-loop fit needs the log at its controller's rate: " + from + " runs at " +
                    hz(known->rateHz) + ", the data are sampled at " + hz(1.0 / T));
    loop.controller = *known;
    loop.fitPercent = controllerFitPercent(*known, loop.reference, loop.angle, loop.torque, T);
    if (!(loop.fitPercent >= o.controllerIdent.minimumFitPercent))
      return refuse("the indirect closed-loop fit needs the log's controller, and " + from + " explains only " +
                    percent(loop.fitPercent) + " of the torque (5.2)");
    loop.source = from + " (it explains " + percent(loop.fitPercent) + " of the torque (5.2))";
    return loop;
  }
  const ControllerIdentResult id = identifyController(loop.reference, loop.angle, loop.torque, T, o.controllerIdent);
  if (!id.ok()) return refuse("the indirect closed-loop fit needs the log's controller; " + id.message);
  loop.controller = id.controller;
  loop.fitPercent = id.fitPercent;
  loop.source = id.message;
  return loop;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The Durbin-Wu-Hausman test of a direct fit against a two-stage one of the same free
// parameters: without feedback bias both are consistent and the direct one efficient, so the
// difference d = b_2 - b_1 has the covariance V_2 - V_1 and d^T (V_2 - V_1)^-1 d is chi-square
// with p degrees of freedom. The estimated V_2 - V_1 is nearly singular in directions where
// both fits are equally precise (on a low-noise log its generalized inverse turned differences
// of a tenth of a standard deviation into H = 16 with 2 degrees of freedom), so the test uses
// V_2, which bounds V_2 - V_1 from above: a difference counts only when it lies beyond the
// two-stage fit's own uncertainty.
struct Hausman {
  double statistic = 0.0, threshold = 0.0;
  int dof = 0;
  bool valid = false;
};

Hausman hausman(const PemResult& direct, const PemResult& twoStage, double level) {
  Hausman h;
  const auto p = static_cast<Eigen::Index>(direct.freeIndices.size());
  if (p == 0 || direct.freeIndices != twoStage.freeIndices || direct.covariance.rows() < p ||
      twoStage.covariance.rows() < p)
    return h;
  Eigen::VectorXd diff(p), scale(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    const auto k = static_cast<std::size_t>(direct.freeIndices[static_cast<std::size_t>(i)]);
    scale[i] = std::max(std::abs(direct.parameters[k].value), 1e-300);
    diff[i] = (twoStage.parameters[k].value - direct.parameters[k].value) / scale[i];
  }
  // Relative units, so that the eigenvalue cut below does not depend on the parameters' sizes.
  const Eigen::MatrixXd S = scale.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd V = S * twoStage.covariance.topLeftCorner(p, p) * S;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (V + V.transpose()));
  if (eig.info() != Eigen::Success) return h;
  const double top = eig.eigenvalues().cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < p; ++i) {
    const double lambda = eig.eigenvalues()[i];
    if (!(lambda > 1e-12 * top)) continue;  // a direction the fit does not determine
    const double c = eig.eigenvectors().col(i).dot(diff);
    h.statistic += c * c / lambda;
    ++h.dof;
  }
  if (h.dof == 0) return h;
  h.threshold = chiSquareQuantile(level, h.dof);
  h.valid = std::isfinite(h.statistic);
  return h;
}

void keepEstimate(PemResult&& e, const FitOptions& o, FitResult& r) {
  (void)o;
  r.summary = e.summary;
  if (e.skippedStarts > 0)
    r.warn(FitWarning::SkippedStarts, std::to_string(e.skippedStarts) + " of " + std::to_string(e.starts) +
                         " starts were skipped for numerical trouble (" + e.skipReason + ")");
  for (const auto& p : e.parameters)
    r.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, p.free, "", true, {}});
  r.physical = std::shared_ptr<const PhysicalModel>(static_cast<PhysicalModel*>(e.model.release()));
  r.K = e.K;
  r.covarianceKind = e.covarianceKind;
  const auto pf = static_cast<Eigen::Index>(e.freeIndices.size());
  if (pf > 0 && e.covariance.rows() >= pf) {
    r.covariance = e.covariance.topLeftCorner(pf, pf);
    r.freeIndices = e.freeIndices;
  }
}

}  // namespace

// A warning for each free parameter that ended on one of its bounds (start: the model the
// search started from, whose bounds it kept).
void boundWarnings(const PhysicalModel& start, FitResult& r) {
  const auto& params = start.parameters();
  for (const auto& q : r.parameters) {
    const int i = start.indexOf(q.name);
    if (!q.free || i < 0) continue;
    const ParameterInfo& p = params[static_cast<std::size_t>(i)];
    // On a bound: within a billionth of the larger of the bound and the start value.
    auto near = [&](double bound) {
      return std::isfinite(bound) &&
             std::abs(q.value - bound) <= 1e-9 * std::max({std::abs(bound), std::abs(p.value), 1e-300});
    };
    const bool low = near(p.lower), high = !low && near(p.upper);
    if (!low && !high) continue;
    r.warn(FitWarning::OnBound, q.name + " sits on its " + (low ? "lower" : "upper") + " bound " +
                         number(low ? p.lower : p.upper) + "; the data would push it " +
                         (low ? "below" : "above") + " (its interval does not account for the bound; " +
                         "widen the bound to let it go further)");
  }
}

bool fitPhysical(const FitOptions& o, FitResult& r, const ProgressCallback& progress) {
  const PreparedData& d = r.data;
  // The start model with the start values and the fit's bounds (fitStartModel).
  const std::shared_ptr<const PhysicalModel> start = fitStartModel(o, &r.warnings);
  const JoinedEstimation joined = joinedEstimation(r);  // every estimation experiment
  const Eigen::VectorXd& u = joined.u;
  const Eigen::VectorXd& y = joined.y;
  const bool several = !joined.lengths.empty();
  const double T = d.sampleTime;
  auto fail = [&r](const std::string& text) {  // the log cannot carry the method asked for
    r.termination = Termination::Failed;
    r.message = text;
    r.status = FitStatus::BadData;
    return false;
  };
  PemOptions po;
  po.maxIterations = o.maxIterations;
  po.noiseModel = o.noiseModel;
  po.randomStarts = o.randomStarts;
  po.seed = o.seed;
  po.level = o.level;
  po.experimentLengths = joined.lengths;
  if (po.randomStarts > 0) {  // two more starts whose notches and peaks match the SPA estimate
    const NonparametricEstimate sp = spa(d.estimationInput(), d.estimationOutput(), T);  // of the first
    if (sp.termination == Termination::Converged) {
      const auto np = notchesAndPeaks(sp.response, 3.0);
      po.targetNotches = np.notches;
      po.targetPeaks = np.peaks;
      if (!np.notches.empty() || !np.peaks.empty()) po.notchPeakStarts = 2;
    }
  }
  ClosedLoopPemOptions co;
  co.pem = po;
  const bool outputError = o.noiseModel == NoiseModel::OutputError;
  std::string loopWhy;
  std::optional<Loop> loop;
  if (d.closedLoop && outputError && !several &&
      (o.closedLoop == ClosedLoopChoice::Auto || o.closedLoop == ClosedLoopChoice::Indirect))
    loop = loopOf(o, d, &loopWhy);

  // The method.
  // One estimator run; its progress fills [from, to] of the whole.
  auto run = [&](ClosedLoopMethod m, CovarianceKind covariance, double from = 0.0, double to = 1.0) {
    ProgressCallback part;
    if (progress)
      part = [&progress, from, to](double f, const std::string& stage) {
        return progress(from + (to - from) * f, stage);
      };
    ClosedLoopPemOptions c = co;
    c.method = m;
    c.pem.covariance = covariance;
    if (m == ClosedLoopMethod::Indirect) {
      c.controller = loop->controller;
      c.loopWarmup = loop->warmup;
      return pemClosedLoop(*start, {}, loop->angle, loop->reference, T, c, part);
    }
    return pemClosedLoop(*start, u, y,
                         m == ClosedLoopMethod::TwoStage ? d.estimationReference() : Eigen::VectorXd(), T, c,
                         part);
  };
  ClosedLoopPemResult cl;
  switch (o.closedLoop) {
    case ClosedLoopChoice::Direct:
      cl = run(ClosedLoopMethod::Direct, CovarianceKind::White);
      if (d.closedLoop) r.methodReason = "asked for";
      break;
    case ClosedLoopChoice::TwoStage:
      if (!d.closedLoop) return fail("the two-stage closed-loop fit needs a reference channel, and the log has none");
      cl = run(ClosedLoopMethod::TwoStage, CovarianceKind::Sandwich);
      r.methodReason = "asked for";
      break;
    case ClosedLoopChoice::Indirect:
      if (!d.closedLoop) return fail("the indirect closed-loop fit needs a reference channel, and the log has none");
      if (!loop) return fail(loopWhy);
      cl = run(ClosedLoopMethod::Indirect, CovarianceKind::Sandwich);
      r.methodReason = "asked for";
      break;
    case ClosedLoopChoice::Auto:
      if (!d.closedLoop) {
        cl = run(ClosedLoopMethod::Direct, CovarianceKind::White);
      } else if (!outputError) {
        cl = run(ClosedLoopMethod::Direct, CovarianceKind::White);
        r.methodReason = "auto: the innovations form models the noise, which only the direct fit can do";
      } else if (several) {
        cl = run(ClosedLoopMethod::Direct, CovarianceKind::White);
        r.methodReason = "auto: several estimation experiments, which only the direct fit takes (it is "
                         "biased in closed loop (4.43))";
      } else if (loop) {
        cl = run(ClosedLoopMethod::Indirect, CovarianceKind::Sandwich);
        r.methodReason = std::string("auto: ") + kIndirectEvidence;
      } else if (d.decimation == 1) {
        // The controller is unknown: the direct fit is biased only when the noise the loop
        // feeds back matters, which a Durbin-Wu-Hausman test of it against the two-stage fit
        // tells (on a low-noise log the direct fit is the more accurate and the faster).
        ClosedLoopPemResult direct = run(ClosedLoopMethod::Direct, CovarianceKind::White, 0.0, 0.3);
        ClosedLoopPemResult twoStage = run(ClosedLoopMethod::TwoStage, CovarianceKind::Sandwich, 0.3, 1.0);
        const Hausman h = direct.pem.summary.ok() && twoStage.pem.summary.ok()
                              ? hausman(direct.pem, twoStage.pem, 0.99)
                              : Hausman{};
        const std::string test = "Durbin-Wu-Hausman H = " + number(h.statistic) + " against the 99 % quantile " +
                                 number(h.threshold) + " of chi-square with " + std::to_string(h.dof) +
                                 " degrees of freedom";
        if (h.valid && h.statistic <= h.threshold) {
          cl = std::move(direct);
          r.methodReason = "auto, because " + loopWhy + ": the direct and two-stage estimates agree within their "
                           "uncertainty (" + test + "), so the feedback does not bias the direct fit and its "
                           "narrower estimate was taken";
        } else {
          cl = std::move(twoStage);
          r.methodReason = "auto, because " + loopWhy +
                           (h.valid ? ": the direct and two-stage estimates differ beyond their uncertainty (" + test +
                                          "), so the feedback biases the direct fit (4.43) and the two-stage fit, "
                                          "consistent in closed loop, was taken"
                                    : std::string(" (two-stage is consistent in closed loop without it)"));
        }
      } else {
        cl = run(ClosedLoopMethod::TwoStage, CovarianceKind::Sandwich);
        r.methodReason = "auto, because " + loopWhy + " (two-stage is consistent in closed loop without it)";
      }
      break;
  }
  if (cl.method == ClosedLoopMethod::Indirect) {
    r.controller = loop->controller;
    r.controllerSource = loop->source;
    r.controllerFitPercent = loop->fitPercent;
  }
  if (d.closedLoop) r.method = cl.method;
  if (cl.method == ClosedLoopMethod::TwoStage && cl.projection.ok) r.referenceFitPercent = cl.projection.fitPercent;
  if (r.method == ClosedLoopMethod::Direct) {
    r.methodDescription = "direct fit of closed-loop data";
  } else if (r.method == ClosedLoopMethod::TwoStage) {
    r.methodDescription = "two-stage closed-loop fit: the reference explains " +
                          percent(r.referenceFitPercent.value_or(0.0), 1) +
                          " of the input, intervals allow coloured errors";
  } else if (r.method == ClosedLoopMethod::Indirect) {
    r.methodDescription = "indirect closed-loop fit: the controller closed around the model, from the "
                          "reference to the motor angle";
  }
  keepEstimate(std::move(cl.pem), o, r);
  if (r.summary.ok()) boundWarnings(*start, r);
  // The estimate keeps the start model's own bounds (widened to hold its value), so that it
  // can be edited and simulated as any model; the fit's bounds were the search's.
  if (r.physical) {
    auto estimate = std::shared_ptr<PhysicalModel>(static_cast<PhysicalModel*>(r.physical->clone().release()));
    for (const auto& p : o.model.start->parameters())
      estimate->setBounds(p.name, std::min(p.lower, estimate->value(p.name)), std::max(p.upper, estimate->value(p.name)));
    r.physical = estimate;
  }
  return true;
}

}  // namespace flexarm::fit_detail
