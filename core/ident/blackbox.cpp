#include "core/ident/blackbox.h"

#include "core/ident/levenberg_marquardt.h"
#include "core/ident/experiment_segments.h"
#include "core/ident/poly_predictor.h"
#include "core/ident/subspace.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace flexarm {

const char* toString(PolyStructure s) {
  switch (s) {
    case PolyStructure::Arx: return "arx";
    case PolyStructure::Armax: return "armax";
    case PolyStructure::Oe: return "oe";
    case PolyStructure::Bj: return "bj";
    case PolyStructure::Ss: return "ss";
  }
  return "arx";
}

std::optional<PolyStructure> polyStructureFromString(std::string_view s) {
  for (auto v : {PolyStructure::Arx, PolyStructure::Armax, PolyStructure::Oe, PolyStructure::Bj, PolyStructure::Ss})
    if (s == toString(v)) return v;
  return std::nullopt;
}

const char* toString(PolyOrder o) {
  switch (o) {
    case PolyOrder::Na: return "na";
    case PolyOrder::Nb: return "nb";
    case PolyOrder::Nc: return "nc";
    case PolyOrder::Nd: return "nd";
    case PolyOrder::Nf: return "nf";
    case PolyOrder::Nk: return "nk";
  }
  return "na";
}

const std::vector<PolyOrder>& polyOrdersOf(PolyStructure s) {
  using O = PolyOrder;
  static const std::vector<PolyOrder> kArx{O::Na, O::Nb, O::Nk}, kArmax{O::Na, O::Nb, O::Nc, O::Nk},
      kOe{O::Nb, O::Nf, O::Nk}, kBj{O::Nb, O::Nc, O::Nd, O::Nf, O::Nk}, kSs{O::Na};
  switch (s) {
    case PolyStructure::Arx: return kArx;
    case PolyStructure::Armax: return kArmax;
    case PolyStructure::Oe: return kOe;
    case PolyStructure::Bj: return kBj;
    case PolyStructure::Ss: return kSs;
  }
  return kArx;
}

bool takesOrder(PolyStructure s, PolyOrder o) {
  const auto& list = polyOrdersOf(s);
  return std::find(list.begin(), list.end(), o) != list.end();
}

int& PolyOrders::operator[](PolyOrder o) {
  switch (o) {
    case PolyOrder::Na: return na;
    case PolyOrder::Nb: return nb;
    case PolyOrder::Nc: return nc;
    case PolyOrder::Nd: return nd;
    case PolyOrder::Nf: return nf;
    case PolyOrder::Nk: return nk;
  }
  return na;
}

int PolyOrders::operator[](PolyOrder o) const { return (*const_cast<PolyOrders*>(this))[o]; }

PolyOrders PolyOrders::stateSpace(int n) {
  PolyOrders o{0, 0, 0, 0, 0, 0};
  o.na = o.nc = n;
  o.nb = std::max(1, n);
  o.nk = 1;
  return o;
}

PolyOrders PolyOrders::of(PolyStructure s) const {
  if (s == PolyStructure::Ss) return stateSpace(na);
  PolyOrders out{0, 0, 0, 0, 0, 0};
  for (PolyOrder o : polyOrdersOf(s)) out[o] = (*this)[o];
  return out;
}

int PolyOrders::parameters() const {
  const long long sum = static_cast<long long>(na) + nb + nc + nd + nf;
  return static_cast<int>(std::min<long long>(sum, std::numeric_limits<int>::max()));
}

bool PolyOrders::isValid(std::string* why) const {
  auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (na < 0 || nb < 0 || nc < 0 || nd < 0 || nf < 0) return fail("orders must not be negative");
  if (nb < 1) return fail("nb must be at least 1");
  if (nk < 0) return fail("the delay nk must not be negative");
  if (std::max({na, nb, nc, nd, nf}) > kMaxOrder || parameters() > kMaxOrder)
    return fail("more than " + std::to_string(kMaxOrder) + " parameters");
  if (nk > kMaxDelay) return fail("the delay nk is more than " + std::to_string(kMaxDelay) + " samples");
  return true;
}

namespace {
// Least-squares work (rows x parameters^2) allowed: ARX solves once, the iterative structures
// once per iteration (up to 100 by default). Both are a few seconds to a minute here.
constexpr double kMaxArxWork = 2e10;
constexpr double kMaxIterativeWork = 2e9;

// First sample at which every regressor holds data: the prediction-error criterion starts here.
int criterionStart(const PolyOrders& o) {
  return static_cast<int>(
      PolyPredictor::criterionStart(o, std::numeric_limits<Eigen::Index>::max()));
}
}  // namespace

bool PolyOrders::fitsData(PolyStructure s, long long samples, std::string* why) const {
  std::string bad;
  if (!isValid(&bad)) {
    if (why) *why = bad;
    return false;
  }
  const long long p = parameters();
  const long long rows = samples - criterionStart(*this);
  const bool iterative = s != PolyStructure::Arx;
  const long long needed = iterative ? 2 * p + 21 : p + 1;
  if (rows < needed) {
    if (why)
      *why = "too few samples (" + std::to_string(samples) + ") for " + std::to_string(p) +
             " parameters with the delay nk = " + std::to_string(nk) + ": the estimate needs at least " +
             std::to_string(needed + samples - rows) + "; lower the orders or the delay";
    return false;
  }
  const double work = static_cast<double>(rows) * static_cast<double>(p) * static_cast<double>(p);
  const double limit = iterative ? kMaxIterativeWork : kMaxArxWork;
  if (work > limit) {
    if (why) {
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "%s with %lld parameters on %lld samples is a least-squares problem of "
                    "%.2g operations%s, more than the %.0e FlexArm allows (minutes of work); "
                    "lower the orders or decimate the data",
                    toString(s), p, samples, work, iterative ? " per iteration" : "", limit);
      *why = buf;
    }
    return false;
  }
  return true;
}

bool PolyEstimateOptions::isValid(std::string* why) const {
  if (maxIterations < 0 || !(relativeTolerance > 0.0) || !(initialDamping > 0.0)) {
    if (why) *why = "maxIterations >= 0, relativeTolerance > 0 and initialDamping > 0 required";
    return false;
  }
  for (Eigen::Index n : experimentLengths)
    if (n < 1) {
      if (why) *why = "every experiment needs at least one sample";
      return false;
    }
  return true;
}

std::string PolynomialModel::name() const {
  if (structure == PolyStructure::Ss && orders.na == 0) return "ss";
  std::ostringstream s;
  s << toString(structure) << "[";
  const char* gap = "";
  for (PolyOrder o : polyOrdersOf(structure)) {
    s << gap << orders[o];
    gap = " ";
  }
  s << "]";
  return s.str();
}

PolynomialModel PolynomialModel::zero(PolyStructure s, const PolyOrders& o, double ts) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("PolynomialModel: " + why);
  PolynomialModel m;
  m.structure = s;
  m.orders = o;
  m.sampleTime = ts;
  m.a.assign(o.na + 1, 0.0);
  m.a[0] = 1.0;
  m.b.assign(o.nk + o.nb, 0.0);
  m.c.assign(o.nc + 1, 0.0);
  m.c[0] = 1.0;
  m.d.assign(o.nd + 1, 0.0);
  m.d[0] = 1.0;
  m.f.assign(o.nf + 1, 0.0);
  m.f[0] = 1.0;
  return m;
}

Eigen::VectorXd PolynomialModel::parameterVector() const {
  Eigen::VectorXd th(orders.parameters());
  int i = 0;
  for (int k = 1; k <= orders.na; ++k) th[i++] = a[k];
  for (int k = 0; k < orders.nb; ++k) th[i++] = b[orders.nk + k];
  for (int k = 1; k <= orders.nc; ++k) th[i++] = c[k];
  for (int k = 1; k <= orders.nd; ++k) th[i++] = d[k];
  for (int k = 1; k <= orders.nf; ++k) th[i++] = f[k];
  return th;
}

void PolynomialModel::setParameterVector(const Eigen::VectorXd& th) {
  if (th.size() != orders.parameters())
    throw std::invalid_argument("PolynomialModel: parameter vector of the wrong length");
  int i = 0;
  for (int k = 1; k <= orders.na; ++k) a[k] = th[i++];
  for (int k = 0; k < orders.nb; ++k) b[orders.nk + k] = th[i++];
  for (int k = 1; k <= orders.nc; ++k) c[k] = th[i++];
  for (int k = 1; k <= orders.nd; ++k) d[k] = th[i++];
  for (int k = 1; k <= orders.nf; ++k) f[k] = th[i++];
}

std::vector<std::string> PolynomialModel::parameterNames() const {
  std::vector<std::string> n;
  auto add = [&](const char* p, int count) {
    for (int k = 1; k <= count; ++k) n.push_back(p + std::to_string(k));
  };
  add("a", orders.na);
  add("b", orders.nb);
  add("c", orders.nc);
  add("d", orders.nd);
  add("f", orders.nf);
  return n;
}

Eigen::VectorXd PolynomialModel::standardDeviations() const {
  if (covariance.size() == 0) return {};
  return covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void checkData(const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
  if (u.size() != y.size())
    throw std::invalid_argument("input and output must have the same number of samples");
}

using Segment = ExperimentSegment;


// Regression matrix whose columns are sign * signal(t - lag), rows t = first..N-1.
struct Block {
  const Eigen::VectorXd* signal;
  double sign;
  int firstLag;
  int count;
};

Eigen::MatrixXd regressors(const std::vector<Block>& blocks, Eigen::Index first, Eigen::Index n) {
  int cols = 0;
  for (const auto& b : blocks) cols += b.count;
  Eigen::MatrixXd phi(n - first, cols);
  int c = 0;
  for (const auto& b : blocks)
    for (int j = 0; j < b.count; ++j, ++c) {
      const int lag = b.firstLag + j;
      for (Eigen::Index t = first; t < n; ++t)
        phi(t - first, c) = t - lag >= 0 ? b.sign * (*b.signal)[t - lag] : 0.0;
    }
  return phi;
}


bool stabilize(PolynomialModel& m) {
  bool changed = false;
  changed |= reflectIntoUnitCircle(m.c);
  changed |= reflectIntoUnitCircle(m.d);
  changed |= reflectIntoUnitCircle(m.f);
  return changed;
}

double oeLoss(const PolynomialModel& m, const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
  return (y - filter(m.b, m.f, u)).squaredNorm();
}

// Least squares on regressors via column-pivoting QR; empty when rank deficient.
Eigen::VectorXd leastSquares(const Eigen::MatrixXd& phi, const Eigen::VectorXd& rhs) {
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(phi);
  if (qr.rank() < phi.cols()) return {};
  return qr.solve(rhs);
}

// Noise model C/D of an ARMA process v by Hannan-Rissanen: a long AR model gives estimates of
// e, then D v = C e is solved by least squares.
void armaInit(const Eigen::VectorXd& v, PolynomialModel& m) {
  const int nc = m.orders.nc, nd = m.orders.nd;
  if (nc == 0 && nd == 0) return;
  const Eigen::Index n = v.size();
  const int nh = static_cast<int>(std::min<Eigen::Index>(std::max(20, 3 * (nc + nd)), n / 10));
  Eigen::VectorXd ehat = v;
  if (nh > 0) {
    Eigen::VectorXd th = leastSquares(regressors({{&v, -1.0, 1, nh}}, nh, n), v.tail(n - nh));
    if (th.size()) {
      Poly ar(nh + 1, 1.0);
      for (int k = 0; k < nh; ++k) ar[k + 1] = th[k];
      ehat = filter(ar, {1.0}, v);
    }
  }
  const int first = std::max({nc, nd, nh});
  Eigen::VectorXd th = leastSquares(regressors({{&v, -1.0, 1, nd}, {&ehat, 1.0, 1, nc}}, first, n),
                                    v.tail(n - first));
  if (!th.size()) return;
  for (int k = 0; k < nd; ++k) m.d[k + 1] = th[k];
  for (int k = 0; k < nc; ++k) m.c[k + 1] = th[nd + k];
}

// B/F from ARX followed by instrumental variables with the ARX simulation as instruments.
void oeInit(const Eigen::VectorXd& u, const Eigen::VectorXd& y, PolynomialModel& m) {
  const auto& o = m.orders;
  PolyEstimate a0 = arx(u, y, o.nf, o.nb, o.nk, m.sampleTime);
  PolynomialModel best = m;
  for (int k = 1; k <= o.nf; ++k) best.f[k] = a0.model.a[k];
  for (int j = 0; j < o.nb; ++j) best.b[o.nk + j] = a0.model.b[o.nk + j];
  reflectIntoUnitCircle(best.f);
  double bestLoss = oeLoss(best, u, y);
  PolynomialModel cur = best;
  const Eigen::Index n = y.size();
  const int first = std::max(o.nf, o.nb + o.nk - 1);
  for (int iter = 0; iter < 3; ++iter) {
    const Eigen::VectorXd x = filter(cur.b, cur.f, u);
    const Eigen::MatrixXd phi =
        regressors({{&y, -1.0, 1, o.nf}, {&u, 1.0, o.nk, o.nb}}, first, n);
    const Eigen::MatrixXd zeta =
        regressors({{&x, -1.0, 1, o.nf}, {&u, 1.0, o.nk, o.nb}}, first, n);
    Eigen::VectorXd th = leastSquares(zeta.transpose() * phi, zeta.transpose() * y.tail(n - first));
    if (!th.size() || !th.allFinite()) break;
    for (int k = 0; k < o.nf; ++k) cur.f[k + 1] = th[k];
    for (int j = 0; j < o.nb; ++j) cur.b[o.nk + j] = th[o.nf + j];
    reflectIntoUnitCircle(cur.f);
    const double l = oeLoss(cur, u, y);
    if (std::isfinite(l) && l < bestLoss) {
      bestLoss = l;
      best = cur;
    }
  }
  m.b = best.b;
  m.f = best.f;
}

PolynomialModel initialModel(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                             PolyStructure s, const PolyOrders& o, double ts) {
  PolynomialModel m = PolynomialModel::zero(s, o, ts);
  const Eigen::Index n = y.size();
  if (s == PolyStructure::Armax) {
    const int nh = static_cast<int>(
        std::min<Eigen::Index>(std::max(20, 2 * (o.na + o.nc + o.nb)), n / 10));
    PolyEstimate high = arx(u, y, nh, nh, o.nk, ts);
    const Eigen::VectorXd ehat = predictionErrors(high.model, u, y);
    const int first = std::max({o.na, o.nb + o.nk - 1, o.nc, nh});
    Eigen::VectorXd th = leastSquares(
        regressors({{&y, -1.0, 1, o.na}, {&u, 1.0, o.nk, o.nb}, {&ehat, 1.0, 1, o.nc}}, first, n),
        y.tail(n - first));
    if (th.size()) m.setParameterVector(th);
    reflectIntoUnitCircle(m.c);
    // The plain ARX estimate (C = 1) is a candidate too: on nearly noise-free data the
    // estimated innovations are poor and the ARX start is the better one.
    PolynomialModel plain = PolynomialModel::zero(s, o, ts);
    const PolyEstimate a0 = arx(u, y, o.na, o.nb, o.nk, ts);
    if (a0.summary.ok()) {
      plain.a = a0.model.a;
      plain.b = a0.model.b;
      PolyPredictor predictor(u, y, o);
      const double lm = predictor.run(m), lp = predictor.run(plain);
      if (!(lm <= lp)) return plain;
    }
    return m;
  }
  oeInit(u, y, m);
  if (s == PolyStructure::Bj && (o.nc > 0 || o.nd > 0)) {
    // Refine B/F as an output-error model first, then model its residual as ARMA.
    PolynomialModel oem = PolynomialModel::zero(PolyStructure::Oe, o, ts);
    oem.orders.nc = oem.orders.nd = 0;
    oem.c = oem.d = Poly{1.0};
    oem.b = m.b;
    oem.f = m.f;
    PolyEstimateOptions opt;
    opt.maxIterations = 30;
    PolyEstimate r = refinePolynomial(u, y, oem, opt);
    if (r.summary.ok()) {
      m.b = r.model.b;
      m.f = r.model.f;
    }
    armaInit(y - filter(m.b, m.f, u), m);
    reflectIntoUnitCircle(m.c);
    reflectIntoUnitCircle(m.d);
  }
  return m;
}

}  // namespace

Eigen::VectorXd predictionErrors(const PolynomialModel& m, const Eigen::VectorXd& u,
                                 const Eigen::VectorXd& y) {
  checkData(u, y);
  return PolyPredictor(u, y, m.orders).errors(m);
}

PolyEstimate arx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int na, int nb, int nk,
                 double sampleTime, const std::vector<Eigen::Index>& experimentLengths) {
  checkData(u, y);
  const std::vector<Segment> segments = experimentSegments(experimentLengths, y.size());
  PolyOrders o;
  o.na = na;
  o.nb = nb;
  o.nk = nk;
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("arx: " + why);
  const auto t0 = Clock::now();
  PolyEstimate r;
  r.model = PolynomialModel::zero(PolyStructure::Arx, o, sampleTime);
  const Eigen::Index n = y.size();
  const int first = std::max(na, nb + nk - 1);
  const int p = o.parameters();
  if (!o.fitsData(PolyStructure::Arx, n, &r.summary.message)) return r;
  Eigen::Index rows = 0;  // regressions: each experiment's samples from its `first` on
  for (const auto& g : segments) rows += std::max<Eigen::Index>(0, g.n - first);
  if (rows <= p) {
    r.summary.message = "too few samples (" + std::to_string(n) + " in " + std::to_string(segments.size()) +
                        " experiments) for " + std::to_string(p) + " parameters";
    return r;
  }
  if (!u.allFinite() || !y.allFinite()) {
    r.summary.message = "the data contain NaN or infinite values";
    return r;
  }
  // Each experiment's regressors from its own samples only, stacked.
  Eigen::MatrixXd phi(rows, p);
  Eigen::VectorXd rhs(rows);
  Eigen::Index at = 0;
  for (const auto& g : segments) {
    if (g.n <= first) continue;
    const Eigen::VectorXd ug = u.segment(g.from, g.n), yg = y.segment(g.from, g.n);
    phi.middleRows(at, g.n - first) = regressors({{&yg, -1.0, 1, na}, {&ug, 1.0, nk, nb}}, first, g.n);
    rhs.segment(at, g.n - first) = yg.tail(g.n - first);
    at += g.n - first;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(phi);
  if (qr.rank() < p) {
    r.summary.message = "the regressors are rank deficient (rank " + std::to_string(qr.rank()) +
                        " of " + std::to_string(p) + "): the input is not exciting enough";
    r.summary.seconds = since(t0);
    return r;
  }
  const Eigen::VectorXd th = qr.solve(rhs);
  r.model.setParameterVector(th);
  const Eigen::VectorXd res = rhs - phi * th;
  const double sumSq = res.squaredNorm();
  const Eigen::Index m = rows;
  r.model.noiseVariance = sumSq / static_cast<double>(m - p);
  // (Phi^T Phi)^{-1} = P R^{-1} R^{-T} P^T from the QR factors.
  const Eigen::MatrixXd R = qr.matrixR().topLeftCorner(p, p).template triangularView<Eigen::Upper>();
  const Eigen::MatrixXd Rinv = R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd inner = Rinv * Rinv.transpose();
  const auto& perm = qr.colsPermutation();
  r.model.covariance = r.model.noiseVariance * (perm * inner * perm.transpose());
  fillStatistics(r.summary, sumSq, m, p);
  r.summary.termination = Termination::Converged;
  r.summary.message = "least squares solution";
  r.summary.lossHistory = {r.summary.loss};
  r.summary.seconds = since(t0);
  return r;
}

PolyEstimate refinePolynomial(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                              const PolynomialModel& initial, const PolyEstimateOptions& options,
                              const ProgressCallback& progress) {
  checkData(u, y);
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("refinePolynomial: " + why);
  const auto t0 = Clock::now();
  PolyEstimate r;
  r.model = initial;
  auto& s = r.summary;
  const Eigen::Index n = y.size();
  const int p = initial.orders.parameters();
  if (n - criterionStart(initial.orders) <= 2 * p) {
    s.message = "too few samples (" + std::to_string(n) + ") for " + std::to_string(p) +
                " parameters with the delay nk = " + std::to_string(initial.orders.nk);
    return r;
  }
  if (!u.allFinite() || !y.allFinite()) {
    s.message = "the data contain NaN or infinite values";
    return r;
  }
  const std::vector<Segment> segments = experimentSegments(options.experimentLengths, n);
  PolynomialModel work = initial;
  // One predictor per experiment, each run from zero initial conditions at its own first
  // sample over its own criterion samples; the records outlive the predictors.
  std::vector<Eigen::VectorXd> us, ys;
  us.reserve(segments.size());
  ys.reserve(segments.size());
  std::vector<PolyPredictor> predictors;
  predictors.reserve(segments.size());
  Eigen::Index used = 0;  // the rows in the criterion
  for (const auto& g : segments) {
    if (segments.size() == 1) {  // the record itself, not a copy
      predictors.emplace_back(u, y, initial.orders);
    } else {
      us.push_back(u.segment(g.from, g.n));
      ys.push_back(y.segment(g.from, g.n));
      predictors.emplace_back(us.back(), ys.back(), initial.orders);
    }
    used += std::max<Eigen::Index>(0, g.n - predictors.back().criterionStart());
  }
  // Coarse to fine: on one long record the search first runs on its first samples (at least
  // 4000, at most a quarter of the record), whose minimum lies within the statistical spread
  // of the whole record's, and then continues on the whole record from there: only the last
  // few iterations cost a pass over every sample. That start is taken only when the whole
  // record's loss there is lower than at the given start; the answer is the whole record's
  // minimum either way.
  PolynomialModel start = initial;
  const Eigen::Index coarse = std::max<Eigen::Index>(4000, n / 16);
  if (segments.size() == 1 && options.maxIterations > 0 && coarse * 4 <= n) {
    PolyEstimateOptions first = options;
    first.relativeTolerance = std::max(options.relativeTolerance, 1e-6);
    const PolyEstimate c = refinePolynomial(u.head(coarse), y.head(coarse), initial, first);
    if (c.summary.termination == Termination::Converged ||
        c.summary.termination == Termination::MaxIterations) {
      const double there = predictors.front().run(c.model);
      if (std::isfinite(there) && predictors.front().run(initial, nullptr, nullptr, there) > there)
        start = c.model;
    }
    if (reportProgress(progress, 0.0, "iterating")) {
      s.termination = Termination::Cancelled;
      s.message = "cancelled by the user";
      return r;
    }
  }
  // Several experiments: each one's squared errors weighted by lambda / lambda_k once a first
  // fit has estimated its noise variance (empty: unweighted), as pem does.
  std::vector<double> weights;
  LeastSquaresProblem problem;
  problem.samples = n;
  problem.normalEquations = [&](const Eigen::VectorXd& th, double bound, double& sumSquares,
                                Eigen::MatrixXd* R, Eigen::VectorXd* g) {
    work.setParameterVector(th);
    if (predictors.size() == 1) {
      sumSquares = predictors.front().run(work, R, g, bound);
      return true;
    }
    sumSquares = 0.0;
    if (R) R->setZero(p, p);
    if (g) g->setZero(p);
    Eigen::MatrixXd Rk;
    Eigen::VectorXd gk;
    for (std::size_t k = 0; k < predictors.size(); ++k) {
      const double w = weights.empty() ? 1.0 : weights[k];
      const double sk = predictors[k].run(work, R ? &Rk : nullptr, g ? &gk : nullptr,
                                          (bound - sumSquares) / w);
      sumSquares += w * sk;
      if (sumSquares > bound) return true;  // rejected anyway; R and g are not used
      if (R) *R += w * Rk;
      if (g) *g += w * gk;
    }
    return true;
  };
  if (options.enforceStability)
    problem.project = [&](Eigen::VectorXd& th) {
      work.setParameterVector(th);
      if (stabilize(work)) th = work.parameterVector();
    };
  LeastSquaresSolution sol = levenbergMarquardt(problem, start.parameterVector(),
                                                options.maxIterations, options.relativeTolerance,
                                                options.initialDamping, progress);
  if (predictors.size() > 1 && sol.summary.termination != Termination::Failed &&
      sol.summary.termination != Termination::Cancelled) {
    // Each experiment's noise variance from the first fit, then the weighted fit from there.
    work.setParameterVector(sol.phi);
    std::vector<double> own(predictors.size());
    double total = 0.0;
    for (std::size_t k = 0; k < predictors.size(); ++k) {
      const double sk = predictors[k].run(work);
      total += sk;
      const Eigen::Index rows = segments[k].n - predictors[k].criterionStart();
      own[k] = sk / static_cast<double>(std::max<Eigen::Index>(1, rows));
    }
    const double pooled = total / static_cast<double>(std::max<Eigen::Index>(1, used));
    for (double o : own) weights.push_back(o > 0.0 && pooled > 0.0 ? pooled / o : 1.0);
    LeastSquaresSolution weighted = levenbergMarquardt(problem, sol.phi, options.maxIterations,
                                                       options.relativeTolerance, options.initialDamping);
    if (weighted.summary.termination != Termination::Failed) {
      weighted.summary.iterations += sol.summary.iterations;
      sol = std::move(weighted);
    }
  }
  s = sol.summary;
  if (s.termination == Termination::Failed) return r;
  r.model.setParameterVector(sol.phi);
  r.model.noiseVariance = sol.sumSquares / static_cast<double>(used - p);
  r.model.covariance = gaussNewtonCovariance(sol.R, used, sol.sumSquares);
  if (r.model.covariance.size() == 0)
    s.message += "; the Hessian is singular, so no covariance (the model is over-parameterized)";
  fillStatistics(s, sol.sumSquares, used, p);
  s.seconds = since(t0);
  return r;
}

namespace {

// Ss: the subspace estimate (its order chosen by the data when n = 0) as ARMAX polynomials,
// refined by prediction error; the subspace result kept beside it.
PolyEstimate stateSpaceEstimate(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int n, double sampleTime,
                                const PolyEstimateOptions& options, const ProgressCallback& progress) {
  SubspaceOptions so;
  so.order = n;
  so.closedLoop = options.closedLoop;
  so.experimentLengths = options.experimentLengths;
  if (n > so.maxOrder) so.maxOrder = std::min(n, SubspaceOptions::kMaxOrder);
  std::string why;
  if (!so.isValid(&why)) throw std::invalid_argument("ss: " + why);
  auto sub = std::make_shared<SubspaceEstimate>(subspaceEstimate(u, y, sampleTime, so));
  PolyEstimate r;
  r.subspace = sub;
  r.model = PolynomialModel::zero(PolyStructure::Ss, PolyOrders::stateSpace(std::max(n, 0)), sampleTime);
  if (!sub->ok) {
    r.summary.message = sub->message;
    return r;
  }
  PolynomialModel start = sub->model.polynomial();
  reflectIntoUnitCircle(start.c);  // the predictor must be stable to be refined
  if (std::string tooBig; !start.orders.fitsData(PolyStructure::Ss, y.size(), &tooBig)) {
    r.summary.message = tooBig;
    return r;
  }
  PolyEstimate refined = refinePolynomial(u, y, start, options, progress);
  refined.subspace = sub;
  if (refined.summary.termination == Termination::Failed) refined.model = start;
  return refined;
}

}  // namespace

PolyEstimate estimatePolynomial(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                PolyStructure structure, const PolyOrders& orders0,
                                double sampleTime, const PolyEstimateOptions& options,
                                const ProgressCallback& progress) {
  checkData(u, y);
  PolyOrders o = orders0;
  // The structure decides which polynomials exist.
  if (structure == PolyStructure::Arx) o.nc = o.nd = o.nf = 0;
  if (structure == PolyStructure::Armax) o.nd = o.nf = 0;
  if (structure == PolyStructure::Oe) o.na = o.nc = o.nd = 0;
  if (structure == PolyStructure::Bj) o.na = 0;
  if (structure == PolyStructure::Ss) o = o.of(PolyStructure::Ss);
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument(std::string(toString(structure)) + ": " + why);
  const auto t0 = Clock::now();
  if (structure == PolyStructure::Arx) return arx(u, y, o.na, o.nb, o.nk, sampleTime, options.experimentLengths);
  experimentSegments(options.experimentLengths, y.size());  // throws when they do not add up
  if (structure == PolyStructure::Ss) {
    PolyEstimate r = stateSpaceEstimate(u, y, o.na, sampleTime, options, progress);
    r.summary.seconds = since(t0);
    return r;
  }
  if (std::string tooBig; !o.fitsData(structure, y.size(), &tooBig)) {
    PolyEstimate r;
    r.model = PolynomialModel::zero(structure, o, sampleTime);
    r.summary.message = tooBig;
    return r;
  }
  if (!u.allFinite() || !y.allFinite()) {
    PolyEstimate r;
    r.model = PolynomialModel::zero(structure, o, sampleTime);
    r.summary.message = "the data contain NaN or infinite values";
    return r;
  }
  PolyEstimate r = refinePolynomial(u, y, initialModel(u, y, structure, o, sampleTime), options,
                                    progress);
  r.summary.seconds = since(t0);
  return r;
}

}  // namespace flexarm
