#include "core/ident/closed_loop_pem.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/ident/evaluation.h"
#include "core/ident/levenberg_marquardt.h"
#include "core/models/physical_models.h"

namespace flexarm {

const char* toString(ClosedLoopMethod m) {
  switch (m) {
    case ClosedLoopMethod::Direct: return "direct";
    case ClosedLoopMethod::TwoStage: return "two-stage";
    case ClosedLoopMethod::Indirect: return "indirect";
  }
  return "direct";
}
std::optional<ClosedLoopMethod> closedLoopMethodFromString(std::string_view s) {
  for (auto m : {ClosedLoopMethod::Direct, ClosedLoopMethod::TwoStage, ClosedLoopMethod::Indirect})
    if (s == toString(m)) return m;
  return std::nullopt;
}

const char* toString(LoopOutput o) {
  return o == LoopOutput::MotorAngle ? "motor-angle" : "motor-velocity";
}
std::optional<LoopOutput> loopOutputFromString(std::string_view s) {
  for (auto o : {LoopOutput::MotorAngle, LoopOutput::MotorVelocity})
    if (s == toString(o)) return o;
  return std::nullopt;
}

bool ReferenceProjectionOptions::isValid(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(pastS >= 0.0) || !(futureS >= 0.0) || !std::isfinite(pastS) || !std::isfinite(futureS) ||
      !(fineS >= 0.0) || !std::isfinite(fineS))
    return fail("the FIR lengths must be finite and not negative");
  if (!(knotS >= 0.0) || !std::isfinite(knotS)) return fail("the knot spacing must be finite and not negative");
  if (!(ridge >= 0.0) || !std::isfinite(ridge)) return fail("the ridge must be finite and not negative");
  return true;
}

bool ClosedLoopPemOptions::isValid(std::string* why) const {
  if (method == ClosedLoopMethod::Indirect && pem.noiseModel != NoiseModel::OutputError) {
    if (why) *why = "the indirect method fits output error; it excludes the innovations form";
    return false;
  }
  return projection.isValid(why) && controller.isValid(why) && pem.isValid(why);
}

namespace {

// Cubic B-spline of unit knot spacing centred at 0 (support [-2, 2]).
double cubicBSpline(double x) {
  x = std::abs(x);
  if (x >= 2.0) return 0.0;
  if (x >= 1.0) return (2.0 - x) * (2.0 - x) * (2.0 - x) / 6.0;
  return (4.0 - 6.0 * x * x + 3.0 * x * x * x) / 6.0;
}

// Columns spanning the admissible taps over lags lo..hi: one per lag up to fine, then cubic
// B-splines with knots `knot` lags apart, restricted to lags beyond fine.
Eigen::MatrixXd tapBasis(int lo, int hi, int fine, double knot) {
  const int m = hi - lo + 1;
  fine = std::clamp(fine, lo - 1, hi);
  if (!(knot >= 1.0)) fine = hi;  // every tap free
  const int nFine = fine - lo + 1;
  const int nSpline = fine < hi ? static_cast<int>(std::ceil((hi - fine) / knot)) + 2 : 0;
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Zero(m, nFine + nSpline);
  for (int j = 0; j < nFine; ++j) Phi(j, j) = 1.0;
  for (int i = 0; i < nSpline; ++i) {
    const double centre = fine + i * knot;
    for (int k = std::max(fine + 1, static_cast<int>(std::floor(centre - 2.0 * knot)));
         k <= std::min(hi, static_cast<int>(std::ceil(centre + 2.0 * knot))); ++k)
      Phi(k - lo, nFine + i) = cubicBSpline((k - centre) / knot);
  }
  return Phi;
}

}  // namespace

ReferenceProjection projectOnReference(const Eigen::VectorXd& u, const Eigen::VectorXd& r,
                                       double T, const ReferenceProjectionOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("projectOnReference: " + why);
  if (u.size() != r.size())
    throw std::invalid_argument("projectOnReference: input and reference differ in length");
  if (!(T > 0.0)) throw std::invalid_argument("projectOnReference: the sample time must be positive");
  ReferenceProjection out;
  const Eigen::Index n = u.size();
  // The FIR length is checked against the data in floating point first: a tiny sample time
  // would overflow an int (e.g. "-1806140927 taps").
  const double pastTaps = std::round(options.pastS / T), futureTaps = std::round(options.futureS / T);
  if (!(pastTaps + futureTaps + 1.0 <= static_cast<double>(n) / 4.0)) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.0f", pastTaps + futureTaps + 1.0);
    out.message = "too few samples (" + std::to_string(n) + ") for an FIR of " + buf +
                  " taps of the reference";
    return out;
  }
  out.pastTaps = static_cast<int>(pastTaps);
  out.futureTaps = static_cast<int>(futureTaps);
  const int lo = -out.futureTaps, hi = out.pastTaps;  // lags k: u(t) ~ r(t - k)
  const int m = hi - lo + 1;
  if (!u.allFinite() || !r.allFinite()) {
    out.message = "the input or the reference contains NaN or infinite values";
    return out;
  }
  auto at = [&](Eigen::Index i) { return i >= 0 && i < n ? r[i] : 0.0; };
  // Normal matrix G(k, l) = sum_{t=0}^{n-1} r(t-k) r(t-l): first row directly, then the
  // shift recursion G(k+1, l+1) = G(k, l) + r(-1-k) r(-1-l) - r(n-1-k) r(n-1-l).
  Eigen::MatrixXd G(m, m);
  Eigen::VectorXd b(m);
  for (int j = 0; j < m; ++j) {
    const int k = lo + j;
    double g = 0.0, c = 0.0;
    for (Eigen::Index t = 0; t < n; ++t) {
      const double rk = at(t - k);
      g += at(t - lo) * rk;
      c += u[t] * rk;
    }
    G(0, j) = g;
    b[j] = c;
  }
  for (int i = 1; i < m; ++i)
    for (int j = i; j < m; ++j) {
      const int k = lo + i - 1, l = lo + j - 1;
      G(i, j) = G(i - 1, j - 1) + at(-1 - k) * at(-1 - l) - at(n - 1 - k) * at(n - 1 - l);
    }
  G = G.selfadjointView<Eigen::Upper>();
  const double scale = G.diagonal().mean();
  if (!(scale > 0.0)) {
    out.message = "the reference is constant, so it explains nothing of the input";
    return out;
  }
  // Taps = Phi c: identity columns up to the fine lag, cubic B-splines beyond it.
  const Eigen::MatrixXd Phi = tapBasis(lo, hi, static_cast<int>(std::lround(options.fineS / T)),
                                       options.knotS / T);
  out.freeParameters = static_cast<int>(Phi.cols());
  Eigen::MatrixXd Gc = Phi.transpose() * G * Phi;
  Gc.diagonal().array() += options.ridge * Gc.diagonal().mean();
  Eigen::LLT<Eigen::MatrixXd> llt(Gc);
  if (llt.info() != Eigen::Success) {
    out.message = "the reference's normal equations are singular";
    return out;
  }
  out.taps = Phi * llt.solve(Phi.transpose() * b);
  out.basis = Phi;
  out.inputFromReference = Eigen::VectorXd::Zero(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    double s = 0.0;
    const Eigen::Index k0 = std::max<Eigen::Index>(lo, t - (n - 1)), k1 = std::min<Eigen::Index>(hi, t);
    for (Eigen::Index k = k0; k <= k1; ++k) s += out.taps[k - lo] * r[t - k];
    out.inputFromReference[t] = s;
  }
  out.fitPercent = fitPercent(u, out.inputFromReference);
  out.ok = true;
  return out;
}

namespace {

// Replaces the covariance of the stage-2 estimate by one that also carries the error of the
// stage-1 FIR: the estimate's error is H^{-1} (psi^T eps - W^T n) with n = u - u_r,
// W = Z (Z^T Z)^{-1} (G Z)^T psi, Z the FIR's regressors (basis columns applied to r).
void addStage1Uncertainty(PemResult& est, const ReferenceProjection& proj,
                          const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                          const Eigen::VectorXd& r, double T, double level) {
  const Eigen::Index n = u.size();
  const Eigen::Index p = static_cast<Eigen::Index>(est.freeIndices.size());
  if (est.covariance.rows() != p || p == 0) return;
  const Eigen::VectorXd& ur = proj.inputFromReference;
  const PemEvaluation ev = evaluatePredictor(*est.model, {}, ur, y, T, est.freeIndices, true, false);
  const int lo = -proj.futureTaps;
  const Eigen::Index nb = proj.basis.cols();
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(n, nb), GZ(n, nb);
  for (Eigen::Index j = 0; j < nb; ++j) {
    for (Eigen::Index row = 0; row < proj.basis.rows(); ++row) {
      const double c = proj.basis(row, j);
      if (c == 0.0) continue;
      const Eigen::Index k = lo + row;  // Z_j(t) += c r(t - k)
      const Eigen::Index t0 = std::max<Eigen::Index>(0, k), t1 = std::min<Eigen::Index>(n, n + k);
      if (t1 > t0) Z.col(j).segment(t0, t1 - t0) += c * r.segment(t0 - k, t1 - t0);
    }
    GZ.col(j) = simulate(*est.model, Z.col(j), T);
  }
  const Eigen::MatrixXd D = ev.psi.transpose() * GZ;  // p x nb
  Eigen::MatrixXd Hz = Z.transpose() * Z;
  Hz.diagonal().array() += 1e-9 * Hz.diagonal().mean();
  const Eigen::MatrixXd W = Z * Eigen::LDLT<Eigen::MatrixXd>(Hz).solve(D.transpose());  // n x p
  const Eigen::VectorXd minusNoise = ur - u;
  const Eigen::MatrixXd H = ev.psi.transpose() * ev.psi;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success) return;
  const int lags = est.covarianceLags > 0 ? est.covarianceLags : automaticCovarianceLags(ev.eps);
  const Eigen::MatrixXd Q = longRunCovariance({{&ev.psi, &ev.eps}, {&W, &minusNoise}}, lags);
  const Eigen::MatrixXd Hi = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  est.covariance = static_cast<double>(n) / static_cast<double>(n - p) * (Hi * Q * Hi);
  const double z = twoSidedNormalQuantile(level);
  for (Eigen::Index j = 0; j < p; ++j) {
    auto& q = est.parameters[static_cast<std::size_t>(est.freeIndices[static_cast<std::size_t>(j)])];
    q.std = std::sqrt(std::max(0.0, est.covariance(j, j)));
    q.lower = q.value - z * q.std;
    q.upper = q.value + z * q.std;
  }
}

}  // namespace

namespace {

// The closed loop of simulateLoop as one discrete state space in z = [x; a_{k-1}; I_{k-1}]:
// z+ = Acl z + Bcl r, output Ccl z (D = 0), with, for each free parameter, dAcl, dBcl, dCcl
// from the plant's sampled derivatives (the controller does not depend on theta).
SampledModel loopMatrices(const ParametricModel& model, const ControllerOptions& ctl, double T,
                          const std::vector<int>& free, bool withGradient, LoopOutput output) {
  std::string why;
  if (!ctl.isValid(&why)) throw std::invalid_argument("closed loop: " + why);
  if (std::abs(T * ctl.rateHz - 1.0) > 1e-6)
    throw std::invalid_argument("closed loop: the sample time must be the controller's period");
  if (const auto* pm = dynamic_cast<const PhysicalModel*>(&model);
      pm && pm->options().output != ModelOutput::MotorAngle)
    throw std::invalid_argument("closed loop: the model's output must be the motor angle");
  const SampledModel s = sampleZoh(model, T, free, withGradient);
  if (s.D(0, 0) != 0.0)
    throw std::invalid_argument("closed loop: the model's output must be the motor angle (D = 0)");
  const Eigen::Index n = s.Ad.rows();
  // u = g e + h I_{k-1}, e = kp r - (kp + 1/T) C x + a_{k-1} / T.
  const double g = ctl.kv * (ctl.ti > 0.0 ? 1.0 + T / ctl.ti : 1.0);
  const double h = ctl.ti > 0.0 ? ctl.kv / ctl.ti : 0.0;
  const double kc = ctl.kp + 1.0 / T;
  // One set of blocks, for the values (constant = true) or for a derivative along theta_j
  // (the controller's constants drop out; BdC is Bd c or its derivative dBd c + Bd dc).
  auto build = [&](const Eigen::MatrixXd& Ad, const Eigen::VectorXd& Bd, const Eigen::RowVectorXd& c,
                   const Eigen::MatrixXd& BdC, bool constant, Eigen::MatrixXd& A,
                   Eigen::VectorXd& B, Eigen::RowVectorXd& C) {
    A = Eigen::MatrixXd::Zero(n + 2, n + 2);
    A.topLeftCorner(n, n) = Ad - g * kc * BdC;
    A.block(0, n, n, 1) = Bd * (g / T);
    A.block(0, n + 1, n, 1) = Bd * h;
    A.block(n, 0, 1, n) = c;
    A.block(n + 1, 0, 1, n) = -(T * ctl.kp + 1.0) * c;
    B = Eigen::VectorXd::Zero(n + 2);
    B.head(n) = Bd * (g * ctl.kp);
    C = Eigen::RowVectorXd::Zero(n + 2);
    C.head(n) = output == LoopOutput::MotorAngle ? Eigen::RowVectorXd(c) : Eigen::RowVectorXd(c / T);
    if (constant) {
      A(n + 1, n) = A(n + 1, n + 1) = 1.0;
      B[n + 1] = T * ctl.kp;
      if (output == LoopOutput::MotorVelocity) C[n] = -1.0 / T;
    }
  };
  SampledModel L;
  Eigen::VectorXd B;
  Eigen::RowVectorXd C;
  const Eigen::VectorXd bd = s.Bd.col(0);
  const Eigen::RowVectorXd c = s.C.row(0);
  build(s.Ad, bd, c, bd * c, true, L.Ad, B, C);
  L.Bd = B;
  L.C = C;
  L.D = Eigen::MatrixXd::Zero(1, 1);
  for (std::size_t j = 0; j < s.dAd.size(); ++j) {
    Eigen::MatrixXd dA;
    const Eigen::VectorXd dbd = s.dBd[j].col(0);
    const Eigen::RowVectorXd dc = s.dC[j].row(0);
    build(s.dAd[j], dbd, dc, dbd * c + bd * dc, false, dA, B, C);
    L.dAd.push_back(dA);
    L.dBd.push_back(B);
    L.dC.push_back(C);
    L.dD.push_back(Eigen::MatrixXd::Zero(1, 1));
  }
  return L;
}

// The model as the loop needs it: a physical model's output switched to the motor angle.
std::unique_ptr<ParametricModel> angleOutputModel(const ParametricModel& model) {
  auto copy = model.clone();
  if (auto* pm = dynamic_cast<PhysicalModel*>(copy.get())) {
    ModelOptions mo = pm->options();
    mo.output = ModelOutput::MotorAngle;
    mo.armAcceleration = false;
    pm->setOptions(mo);
  }
  return copy;
}

ClosedLoopPemResult indirect(const ParametricModel& model, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& r, double T, const ClosedLoopPemOptions& options,
                             const ProgressCallback& progress) {
  if (r.size() != y.size())
    throw std::invalid_argument("pemClosedLoop: the indirect method needs a reference as long as the output");
  if (options.loopWarmup < 0 || options.loopWarmup >= y.size())
    throw std::invalid_argument("pemClosedLoop: the loop's warm-up must leave samples to compare");
  ClosedLoopPemResult out;
  out.method = ClosedLoopMethod::Indirect;
  const std::string head = "indirect closed-loop fit";
  if (std::abs(T * options.controller.rateHz - 1.0) > 1e-6) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "%s: the controller runs at %g Hz but the data are sampled at %g Hz; the loop "
                  "is only known at the controller's rate, so it needs the log at that rate",
                  head.c_str(), options.controller.rateHz, 1.0 / T);
    out.pem.model = model.clone();
    out.pem.sampleTime = T;
    out.pem.summary.message = buf;
    return out;
  }
  // The loop starts at rest at the first measured angle; the controller sees only r - a.
  const double rest = y.size() ? y[0] : 0.0;
  const Eigen::VectorXd yRel = y.array() - rest, rRel = r.array() - rest;
  const auto work = angleOutputModel(model);
  PemOptions po = options.pem;
  po.noiseModel = NoiseModel::OutputError;
  po.covariance = CovarianceKind::Sandwich;
  const ControllerOptions ctl = options.controller;
  const LoopOutput output = options.loopOutput;
  const Eigen::Index skip = options.loopWarmup;
  po.predictor = [ctl, output, skip](const ParametricModel& m, const Eigen::VectorXd& ref,
                                     const Eigen::VectorXd& angle, double Ts,
                                     const std::vector<int>& free, bool withGradient) {
    PemEvaluation ev = evaluateLoop(m, ctl, ref, angle, Ts, free, withGradient, output);
    if (skip > 0) {
      const Eigen::Index n = ev.eps.size() - skip;
      ev.eps = Eigen::VectorXd(ev.eps.tail(n));
      if (withGradient) ev.psi = Eigen::MatrixXd(ev.psi.bottomRows(n));
    }
    return ev;
  };
  out.pem = pem(*work, rRel, yRel, T, po, progress);
  // Back to the caller's output (e.g. the motor velocity) for Bode plots and simulation.
  const auto* original = dynamic_cast<const PhysicalModel*>(&model);
  if (auto* estimate = dynamic_cast<PhysicalModel*>(out.pem.model.get()); original && estimate)
    estimate->setOptions(original->options());
  out.pem.summary.message = head + " (the known controller around the model, " +
                            toString(output) + " from the reference)" +
                            (out.pem.summary.message.empty() ? "" : "; ") + out.pem.summary.message;
  return out;
}

}  // namespace

PemEvaluation evaluateLoop(const ParametricModel& model, const ControllerOptions& ctl,
                           const Eigen::VectorXd& r, const Eigen::VectorXd& y, double T,
                           const std::vector<int>& free, bool withGradient, LoopOutput output) {
  if (r.size() != y.size())
    throw std::invalid_argument("closed loop: reference and output differ in length");
  Eigen::VectorXd measured = y;
  if (output == LoopOutput::MotorVelocity)
    for (Eigen::Index t = 0; t < y.size(); ++t) measured[t] = (y[t] - (t > 0 ? y[t - 1] : y[0])) / T;
  return evaluateSampled(loopMatrices(model, ctl, T, free, withGradient, output), r, measured,
                         withGradient);
}

Eigen::VectorXd simulateLoop(const ParametricModel& model, const ControllerOptions& controller,
                             const Eigen::VectorXd& r, double T, LoopOutput output) {
  return -evaluateLoop(model, controller, r, Eigen::VectorXd::Zero(r.size()), T, {}, false, output)
              .eps;
}

ClosedLoopPemResult pemClosedLoop(const ParametricModel& model, const Eigen::VectorXd& u,
                                  const Eigen::VectorXd& y, const Eigen::VectorXd& r,
                                  double T, const ClosedLoopPemOptions& options,
                                  const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("pemClosedLoop: " + why);
  ClosedLoopPemResult out;
  out.method = options.method;
  if (options.method == ClosedLoopMethod::Direct) {
    out.pem = pem(model, u, y, T, options.pem, progress);
    return out;
  }
  if (options.method == ClosedLoopMethod::Indirect) return indirect(model, y, r, T, options, progress);
  if (r.size() != u.size())
    throw std::invalid_argument("pemClosedLoop: the two-stage method needs a reference as long as the input");
  out.projection = projectOnReference(u, r, T, options.projection);
  if (!out.projection.ok) {
    out.pem.model = model.clone();
    out.pem.sampleTime = T;
    out.pem.summary.message = "two-stage closed-loop fit, stage 1: " + out.projection.message;
    return out;
  }
  PemOptions po = options.pem;
  po.noiseModel = NoiseModel::OutputError;
  po.covariance = CovarianceKind::Sandwich;
  out.pem = pem(model, out.projection.inputFromReference, y, T, po, progress);
  if (options.stage1Uncertainty && out.pem.summary.ok() && out.pem.covariance.size() > 0)
    addStage1Uncertainty(out.pem, out.projection, u, y, r, T, po.level);
  char buf[96];
  std::snprintf(buf, sizeof buf, "two-stage closed-loop fit (the reference explains %.1f %% of the input)",
                out.projection.fitPercent);
  out.pem.summary.message = std::string(buf) + (out.pem.summary.message.empty() ? "" : "; ") +
                            out.pem.summary.message;
  return out;
}

}  // namespace flexarm
