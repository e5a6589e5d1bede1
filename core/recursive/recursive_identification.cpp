// The whole-log call of chapter 6 and the seed's choice of P(0).
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "core/recursive/covariance_update.h"
#include "core/recursive/rpem.h"
#include "core/recursive/theta.h"

namespace flexarm {

namespace {

// A sentence naming the first non-finite sample, or empty.
std::string nonFinite(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double T, double t0) {
  for (Eigen::Index k = 0; k < u.size(); ++k)
    if (!std::isfinite(u[k]) || !std::isfinite(y[k]))
      return std::string("The ") + (std::isfinite(u[k]) ? "output" : "input") + " at sample " +
             std::to_string(k) + " (t = " + formatNumber(t0 + static_cast<double>(k) * T) +
             " s) is not a finite number.";
  return {};
}

// Symmetric square root of a positive semi-definite matrix.
Eigen::MatrixXd sqrtm(const Eigen::MatrixXd& S) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(S);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() *
         es.eigenvectors().transpose();
}

// How far sigma can be trusted, measured on the run: the lag-1 autocorrelation of the
// prediction errors and, per parameter, the spread of theta(t) against the mean sigma(t) over
// the second half. Sets r.caveat when sigma understates the uncertainty.
void assessSigma(RecursiveResult& r) {
  const auto& t = r.trajectory;
  const std::size_t n = t.size();
  if (n < 40) return;
  double c0 = 0.0, c1 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    c0 += t.epsilon[k] * t.epsilon[k];
    if (k > 0) c1 += t.epsilon[k] * t.epsilon[k - 1];
  }
  r.epsilonLag1 = c0 > 0.0 ? c1 / c0 : 0.0;
  std::string wide;
  for (std::size_t i = 0; i < r.estimates.size(); ++i) {
    double mean = 0.0, sigma = 0.0;
    const std::size_t from = n / 2, count = n - from;
    for (std::size_t k = from; k < n; ++k) {
      mean += t.theta[i][k];
      sigma += t.sigma[i][k];
    }
    mean /= static_cast<double>(count);
    double var = 0.0;
    for (std::size_t k = from; k < n; ++k) var += (t.theta[i][k] - mean) * (t.theta[i][k] - mean);
    RecursiveEstimate& e = r.estimates[i];
    e.spread = std::sqrt(var / static_cast<double>(count));
    e.meanSigma = sigma / static_cast<double>(count);
    if (e.meanSigma > 0.0 && e.spread > e.meanSigma)
      wide += (wide.empty() ? "" : ", ") + e.parameter.name + " " +
              formatNumber(std::round(10.0 * e.spread / e.meanSigma) / 10.0) + " times";
  }
  // Beyond 2.58 / sqrt(n) the lag-1 correlation is significant at 99 %.
  const bool coloured = std::abs(r.epsilonLag1) > 2.58 / std::sqrt(static_cast<double>(n));
  if (!coloured && wide.empty()) return;
  r.caveat = "sigma = sqrt(lambda_0 P_ii) (7.8) holds for white prediction errors";
  if (coloured)
    r.caveat += "; these are coloured (lag-1 autocorrelation " +
                formatNumber(std::round(100.0 * r.epsilonLag1) / 100.0) + ")";
  if (!wide.empty())
    r.caveat += (coloured ? ", and " : "; ") + std::string("over the second half the estimates varied ") +
                wide + " as much as sigma says";
  r.caveat += ": read the +-3 sigma band as a lower bound of the uncertainty (a bias, e.g. from "
              "noise fed back in closed loop or from decimation, is not in it either).";
}

}  // namespace

InitialCovariance steadyStateCovariance(const ParametricModel& nominal, const Eigen::VectorXd& u,
                                        const Eigen::VectorXd& y, double T,
                                        const RecursiveOptions& design) {
  if (u.size() != y.size())
    throw std::invalid_argument("recursive identification: input and output must have the same "
                                "number of samples");
  InitialCovariance r;
  // psi at the nominal theta: the estimator with theta held (P does not matter here).
  const RecursiveOptions options = perSample(design, T, resolveParameters(nominal, design));
  RecursiveOptions pre = options;
  pre.updateParameters = false;
  pre.thetaStart.clear();
  pre.startScale = 1.0;
  pre.p0.assign(options.estimate.size(), 1.0);
  pre.covarianceLimit = 1e300;
  RecursiveEstimator est(nominal, T, pre);
  const auto p = static_cast<Eigen::Index>(est.parameters().size());
  Eigen::Index N = u.size();
  if (options.p0Samples > 0) N = std::min<Eigen::Index>(N, static_cast<Eigen::Index>(options.p0Samples));
  if (const std::string bad = nonFinite(u.head(N), y.head(N), T, 0.0); !bad.empty()) {
    r.message = bad;
    return r;
  }
  if (N < std::max<Eigen::Index>(10, 2 * p)) {
    r.message = "The pre-run that chooses P(0) needs at least " +
                std::to_string(std::max<Eigen::Index>(10, 2 * p)) + " samples; it has " +
                std::to_string(N) + ".";
    return r;
  }
  Eigen::MatrixXd psi(N, p);
  for (Eigen::Index k = 0; k < N; ++k) {
    const RecursiveStep& s = est.update(u[k], y[k]);
    if (!s.ok) {
      r.message = "The nominal predictor failed in the pre-run for P(0): " + est.message();
      return r;
    }
    psi.row(k) = s.psi.transpose();
  }
  r.Q = psi.transpose() * psi / static_cast<double>(N);  // (6.53)
  const auto& params = est.parameters();
  for (Eigen::Index i = 0; i < p; ++i)
    if (!(r.Q(i, i) > 0.0)) {
      r.message = "The data do not excite " + params[static_cast<std::size_t>(i)].name +
                  ": its gradient psi is zero over the pre-run for P(0).";
      return r;
    }
  const Eigen::VectorXd scale = r.Q.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd correlation = scale.asDiagonal() * r.Q * scale.asDiagonal();
  if (p > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(correlation);
    if (es.eigenvalues().minCoeff() < 1e-10) {
      r.message = "The data cannot tell the estimated parameters apart: their gradients are "
                  "(nearly) linearly dependent over the pre-run for P(0).";
      return r;
    }
  }
  // Start where (6.51) resp. (6.52) put P in steady state, run the P update over the pre-run,
  // and average its diagonal (Section 6.6.2).
  const Eigen::MatrixXd Qinv = r.Q.inverse();
  Eigen::VectorXd r1 = Eigen::VectorXd::Zero(p);
  Eigen::MatrixXd P;
  if (options.algorithm == RecursiveAlgorithm::ForgettingFactor) {
    P = (options.lambda < 1.0 ? 1.0 - options.lambda : 1.0) * Qinv;
  } else {
    r1 = kalmanR1(params, options);
    const Eigen::MatrixXd Qh = sqrtm(r.Q);
    const Eigen::MatrixXd Qhi = Qh.inverse();
    const Eigen::MatrixXd R = Eigen::MatrixXd(r1.asDiagonal()) * options.r2;
    P = Qhi * sqrtm(Qh * R * Qh) * Qhi;
  }
  CovarianceUpdate update(options.algorithm, options.lambda, r1, options.r2, options.mu);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(p), K;
  for (Eigen::Index k = 0; k < N; ++k) {
    if (!update(psi.row(k).transpose(), P, K)) {
      r.message = "The P update failed in the pre-run for P(0) at sample " + std::to_string(k) + ".";
      return r;
    }
    mean += P.diagonal();
  }
  r.p0 = mean / static_cast<double>(N);
  for (Eigen::Index i = 0; i < p; ++i)
    if (!(r.p0[i] > 0.0) || !std::isfinite(r.p0[i])) {
      r.message = "The pre-run gives no usable P(0) for " + params[static_cast<std::size_t>(i)].name +
                  " (R1 of zero keeps P at zero in steady state): give P(0).";
      return r;
    }
  r.termination = Termination::Converged;
  r.message = "P(0) from the P update run at the nominal parameters over " + std::to_string(N) +
              " samples (the seed's Section 6.6.2).";
  return r;
}

RecursiveStart startRecursive(const ParametricModel& nominal, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& y, double T, const RecursiveOptions& options,
                              double startTime) {
  if (u.size() != y.size())
    throw std::invalid_argument("recursive identification: input and output must have the same "
                                "number of samples");
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("recursive identification: " + why);
  RecursiveStart start;
  start.failed.sampleTime = T;
  if (const std::string bad = nonFinite(u, y, T, startTime); !bad.empty()) {
    start.failed.message = bad;
    return start;
  }
  RecursiveOptions o = options;
  if (o.p0.empty() && !o.estimate.empty()) {
    const InitialCovariance ic = steadyStateCovariance(nominal, u, y, T, options);
    if (ic.termination != Termination::Converged) {
      start.failed.message = ic.message;
      return start;
    }
    o.p0.assign(ic.p0.data(), ic.p0.data() + ic.p0.size());
    start.Q = ic.Q;
  }
  start.estimator.emplace(nominal, T, o, startTime);
  return start;
}

RecursiveResult finishRecursive(const RecursiveEstimator& est, RecursiveTrajectory trajectory,
                                std::size_t totalSamples, bool cancelled, const Eigen::MatrixXd& Q) {
  RecursiveResult r;
  r.sampleTime = est.sampleTime();
  r.Q = Q;
  r.trajectory = std::move(trajectory);
  const auto& params = est.parameters();
  r.samples = r.trajectory.size();
  double sumSquares = 0.0;
  for (double e : r.trajectory.epsilon) sumSquares += e * e;
  r.rmsEpsilon = r.samples ? std::sqrt(sumSquares / static_cast<double>(r.samples)) : 0.0;
  r.p0 = est.initialCovariance().diagonal();
  r.P = est.covariance();
  const RecursiveStep& last = est.last();
  for (std::size_t i = 0; i < params.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    RecursiveEstimate e;
    e.parameter = params[i];
    e.start = est.initialTheta()[k];
    e.final = est.theta()[k];
    e.sigma = last.sigma.size() > k ? last.sigma[k] : 0.0;
    e.modelNominal = e.parameter.toModel(e.parameter.nominal);
    e.modelStart = e.parameter.toModel(e.start);
    e.modelFinal = e.parameter.toModel(e.final);
    e.modelSigma = e.parameter.sigmaToModel(e.final, e.sigma);
    r.estimates.push_back(e);
  }
  r.model = est.model();
  r.asRun = est.options();
  assessSigma(r);
  if (!est.ok()) {
    r.termination = Termination::Diverged;
    r.message = est.message();
  } else if (cancelled || r.samples < totalSamples) {
    r.termination = Termination::Cancelled;
    r.message = "Stopped after " + std::to_string(r.samples) + " of " + std::to_string(totalSamples) +
                " samples.";
  } else {
    r.termination = Termination::Converged;
    std::string m = est.message();  // "Processed N samples; ..."
    r.message = "Processed all " + std::to_string(totalSamples) + " samples (" +
                formatNumber(static_cast<double>(totalSamples) * r.sampleTime) + " s)" +
                m.substr(m.find(';'));
  }
  return r;
}

RecursiveResult recursiveIdentification(const ParametricModel& nominal, const Eigen::VectorXd& u,
                                        const Eigen::VectorXd& y, double T,
                                        const RecursiveOptions& options,
                                        const ProgressCallback& progress, double startTime) {
  const auto clock0 = std::chrono::steady_clock::now();
  RecursiveStart start = startRecursive(nominal, u, y, T, options, startTime);
  if (!start.estimator) {
    start.failed.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
    return start.failed;
  }
  RecursiveEstimator& est = *start.estimator;
  const Eigen::Index N = u.size();
  RecursiveTrajectory trajectory;
  trajectory.reserve(static_cast<std::size_t>(N), est.parameters().size());
  const Eigen::Index chunk = std::max<Eigen::Index>(1, N / 100);
  bool cancelled = false;
  for (Eigen::Index k = 0; k < N; ++k) {
    if (k % chunk == 0 && reportProgress(progress, static_cast<double>(k) / N, "recursive")) {
      cancelled = true;
      break;
    }
    const RecursiveStep& s = est.update(u[k], y[k]);
    if (!s.ok) break;
    trajectory.append(s);
  }
  RecursiveResult r = finishRecursive(est, std::move(trajectory), static_cast<std::size_t>(N),
                                      cancelled, start.Q);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  return r;
}

}  // namespace flexarm
