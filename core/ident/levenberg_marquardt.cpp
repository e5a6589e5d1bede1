#include "core/ident/levenberg_marquardt.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>
#include <stdexcept>

namespace flexarm {

void fillStatistics(EstimateSummary& s, double sumSq, Eigen::Index n, int p) {
  const double N = static_cast<double>(n);
  s.loss = sumSq / N;
  s.fpe = p < n ? s.loss * (1.0 + p / N) / (1.0 - p / N) : INFINITY;
  s.aic = N * std::log(std::max(s.loss, 1e-300)) + 2.0 * p;
}

Eigen::MatrixXd gaussNewtonCovariance(const Eigen::MatrixXd& psi, double sumSquares) {
  if (psi.rows() <= psi.cols() || psi.cols() == 0) return {};
  return gaussNewtonCovariance(Eigen::MatrixXd(psi.transpose() * psi), psi.rows(), sumSquares);
}

Eigen::MatrixXd gaussNewtonCovariance(const Eigen::MatrixXd& R, Eigen::Index n, double sumSquares) {
  const Eigen::Index p = R.cols();
  if (n <= p || p == 0) return {};
  Eigen::LDLT<Eigen::MatrixXd> ldlt(R);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-14 * R.diagonal().maxCoeff()).all())
    return {};
  return sumSquares / static_cast<double>(n - p) * ldlt.solve(Eigen::MatrixXd::Identity(p, p));
}

namespace {

// In-place radix-2 FFT (length a power of two); inverse without the 1/n factor.
void fft(std::vector<std::complex<double>>& a, bool inverse) {
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const double ang = 2.0 * M_PI / static_cast<double>(len) * (inverse ? 1.0 : -1.0);
    const std::complex<double> wl(std::cos(ang), std::sin(ang));
    for (std::size_t i = 0; i < n; i += len) {
      std::complex<double> w(1.0, 0.0);
      for (std::size_t k = 0; k < len / 2; ++k) {
        const std::complex<double> x = a[i + k], y = a[i + k + len / 2] * w;
        a[i + k] = x + y;
        a[i + k + len / 2] = x - y;
        w *= wl;
      }
    }
  }
}

std::vector<std::complex<double>> padded(const Eigen::VectorXd& x, std::size_t len) {
  std::vector<std::complex<double>> a(len, 0.0);
  for (Eigen::Index i = 0; i < x.size(); ++i) a[static_cast<std::size_t>(i)] = x[i];
  return a;
}

}  // namespace

Eigen::MatrixXd longRunCovariance(const std::vector<RegressorErrorPair>& terms, int lags) {
  if (terms.empty()) throw std::invalid_argument("longRunCovariance: no terms");
  if (lags < 0) throw std::invalid_argument("longRunCovariance: the number of lags must not be negative");
  const Eigen::Index n = terms[0].psi->rows(), p = terms[0].psi->cols();
  for (const auto& t : terms)
    if (t.psi->rows() != n || t.psi->cols() != p || t.eps->size() != n)
      throw std::invalid_argument("longRunCovariance: regressors and errors differ in size");
  if (n < 2) return Eigen::MatrixXd::Zero(p, p);
  const Eigen::Index m = std::min<Eigen::Index>(lags, n - 1);
  // Transforms of length L >= n + m, so that no circular wrap reaches the lags |tau| <= m.
  std::size_t len = 1;
  while (len < static_cast<std::size_t>(n + m + 1)) len <<= 1;
  const double L = static_cast<double>(len);
  std::vector<std::vector<std::complex<double>>> E;
  std::vector<Eigen::MatrixXcd> Psi;
  for (const auto& t : terms) {
    E.push_back(padded(*t.eps, len));
    fft(E.back(), false);
    Eigen::MatrixXcd P(static_cast<Eigen::Index>(len), p);
    for (Eigen::Index j = 0; j < p; ++j) {
      auto col = padded(t.psi->col(j), len);
      fft(col, false);
      for (std::size_t k = 0; k < len; ++k) P(static_cast<Eigen::Index>(k), j) = col[k];
    }
    Psi.push_back(std::move(P));
  }
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(p, p);
  for (std::size_t i = 0; i < terms.size(); ++i)
    for (std::size_t j = 0; j < terms.size(); ++j) {
      // R_ij(tau) = (1/n) sum_t eps_i(t) eps_j(t - tau), windowed, then its transform S_ij.
      std::vector<std::complex<double>> a(len);
      for (std::size_t k = 0; k < len; ++k) a[k] = E[i][k] * std::conj(E[j][k]);
      fft(a, true);
      std::vector<std::complex<double>> w(len, 0.0);
      for (Eigen::Index tau = -m; tau <= m; ++tau) {
        const std::size_t at = tau >= 0 ? static_cast<std::size_t>(tau) : len - static_cast<std::size_t>(-tau);
        const double weight = 1.0 - static_cast<double>(std::abs(tau)) / static_cast<double>(m + 1);
        w[at] = weight * a[at].real() / (L * static_cast<double>(n));
      }
      fft(w, false);
      Eigen::VectorXcd S(static_cast<Eigen::Index>(len));
      for (std::size_t k = 0; k < len; ++k) S[static_cast<Eigen::Index>(k)] = w[k];
      // sum_tau R(tau) sum_t a(t) b(t - tau) = (1/L) sum_k S(k) conj(A(k)) B(k).
      Q += (Psi[i].adjoint() * S.asDiagonal() * Psi[j]).real() / L;
    }
  return 0.5 * (Q + Q.transpose());
}

Eigen::MatrixXd sandwichCovariance(const Eigen::MatrixXd& psi, const Eigen::VectorXd& eps,
                                   int lags) {
  const Eigen::Index n = psi.rows(), p = psi.cols();
  if (eps.size() != n) throw std::invalid_argument("sandwichCovariance: psi and eps differ in length");
  if (lags < 0) throw std::invalid_argument("sandwichCovariance: the number of lags must not be negative");
  if (n <= p || p == 0) return {};
  const Eigen::MatrixXd H = psi.transpose() * psi;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-14 * H.diagonal().maxCoeff()).all())
    return {};
  const Eigen::MatrixXd Q = longRunCovariance({{&psi, &eps}}, lags);
  const Eigen::MatrixXd Hi = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  return static_cast<double>(n) / static_cast<double>(n - p) * (Hi * Q * Hi);
}

int automaticCovarianceLags(const Eigen::VectorXd& eps) {
  const Eigen::Index n = eps.size();
  return static_cast<int>(std::max<Eigen::Index>(std::min<Eigen::Index>(10, n - 1), n / 10));
}

LeastSquaresSolution levenbergMarquardt(const LeastSquaresProblem& problem,
                                        const Eigen::VectorXd& phi0, int maxIterations,
                                        double relTol, double damping,
                                        const ProgressCallback& progress) {
  LeastSquaresSolution r;
  auto& s = r.summary;
  r.phi = phi0;
  if (problem.project) problem.project(r.phi);
  const bool normal = static_cast<bool>(problem.normalEquations);
  // N times (4.21) and -N times (4.19) at r.phi from psi. Few parameters: one dot product per
  // entry, which for tall, narrow psi beats the blocked matrix product.
  Eigen::VectorXd g;
  const auto reduce = [&] {
    if (r.psi.cols() <= 16) {
      r.R.noalias() = r.psi.transpose().lazyProduct(r.psi);
      g.noalias() = r.psi.transpose().lazyProduct(r.eps);
    } else {
      r.R.noalias() = r.psi.transpose() * r.psi;
      g.noalias() = r.psi.transpose() * r.eps;
    }
  };
  const bool admissible =
      normal ? problem.normalEquations(r.phi, INFINITY, r.sumSquares, &r.R, &g) &&
                   std::isfinite(r.sumSquares) && r.R.allFinite() && g.allFinite()
             : problem.evaluate(r.phi, r.eps, &r.psi) && r.eps.allFinite() && r.psi.allFinite();
  if (!admissible) {
    s.termination = Termination::Failed;
    s.message = "the initial parameters give an unstable predictor or non-finite errors";
    return r;
  }
  if (!normal) r.sumSquares = r.eps.squaredNorm();
  const double n = static_cast<double>(normal ? problem.samples : r.eps.size());
  s.lossHistory.push_back(r.sumSquares / n);
  double mu = damping;
  s.termination = Termination::MaxIterations;
  s.message = "reached the maximum number of iterations";
  Eigen::VectorXd trialPhi, trialEps, trialG;
  Eigen::MatrixXd trialR, Rl;
  for (int it = 0; it < maxIterations; ++it) {
    if (reportProgress(progress, static_cast<double>(it) / maxIterations, "iterating")) {
      s.termination = Termination::Cancelled;
      s.message = "cancelled by the user";
      break;
    }
    if (!normal) reduce();
    const double dmax = std::max(1e-300, r.R.diagonal().maxCoeff());
    const Eigen::VectorXd scale = r.R.diagonal().cwiseMax(1e-12 * dmax);
    bool accepted = false, first = true;
    double newSum = r.sumSquares;
    while (mu < 1e12) {
      Rl = r.R;
      Rl.diagonal() += mu * scale;
      trialPhi = r.phi + Rl.ldlt().solve(g);
      if (problem.project) {
        // A parameter already on its bound that the step pushes past it is held there and the
        // step solved again for the others: clipping the full step instead moves the others
        // as if the held one had moved too, and the search crawls along the bound (a two-mass
        // fit of the three-mass chirp log, d_a on 0: 118 iterations instead of a few).
        Eigen::VectorXd clipped = trialPhi;
        problem.project(clipped);
        std::vector<Eigen::Index> moving;
        for (Eigen::Index j = 0; j < clipped.size(); ++j) {
          const bool onBound = clipped[j] != trialPhi[j] &&
                               std::abs(clipped[j] - r.phi[j]) <= 1e-12 * (1.0 + std::abs(r.phi[j]));
          if (!onBound) moving.push_back(j);
        }
        if (static_cast<Eigen::Index>(moving.size()) < clipped.size() && !moving.empty()) {
          const auto m = static_cast<Eigen::Index>(moving.size());
          Eigen::MatrixXd Rm(m, m);
          Eigen::VectorXd gm(m);
          for (Eigen::Index a = 0; a < m; ++a) {
            gm[a] = g[moving[a]];
            for (Eigen::Index b = 0; b < m; ++b) Rm(a, b) = Rl(moving[a], moving[b]);
          }
          const Eigen::VectorXd step = Rm.ldlt().solve(gm);
          trialPhi = r.phi;
          for (Eigen::Index a = 0; a < m; ++a) trialPhi[moving[a]] += step[a];
          problem.project(trialPhi);
        } else {
          trialPhi = clipped;
        }
      }
      double ss = INFINITY;
      if (normal) {
        // The first trial of an iteration, usually accepted, brings R and g with its loss; a
        // retry brings its loss alone, and R and g once it is accepted. Any trial may stop as
        // soon as its loss exceeds the current one.
        bool ok = problem.normalEquations(trialPhi, r.sumSquares, ss, first ? &trialR : nullptr,
                                          first ? &trialG : nullptr);
        if (ok && !first && ss < r.sumSquares)
          ok = problem.normalEquations(trialPhi, INFINITY, ss, &trialR, &trialG);
        if (!ok || !trialR.allFinite() || !trialG.allFinite()) ss = INFINITY;
      } else if (problem.evaluate(trialPhi, trialEps, nullptr)) {
        ss = trialEps.squaredNorm();
      }
      first = false;
      if (std::isfinite(ss) && ss < r.sumSquares) {
        newSum = ss;
        accepted = true;
        mu = std::max(mu / 10.0, 1e-12);
        break;
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
    if (normal) {
      r.R.swap(trialR);
      g.swap(trialG);
    } else {
      problem.evaluate(r.phi, r.eps, &r.psi);
    }
    s.lossHistory.push_back(r.sumSquares / n);
    if (rel < relTol) {
      s.termination = Termination::Converged;
      s.message = "the relative loss improvement fell below the tolerance";
      break;
    }
  }
  if (!normal) r.R.resize(0, 0);
  return r;
}

}  // namespace flexarm
