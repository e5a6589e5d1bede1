#include "core/ident/levenberg_marquardt.h"

#include <algorithm>
#include <cmath>

namespace flexarm {

void fillStatistics(EstimateSummary& s, double sumSq, Eigen::Index n, int p) {
  const double N = static_cast<double>(n);
  s.loss = sumSq / N;
  s.fpe = p < n ? s.loss * (1.0 + p / N) / (1.0 - p / N) : INFINITY;
  s.aic = N * std::log(std::max(s.loss, 1e-300)) + 2.0 * p;
}

Eigen::MatrixXd gaussNewtonCovariance(const Eigen::MatrixXd& psi, double sumSquares) {
  const Eigen::Index n = psi.rows(), p = psi.cols();
  if (n <= p || p == 0) return {};
  const Eigen::MatrixXd R = psi.transpose() * psi;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(R);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-14 * R.diagonal().maxCoeff()).all())
    return {};
  return sumSquares / static_cast<double>(n - p) * ldlt.solve(Eigen::MatrixXd::Identity(p, p));
}

LeastSquaresSolution levenbergMarquardt(const LeastSquaresProblem& problem,
                                        const Eigen::VectorXd& phi0, int maxIterations,
                                        double relTol, double damping,
                                        const ProgressCallback& progress) {
  LeastSquaresSolution r;
  auto& s = r.summary;
  r.phi = phi0;
  if (problem.project) problem.project(r.phi);
  if (!problem.evaluate(r.phi, r.eps, &r.psi) || !r.eps.allFinite() || !r.psi.allFinite()) {
    s.termination = Termination::Failed;
    s.message = "the initial parameters give an unstable predictor or non-finite errors";
    return r;
  }
  r.sumSquares = r.eps.squaredNorm();
  const double n = static_cast<double>(r.eps.size());
  s.lossHistory.push_back(r.sumSquares / n);
  double mu = damping;
  s.termination = Termination::MaxIterations;
  s.message = "reached the maximum number of iterations";
  for (int it = 0; it < maxIterations; ++it) {
    if (reportProgress(progress, static_cast<double>(it) / maxIterations, "iterating")) {
      s.termination = Termination::Cancelled;
      s.message = "cancelled by the user";
      break;
    }
    const Eigen::MatrixXd R = r.psi.transpose() * r.psi;  // N times (4.21)
    const Eigen::VectorXd g = r.psi.transpose() * r.eps;  // -N times (4.19)
    const double dmax = std::max(1e-300, R.diagonal().maxCoeff());
    const Eigen::VectorXd scale = R.diagonal().cwiseMax(1e-12 * dmax);
    bool accepted = false;
    double newSum = r.sumSquares;
    Eigen::VectorXd trialPhi, trialEps;
    while (mu < 1e12) {
      Eigen::MatrixXd Rl = R;
      Rl.diagonal() += mu * scale;
      trialPhi = r.phi + Rl.ldlt().solve(g);
      if (problem.project) problem.project(trialPhi);
      if (problem.evaluate(trialPhi, trialEps, nullptr)) {
        const double ss = trialEps.squaredNorm();
        if (std::isfinite(ss) && ss < r.sumSquares) {
          newSum = ss;
          accepted = true;
          mu = std::max(mu / 10.0, 1e-12);
          break;
        }
      }
      mu *= 10.0;
    }
    s.iterations = it + 1;
    if (!accepted) {
      s.termination = Termination::Converged;
      s.message = "no step reduces the loss: a local minimum";
      break;
    }
    const double rel = (r.sumSquares - newSum) / r.sumSquares;
    r.phi = trialPhi;
    r.sumSquares = newSum;
    problem.evaluate(r.phi, r.eps, &r.psi);
    s.lossHistory.push_back(r.sumSquares / n);
    if (rel < relTol) {
      s.termination = Termination::Converged;
      s.message = "the relative loss improvement fell below the tolerance";
      break;
    }
  }
  return r;
}

}  // namespace flexarm
