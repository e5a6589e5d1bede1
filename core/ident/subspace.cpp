#include "core/ident/subspace.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>

#include "core/common/text.h"
#include "core/ident/experiment_segments.h"
#include "core/ident/polynomial.h"

namespace flexarm {

const char* toString(SubspaceMethod m) {
  switch (m) {
    case SubspaceMethod::Auto: return "auto";
    case SubspaceMethod::N4sid: return "n4sid";
    case SubspaceMethod::Moesp: return "moesp";
    case SubspaceMethod::Cva: return "cva";
    case SubspaceMethod::Pbsid: return "pbsid";
  }
  return "auto";
}

std::optional<SubspaceMethod> subspaceMethodFromString(std::string_view s) {
  for (auto m : {SubspaceMethod::Auto, SubspaceMethod::N4sid, SubspaceMethod::Moesp, SubspaceMethod::Cva,
                 SubspaceMethod::Pbsid})
    if (s == toString(m)) return m;
  return std::nullopt;
}

bool SubspaceOptions::isValid(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (order < 0 || order > kMaxOrder)
    return fail("the state-space order must be between 1 and " + std::to_string(kMaxOrder) + " (0: chosen by the data)");
  if (maxOrder < 1 || maxOrder > kMaxOrder)
    return fail("the largest order tried must be between 1 and " + std::to_string(kMaxOrder));
  if (horizon < 0 || horizon > kMaxHorizon)
    return fail("the horizon must be between 1 and " + std::to_string(kMaxHorizon) + " (0: chosen by the data)");
  const int n = order > 0 ? order : maxOrder;
  if (horizon > 0 && horizon <= n)
    return fail("the horizon (" + std::to_string(horizon) + ") must exceed the order (" + std::to_string(n) + ")");
  for (Eigen::Index k : experimentLengths)
    if (k < 1) return fail("every experiment needs at least one sample");
  return true;
}

namespace {

using Segment = ExperimentSegment;


// The columns j of the data matrices: every t of every experiment with p samples before it
// and f from it on (t + f <= n).
std::vector<Eigen::Index> columnTimes(const std::vector<Segment>& segs, int p, int f) {
  std::vector<Eigen::Index> t;
  for (const auto& g : segs)
    for (Eigen::Index k = p; k + f <= g.n; ++k) t.push_back(g.from + k);
  return t;
}

// The past of time t: [u(t-1) y(t-1) u(t-2) y(t-2) ... u(t-p) y(t-p)].
void pastRow(const Eigen::VectorXd& u, const Eigen::VectorXd& y, Eigen::Index t, int p, double* out) {
  for (int k = 1; k <= p; ++k) {
    out[2 * (k - 1)] = u[t - k];
    out[2 * (k - 1) + 1] = y[t - k];
  }
}

// The high-order ARX (VARX) predictor y(t) = sum_{k=1..p} (a_k u(t-k) + b_k y(t-k)) + e(t) of
// every order up to pmax from one QR: the regressors are nested by lag, so the residual sum of
// squares of the first 2p columns is what lies below row 2p of Q^T y.
struct ArxLadder {
  Eigen::MatrixXd R;  // upper triangle of [Phi y]
  Eigen::Index rows = 0;
  int pmax = 0;
  double rss(int p) const {
    const Eigen::Index last = R.cols() - 1;
    double s = 0.0;
    for (Eigen::Index i = 2 * p; i <= last; ++i) s += R(i, last) * R(i, last);
    return s;
  }
  // The coefficients of order p: [a_1 b_1 ... a_p b_p].
  Eigen::VectorXd theta(int p) const {
    const Eigen::Index last = R.cols() - 1;
    // Minimum-norm where the past data are collinear (a periodic input, no noise): the
    // directions the data do not see get no weight instead of an arbitrary one.
    const Eigen::MatrixXd Rp = R.topLeftCorner(2 * p, 2 * p);
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(Rp);
    cod.setThreshold(1e-10);
    return cod.solve(Eigen::VectorXd(R.col(last).head(2 * p)));
  }
};

ArxLadder arxLadder(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const std::vector<Segment>& segs,
                    int pmax) {
  const std::vector<Eigen::Index> times = columnTimes(segs, pmax, 1);
  ArxLadder l;
  l.pmax = pmax;
  l.rows = static_cast<Eigen::Index>(times.size());
  Eigen::MatrixXd M(l.rows, 2 * pmax + 1);
  std::vector<double> row(2 * pmax);
  for (Eigen::Index r = 0; r < l.rows; ++r) {
    pastRow(u, y, times[r], pmax, row.data());
    for (int c = 0; c < 2 * pmax; ++c) M(r, c) = row[c];
    M(r, 2 * pmax) = y[times[r]];
  }
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(M);
  const Eigen::Index k = std::min(M.rows(), M.cols());
  l.R = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  return l;
}

// The innovations of the ARX predictor of order p at every sample (0 before p samples of an
// experiment).
Eigen::VectorXd arxInnovations(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const std::vector<Segment>& segs,
                               const Eigen::VectorXd& theta, int p) {
  Eigen::VectorXd e = Eigen::VectorXd::Zero(y.size());
  std::vector<double> row(2 * p);
  for (const auto& g : segs)
    for (Eigen::Index k = p; k < g.n; ++k) {
      const Eigen::Index t = g.from + k;
      pastRow(u, y, t, p, row.data());
      double pred = 0.0;
      for (int c = 0; c < 2 * p; ++c) pred += theta[c] * row[c];
      e[t] = y[t] - pred;
    }
  return e;
}

// Pseudo-inverse by SVD with a relative threshold.
Eigen::MatrixXd pinv(const Eigen::MatrixXd& M) {
  Eigen::BDCSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  const double tol = std::max(M.rows(), M.cols()) * std::numeric_limits<double>::epsilon() * (s.size() ? s[0] : 0.0);
  Eigen::VectorXd inv = s;
  for (Eigen::Index i = 0; i < s.size(); ++i) inv[i] = s[i] > tol ? 1.0 / s[i] : 0.0;
  return svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose();
}

// Symmetric positive semi-definite S to the power -1/2 (directions of no variance left out).
Eigen::MatrixXd inverseSqrt(const Eigen::MatrixXd& S, Eigen::MatrixXd* sqrtOut) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(S);
  Eigen::VectorXd l = es.eigenvalues(), li = l, ls = l;
  const double top = l.size() ? l.maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < l.size(); ++i) {
    const bool keep = l[i] > 1e-12 * top;
    li[i] = keep ? 1.0 / std::sqrt(l[i]) : 0.0;
    ls[i] = keep ? std::sqrt(l[i]) : 0.0;
  }
  if (sqrtOut) *sqrtOut = es.eigenvectors() * ls.asDiagonal() * es.eigenvectors().transpose();
  return es.eigenvectors() * li.asDiagonal() * es.eigenvectors().transpose();
}

// The weighted matrix of the open-loop family, its SVD, and W1^{-1} for Gamma_f. Rows of the
// data matrix at time t: [u(t..t+f-1), past (2p), y(t..t+f-1)], factored as L Q.
struct ObliqueSvd {
  Eigen::MatrixXd U;       // left singular vectors
  Eigen::VectorXd s;       // singular values
  Eigen::MatrixXd W1inv;   // f x f
  Eigen::MatrixXd past;    // f x 2p: O_i = past * W_p, the oblique projection from the past data
};

ObliqueSvd obliqueSvd(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const std::vector<Segment>& segs, int p,
                      int f, SubspaceMethod method) {
  const std::vector<Eigen::Index> times = columnTimes(segs, p, f);
  const Eigen::Index j = static_cast<Eigen::Index>(times.size());
  const int cols = 2 * p + 2 * f;
  Eigen::MatrixXd D(j, cols);
  std::vector<double> row(2 * p);
  for (Eigen::Index r = 0; r < j; ++r) {
    const Eigen::Index t = times[r];
    for (int i = 0; i < f; ++i) D(r, i) = u[t + i];
    pastRow(u, y, t, p, row.data());
    for (int c = 0; c < 2 * p; ++c) D(r, f + c) = row[c];
    for (int i = 0; i < f; ++i) D(r, f + 2 * p + i) = y[t + i];
  }
  D /= std::sqrt(static_cast<double>(j));
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(D);
  const Eigen::MatrixXd L = qr.matrixQR().topRows(cols).triangularView<Eigen::Upper>().toDenseMatrix().transpose();
  const Eigen::MatrixXd L21 = L.block(f, 0, 2 * p, f), L22 = L.block(f, f, 2 * p, 2 * p);
  const Eigen::MatrixXd L32 = L.block(f + 2 * p, f, f, 2 * p), L33 = L.block(f + 2 * p, f + 2 * p, f, f);
  const Eigen::MatrixXd proj = L32 * pinv(L22);  // Y_f /_{U_f} W_p = proj * W_p
  Eigen::MatrixXd M;
  ObliqueSvd out;
  out.past = proj;
  out.W1inv = Eigen::MatrixXd::Identity(f, f);
  if (method == SubspaceMethod::N4sid) {
    M.resize(f, f + 2 * p);
    M << proj * L21, proj * L22;  // W_p's coordinates on Q
  } else {
    M = proj * L22;  // with W2 = Pi_{U_f}^perp: the part of W_p orthogonal to U_f
    if (method == SubspaceMethod::Cva) {
      const Eigen::MatrixXd S = L32 * L32.transpose() + L33 * L33.transpose();
      Eigen::MatrixXd sq;
      const Eigen::MatrixXd W1 = inverseSqrt(S, &sq);
      M = W1 * M;
      out.W1inv = sq;
    }
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU);
  out.U = svd.matrixU();
  out.s = svd.singularValues();
  return out;
}

// B, K and the initial state of every experiment by least squares on
// y(t) = C^T (qI - A)^{-1} (B u(t) + K e(t)) + C^T A^(t - t0) x0 + e(t), t >= t0 = p.
bool outputRegression(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const Eigen::VectorXd& e,
                      const std::vector<Segment>& segs, int p, InnovationsModel& m) {
  const int n = m.order();
  Eigen::Index rows = 0;
  for (const auto& g : segs) rows += std::max<Eigen::Index>(0, g.n - p);
  const int cols = 2 * n + n * static_cast<int>(segs.size());
  if (rows <= cols) return false;
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Zero(rows, cols);
  Eigen::VectorXd rhs(rows);
  Eigen::Index at = 0;
  const Eigen::RowVectorXd ct = m.C.transpose();
  for (std::size_t s = 0; s < segs.size(); ++s) {
    const auto& g = segs[s];
    if (g.n <= p) continue;
    const Eigen::Index len = g.n - p;
    // x_u(t+1) = A x_u + I u(t): column i of the state's response to u through B = e_i.
    Eigen::MatrixXd Xu = Eigen::MatrixXd::Zero(n, n), Xe = Eigen::MatrixXd::Zero(n, n);
    Eigen::MatrixXd Ak = Eigen::MatrixXd::Identity(n, n);
    for (Eigen::Index k = 0; k < len; ++k) {
      const Eigen::Index t = g.from + p + k;
      Phi.block(at + k, 0, 1, n) = ct * Xu;
      Phi.block(at + k, n, 1, n) = ct * Xe;
      Phi.block(at + k, 2 * n + n * static_cast<Eigen::Index>(s), 1, n) = ct * Ak;
      rhs[at + k] = y[t] - e[t];
      Xu = m.A * Xu;
      Xu.diagonal().array() += u[t];
      Xe = m.A * Xe;
      Xe.diagonal().array() += e[t];
      Ak = m.A * Ak;
      if (!Ak.allFinite() || !Xu.allFinite()) return false;
    }
    at += len;
  }
  // Columns of very different scale (an integrator's free response grows) are balanced.
  Eigen::VectorXd scale = Phi.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < scale.size(); ++c) scale[c] = scale[c] > 0.0 ? scale[c] : 1.0;
  const Eigen::MatrixXd Phis = Phi * scale.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Phis);
  const Eigen::VectorXd th = qr.solve(rhs).cwiseQuotient(scale);
  if (!th.allFinite()) return false;
  m.B = th.head(n);
  m.K = th.segment(n, n);
  return true;
}

bool gainFromStates(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const std::vector<Segment>& segs,
                    const Eigen::MatrixXd& T, int p, InnovationsModel& m);

// The predictor route (PBSID-opt): the state sequence from the ARX predictor's Markov
// parameters, then C and [A B] by least squares (with the innovations as a regressor) and K
// from the Riccati equation. The data matrix and its SVD are formed once, for every order.
class PredictorRoute {
 public:
  PredictorRoute(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const std::vector<Segment>& segs,
                 const Eigen::VectorXd& theta, int p, int f)
      : u_(u), y_(y), segs_(segs), p_(p), times_(columnTimes(segs, p, 1)) {
    // M[i, k] = Phi_{i+k-1}, i = 1..f, k = 1..p (zero beyond p): Gamma~_f times the map from
    // the past to the state.
    M_ = Eigen::MatrixXd::Zero(f, 2 * p);
    for (int i = 1; i <= f; ++i)
      for (int k = 1; i + k - 1 <= p; ++k) {
        const int lag = i + k - 1;
        M_(i - 1, 2 * (k - 1)) = theta[2 * (lag - 1)];
        M_(i - 1, 2 * (k - 1) + 1) = theta[2 * (lag - 1) + 1];
      }
    const Eigen::Index j = static_cast<Eigen::Index>(times_.size());
    Zp_.resize(2 * p, j);
    std::vector<double> row(2 * p);
    for (Eigen::Index r = 0; r < j; ++r) {
      pastRow(u, y, times_[r], p, row.data());
      for (int c = 0; c < 2 * p; ++c) Zp_(c, r) = row[c];
    }
    // Weighted by the past's covariance so the SVD is that of M Z_p.
    Eigen::MatrixXd sq;
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(2 * p, 2 * p);
    cov.selfadjointView<Eigen::Lower>().rankUpdate(Zp_);
    inverseSqrt(Eigen::MatrixXd(cov.selfadjointView<Eigen::Lower>()) / static_cast<double>(j), &sq);
    Eigen::BDCSVD<Eigen::MatrixXd> svd(M_ * sq, Eigen::ComputeThinU);
    U_ = svd.matrixU();
    s_ = svd.singularValues();
  }
  const Eigen::VectorXd& singularValues() const { return s_; }

  bool model(int n, InnovationsModel& m) const {
    if (s_.size() < n || !(s_[n - 1] > 0.0)) return false;
    const Eigen::MatrixXd T = s_.head(n).cwiseSqrt().cwiseInverse().asDiagonal() * U_.leftCols(n).transpose() * M_;
    const Eigen::MatrixXd X = T * Zp_;  // the state at every column time
    const Eigen::Index j = X.cols();
    Eigen::VectorXd yt(j), ut(j);
    for (Eigen::Index r = 0; r < j; ++r) {
      yt[r] = y_[times_[r]];
      ut[r] = u_[times_[r]];
    }
    // y(t) = C^T x(t) + e(t).
    const Eigen::VectorXd c = X.transpose().colPivHouseholderQr().solve(yt);
    const Eigen::VectorXd e = yt - X.transpose() * c;
    // x(t+1) = A x(t) + B u(t) + K e(t), over consecutive columns of one experiment.
    std::vector<Eigen::Index> pairs;
    for (Eigen::Index r = 0; r + 1 < j; ++r)
      if (times_[r + 1] == times_[r] + 1) pairs.push_back(r);
    const Eigen::Index np = static_cast<Eigen::Index>(pairs.size());
    if (np <= n + 2) return false;
    Eigen::MatrixXd Phi(np, n + 2), Next(np, n);
    for (Eigen::Index i = 0; i < np; ++i) {
      const Eigen::Index r = pairs[i];
      Phi.row(i) << X.col(r).transpose(), ut[r], e[r];
      Next.row(i) = X.col(r + 1).transpose();
    }
    const Eigen::MatrixXd th = Phi.colPivHouseholderQr().solve(Next);  // (n + 2) x n
    if (!th.allFinite() || !c.allFinite()) return false;
    m.A = th.topRows(n).transpose();
    m.B = th.row(n).transpose();
    m.C = c;
    // K from the noise covariances by the Riccati equation: a stable predictor at every
    // order, as on the open-loop route (the regression's own K need not be one when n is
    // too small).
    return gainFromStates(u_, y_, segs_, T, p_, m);
  }

 private:
  const Eigen::VectorXd& u_;
  const Eigen::VectorXd& y_;
  const std::vector<Segment>& segs_;
  int p_;
  std::vector<Eigen::Index> times_;
  Eigen::MatrixXd M_, Zp_, U_;
  Eigen::VectorXd s_;
};

// Largest eigenvalue magnitude.
double spectralRadius(const Eigen::MatrixXd& A) {
  if (A.rows() == 0) return 0.0;
  Eigen::EigenSolver<Eigen::MatrixXd> es(A, false);
  return es.eigenvalues().cwiseAbs().maxCoeff();
}

// The stabilizing solution P of the filter Riccati equation
//   P = A P A^T + Q - (A P C + S)(C^T P C + R)^{-1} (A P C + S)^T
// by the structure-preserving doubling algorithm on its control form (A - S C^T / R)^T, C, and
// the predictor gain K = (A P C + S) / (C^T P C + R). Empty when it does not converge.
Eigen::VectorXd kalmanGain(const Eigen::MatrixXd& A, const Eigen::VectorXd& C, const Eigen::MatrixXd& Q,
                           const Eigen::VectorXd& S, double R) {
  const Eigen::Index n = A.rows();
  if (!(R > 0.0)) return {};
  const Eigen::MatrixXd Ab = A - S * C.transpose() / R;
  Eigen::MatrixXd Qb = Q - S * S.transpose() / R;
  // A covariance estimate may come out slightly indefinite: its negative part is dropped.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Qb + Qb.transpose()));
  Qb = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
  Eigen::MatrixXd Ak = Ab.transpose(), G = C * C.transpose() / R, H = Qb;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  for (int k = 0; k < 60; ++k) {
    const Eigen::PartialPivLU<Eigen::MatrixXd> W(I + G * H);
    const Eigen::MatrixXd WA = W.solve(Ak), WG = W.solve(G);
    const Eigen::MatrixXd Hn = H + Ak.transpose() * H * WA;
    G = G + Ak * WG * Ak.transpose();
    Ak = Ak * WA;
    const double change = (Hn - H).norm(), size = Hn.norm();
    H = 0.5 * (Hn + Hn.transpose());
    if (!H.allFinite()) return {};
    if (change <= 1e-12 * std::max(size, 1e-300)) break;
  }
  const Eigen::MatrixXd& P = H;
  const double innovation = C.dot(P * C) + R;
  const Eigen::VectorXd K = (A * P * C + S) / innovation;
  return K.allFinite() ? K : Eigen::VectorXd();
}

// The noise of the innovations model from the states the past data give: the residuals
// w = x(t+1) - A x(t) - B u(t), v = y(t) - C^T x(t) over consecutive samples of each
// experiment, their covariances Q, S, R, and K from the Riccati equation, so that the
// predictor A - K C^T is stable.
bool gainFromStates(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const std::vector<Segment>& segs,
                    const Eigen::MatrixXd& T, int p, InnovationsModel& m) {
  const std::vector<Eigen::Index> times = columnTimes(segs, p, 1);
  const Eigen::Index j = static_cast<Eigen::Index>(times.size());
  const int n = m.order();
  Eigen::MatrixXd X(n, j);
  std::vector<double> row(2 * p);
  Eigen::Map<const Eigen::VectorXd> z(row.data(), 2 * p);
  for (Eigen::Index r = 0; r < j; ++r) {
    pastRow(u, y, times[r], p, row.data());
    X.col(r) = T * z;
  }
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd S = Eigen::VectorXd::Zero(n);
  double R = 0.0;
  Eigen::Index count = 0;
  for (Eigen::Index r = 0; r + 1 < j; ++r) {
    if (times[r + 1] != times[r] + 1) continue;
    const Eigen::VectorXd w = X.col(r + 1) - m.A * X.col(r) - m.B * u[times[r]];
    const double v = y[times[r]] - m.C.dot(X.col(r));
    Q += w * w.transpose();
    S += w * v;
    R += v * v;
    ++count;
  }
  if (count <= n) return false;
  const double c = static_cast<double>(count);
  m.K = kalmanGain(m.A, m.C, Q / c, S / c, R / c);
  return m.K.size() == n;
}

// A from the shift invariance of Gamma_f (rows 1..f-1 times A = rows 2..f), C its first row.
void fromObservability(const Eigen::MatrixXd& Gamma, InnovationsModel& m) {
  const Eigen::Index f = Gamma.rows();
  m.A = Gamma.topRows(f - 1).colPivHouseholderQr().solve(Gamma.bottomRows(f - 1));
  m.C = Gamma.row(0).transpose();
}

// Monic characteristic polynomial in q^{-1}: det(I - M q^{-1}).
Poly characteristic(const Eigen::MatrixXd& M) {
  if (M.rows() == 0) return {1.0};
  Eigen::EigenSolver<Eigen::MatrixXd> es(M, false);
  std::vector<std::complex<double>> roots;
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) roots.push_back(es.eigenvalues()[i]);
  return polyFromRoots(roots);
}

double mdlOf(double loss, int n, Eigen::Index rows) {
  const double N = static_cast<double>(rows);
  return N * std::log(std::max(loss, 1e-300)) + 3.0 * n * std::log(N);
}

}  // namespace

PolynomialModel InnovationsModel::polynomial() const {
  const int n = order();
  PolyOrders o;
  o.na = o.nb = o.nc = n;
  o.nk = 1;
  PolynomialModel p = PolynomialModel::zero(PolyStructure::Ss, o, sampleTime);
  const Poly a = characteristic(A);
  const Poly c = characteristic(A - K * C.transpose());
  const Poly b = characteristic(A - B * C.transpose());
  for (int k = 1; k <= n; ++k) {
    p.a[k] = a[k];
    p.c[k] = c[k];
    p.b[k] = b[k] - a[k];  // b[0] = 0: the delay nk = 1
  }
  p.noiseVariance = noiseVariance;
  return p;
}

Eigen::VectorXd innovationErrors(const InnovationsModel& m, const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
  if (u.size() != y.size()) throw std::invalid_argument("innovationErrors: u and y differ in length");
  const Eigen::MatrixXd At = m.A - m.K * m.C.transpose();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m.order());
  Eigen::VectorXd e(y.size());
  for (Eigen::Index t = 0; t < y.size(); ++t) {
    e[t] = y[t] - m.C.dot(x);
    x = At * x + m.B * u[t] + m.K * y[t];
  }
  return e;
}

SubspaceEstimate subspaceEstimate(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double sampleTime,
                                  const SubspaceOptions& options) {
  if (u.size() != y.size()) throw std::invalid_argument("subspace: u and y must have the same number of samples");
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("subspace: " + why);
  const std::vector<Segment> segs = experimentSegments(options.experimentLengths, y.size());
  SubspaceEstimate r;
  r.method = options.method != SubspaceMethod::Auto ? options.method
             : options.closedLoop                   ? SubspaceMethod::Pbsid
                                                    : SubspaceMethod::Cva;
  if (!u.allFinite() || !y.allFinite()) {
    r.message = "the data contain NaN or infinite values";
    return r;
  }
  const int nmax = options.order > 0 ? options.order : options.maxOrder;
  Eigen::Index longest = 0, total = 0;
  for (const auto& g : segs) {
    longest = std::max(longest, g.n);
    total += g.n;
  }
  // Horizon: the ARX order of least AIC in [nmax + 1, pmax], from one nested QR.
  const int pmax = options.horizon > 0 ? options.horizon
                                       : static_cast<int>(std::min<Eigen::Index>(SubspaceOptions::kMaxHorizon,
                                                                                 std::max<Eigen::Index>(nmax + 1, total / 20)));
  if (longest < 2 * pmax + 10 * nmax + 20 || total < 40 * (nmax + 1)) {
    r.message = "too few samples (" + std::to_string(total) + ") for a state-space model of order up to " +
                std::to_string(nmax) + " with a horizon of " + std::to_string(pmax) +
                " samples; lower the order or give a longer record";
    return r;
  }
  const ArxLadder ladder = arxLadder(u, y, segs, pmax);
  int p = pmax;
  if (options.horizon == 0) {
    double best = std::numeric_limits<double>::infinity();
    for (int q = nmax + 1; q <= pmax; ++q) {
      const double v = ladder.rss(q) / static_cast<double>(ladder.rows);
      const double aic = static_cast<double>(ladder.rows) * std::log(std::max(v, 1e-300)) + 2.0 * (2 * q);
      if (aic < best) {
        best = aic;
        p = q;
      }
    }
  }
  r.horizon = p;
  const int f = p;
  const Eigen::VectorXd theta = ladder.theta(p);
  if (!theta.allFinite()) {
    r.message = "the high-order ARX model is singular: the input does not excite the system enough";
    return r;
  }
  const Eigen::VectorXd ehat = arxInnovations(u, y, segs, theta, p);

  // The model of each order.
  ObliqueSvd oblique;
  Eigen::VectorXd singular;
  std::optional<PredictorRoute> predictor;
  if (r.method == SubspaceMethod::Pbsid) {
    predictor.emplace(u, y, segs, theta, p, f);
    singular = predictor->singularValues();
  } else {
    oblique = obliqueSvd(u, y, segs, p, f, r.method);
    singular = oblique.s;
  }
  r.singularValues.assign(singular.data(), singular.data() + singular.size());
  auto modelOf = [&](int n, InnovationsModel& m) {
    m.sampleTime = sampleTime;
    if (predictor) return predictor->model(n, m);
    if (oblique.U.cols() < n) return false;
    const Eigen::MatrixXd Gamma =
        oblique.W1inv * oblique.U.leftCols(n) * oblique.s.head(n).cwiseSqrt().asDiagonal();
    fromObservability(Gamma, m);
    if (!m.A.allFinite() || !outputRegression(u, y, ehat, segs, p, m)) return false;
    // The states Gamma^+ O_i of the past data give the noise covariances and K.
    const Eigen::MatrixXd T = Gamma.completeOrthogonalDecomposition().pseudoInverse() * oblique.past;
    return gainFromStates(u, y, segs, T, p, m);
  };
  const int first = options.order > 0 ? options.order : 1;
  double bestMdl = std::numeric_limits<double>::infinity();
  Eigen::Index rows = 0;
  for (const auto& g : segs) rows += std::max<Eigen::Index>(0, g.n - p);
  for (int n = first; n <= nmax; ++n) {
    InnovationsModel m;
    if (!modelOf(n, m)) continue;
    // The loss from sample p of each experiment on, where the predictor has forgotten its
    // zero start.
    double sum = 0.0;
    for (const auto& g : segs) {
      const Eigen::VectorXd e = innovationErrors(m, u.segment(g.from, g.n), y.segment(g.from, g.n));
      if (g.n > p) sum += e.tail(g.n - p).squaredNorm();
    }
    SubspaceOrder o;
    o.order = n;
    o.loss = sum / static_cast<double>(rows);
    o.stablePredictor = spectralRadius(m.A - m.K * m.C.transpose()) < 1.0;
    o.mdl = std::isfinite(o.loss) && o.stablePredictor ? mdlOf(o.loss, n, rows)
                                                       : std::numeric_limits<double>::infinity();
    r.orders.push_back(o);
    if (o.mdl < bestMdl || (r.chosenOrder == 0 && options.order > 0)) {
      bestMdl = o.mdl;
      r.chosenOrder = n;
      m.noiseVariance = o.loss;
      r.model = m;
    }
  }
  if (r.chosenOrder == 0) {
    r.message = "no state-space model of order " +
                (options.order > 0 ? std::to_string(options.order) : "1 to " + std::to_string(nmax)) +
                " could be formed from the data (the input does not excite enough states)";
    return r;
  }
  // Why this order: the criterion, and the singular values around it.
  const auto sv = [&](int k) { return k >= 1 && k <= static_cast<int>(r.singularValues.size()) ? r.singularValues[k - 1] : 0.0; };
  std::string reason = "n = " + std::to_string(r.chosenOrder) + ": ";
  if (options.order > 0) {
    reason += "as asked";
  } else {
    reason += "least MDL of orders 1-" + std::to_string(nmax);
  }
  const int n = r.chosenOrder;
  if (options.order == 0 && n == nmax)
    reason += ", the largest tried: the data ask for more states than that (noise the innovations model "
              "must describe as well as the plant); give ss:N to fix the order";
  if (sv(n + 1) > 0.0)
    reason += "; singular value " + std::to_string(n) + " is " + shortNumber(sv(n) / sv(n + 1)) + " times the next";
  // The singular values' own suggestion: where they drop most (log scale) among the orders tried.
  int drop = 0;
  double most = 0.0;
  for (int k = 1; k <= nmax && sv(k + 1) > 0.0; ++k)
    if (sv(k) / sv(k + 1) > most) {
      most = sv(k) / sv(k + 1);
      drop = k;
    }
  if (drop > 0 && drop != n)
    reason += "; they drop most after n = " + std::to_string(drop) + " (" + shortNumber(most) + " times)";
  r.orderReason = reason;
  r.ok = true;
  return r;
}

}  // namespace flexarm
