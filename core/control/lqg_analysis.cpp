#include "core/control/lqg_analysis.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/control/frequency_response.h"

namespace flexarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Zero-order-hold discretization of x' = A x + B u over h: (Phi, Gamma) from one exponential.
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> discretize(const Eigen::MatrixXd& A,
                                                       const Eigen::MatrixXd& B, double h) {
  const auto n = A.rows(), m = B.cols();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = A * h;
  M.topRightCorner(n, m) = B * h;
  const Eigen::MatrixXd E = M.exp();
  return {E.topLeftCorner(n, n), E.topRightCorner(n, m)};
}

void appendMagnitudes(const Eigen::VectorXcd& poles, std::vector<double>& out) {
  for (Eigen::Index i = 0; i < poles.size(); ++i) out.push_back(std::abs(poles(i)));
}

// Ascending polynomial coefficients: product and the real roots' count in the open RHP.
std::vector<double> multiply(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> c(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}

Eigen::VectorXcd roots(std::vector<double> c) {
  while (c.size() > 1 && c.back() == 0.0) c.pop_back();
  const int n = static_cast<int>(c.size()) - 1;
  if (n < 1) return {};
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) companion(0, i) = -c[n - 1 - i] / c[n];
  for (int i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  return Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
}

}  // namespace

bool DisturbanceStepOptions::isValid(std::string* why) const {
  auto fail = [why](const char* s) {
    if (why) *why = s;
    return false;
  };
  if (!(horizon > 0.0) || !std::isfinite(horizon)) return fail("horizon must be positive");
  if (!(sampleTime > 0.0) || sampleTime > horizon)
    return fail("sampleTime must be positive and at most the horizon");
  if (horizon / sampleTime > 1e7) return fail("horizon / sampleTime exceeds 1e7 samples");
  if (!std::isfinite(wStepTime) || !std::isfinite(vStepTime) || !std::isfinite(wAmplitude) ||
      !std::isfinite(vAmplitude))
    return fail("step times and amplitudes must be finite");
  if (!(saturationLimit >= 0.0)) return fail("saturationLimit must not be negative");
  if (subSteps < 1) return fail("subSteps must be at least 1");
  return true;
}

DisturbanceResponse disturbanceSteps(const LqgDesign& d, const DisturbanceStepOptions& o) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("DisturbanceStepOptions: " + why);
  if (!d.ok()) throw std::invalid_argument("disturbanceSteps: the design failed: " + d.message);
  const StateSpace cl = disturbanceClosedLoop(d);
  const int n = d.plant.states(), nm = d.model.states();
  const bool saturated = o.saturationLimit > 0.0;
  const int sub = saturated ? o.subSteps : 1;
  const double h = o.sampleTime / sub;
  const long samples = static_cast<long>(std::floor(o.horizon / o.sampleTime + 1e-9)) + 1;

  // Linear: inputs (w, v) on the closed loop. Saturated: inputs (u applied, u seen by the
  // estimator, w, v) on the arm and estimator with the feedback loop left open.
  Eigen::MatrixXd A = cl.A, B = cl.B;
  if (saturated) {
    const auto& g = d.plant;
    const auto& m = d.model;
    A = Eigen::MatrixXd::Zero(n + nm, n + nm);
    A.topLeftCorner(n, n) = g.A;
    A.bottomLeftCorner(nm, n) = d.K * g.C;
    A.bottomRightCorner(nm, nm) = m.A - d.K * m.C;
    B = Eigen::MatrixXd::Zero(n + nm, 4);
    B.block(0, 0, n, 1) = g.B;
    B.block(n, 1, nm, 1) = m.B;
    B.block(0, 2, n, 1) = g.Bw;
    B.block(0, 3, n, 1) = g.Bv;
    B.block(n, 3, nm, 1) = d.K * g.Dv;
  }
  const auto [Phi, Gamma] = discretize(A, B, h);
  DisturbanceResponse r;
  // The loop below runs tens of thousands of times per call: column-wise updates on plain
  // arrays keep the small products free of temporaries and of serial dependencies.
  const int ns = n + nm, ni = static_cast<int>(B.cols());
  std::vector<double> xi(ns, 0.0), next(ns), in(ni, 0.0);
  for (auto* v : {&r.time, &r.armAngle, &r.motorAngle, &r.torque, &r.computedTorque})
    v->reserve(static_cast<std::size_t>(samples));
  const std::vector<double> gain(d.L.data(), d.L.data() + nm);
  for (long k = 0; k < samples; ++k) {
    const double t = k * o.sampleTime;
    const double w = t >= o.wStepTime - 1e-9 * o.sampleTime ? o.wAmplitude : 0.0;
    const double v = t >= o.vStepTime - 1e-9 * o.sampleTime ? o.vAmplitude : 0.0;
    for (int s = 0; s < sub; ++s) {
      double ubar = 0.0;
      for (int i = 0; i < nm; ++i) ubar -= gain[i] * xi[n + i];
      const double u = saturated ? std::clamp(ubar, -o.saturationLimit, o.saturationLimit) : ubar;
      if (s == 0) {
        r.time.push_back(t);
        r.armAngle.push_back(xi[2]);
        r.motorAngle.push_back(xi[0]);
        r.torque.push_back(u);
        r.computedTorque.push_back(ubar);
        r.peakArmDeviation = std::max(r.peakArmDeviation, std::abs(xi[2]));
      }
      if (saturated) {
        in[0] = u;
        in[1] = o.antiWindup ? u : ubar;
        in[2] = w;
        in[3] = v;
      } else {
        in[0] = w;
        in[1] = v;
      }
      std::fill(next.begin(), next.end(), 0.0);
      for (int j = 0; j < ns; ++j) {
        const double* col = Phi.data() + static_cast<std::ptrdiff_t>(j) * ns;
        const double xj = xi[j];
        for (int i = 0; i < ns; ++i) next[i] += col[i] * xj;
      }
      for (int j = 0; j < ni; ++j) {
        const double* col = Gamma.data() + static_cast<std::ptrdiff_t>(j) * ns;
        const double uj = in[j];
        for (int i = 0; i < ns; ++i) next[i] += col[i] * uj;
      }
      xi.swap(next);
    }
    double norm2 = 0.0;
    for (double x : xi) norm2 += x * x;
    if (!(norm2 < 1e12)) {
      r.diverged = true;
      break;
    }
  }
  return r;
}

BandwidthCriterion bandwidthCriterion(const TwoMassLqgParameters& p, double bandwidth,
                                      const NyquistOptions& options) {
  std::string why;
  if (!p.isValid(&why)) throw std::invalid_argument("bandwidthCriterion: " + why);
  if (!(bandwidth > 0.0) || !std::isfinite(bandwidth))
    throw std::invalid_argument("bandwidthCriterion: the bandwidth must be positive");
  BandwidthCriterion c;
  c.bandwidth = bandwidth;
  // |1/(1 + i wb/w0)^3| = 1/sqrt(2) at wb = w0 sqrt(2^(1/3) - 1).
  c.omega0 = bandwidth / std::sqrt(std::cbrt(2.0) - 1.0);
  const double w0 = c.omega0;
  auto tm = [&p, w0](std::complex<double> s) {  // (8.26)
    const std::complex<double> q = 1.0 + s / w0;
    return 1.0 / (q * q * q) / armFromMotorResponse(p, s);
  };
  std::vector<double> freqs = {w0, std::sqrt(p.k / p.Ja)};
  if (p.d > 0.0) freqs.push_back(p.k / p.d);
  c.curve = nyquist(tm, 1.0, freqs, options);
  // Numerator of 1 - T_m: (1 + s/w0)^3 (k + d s) - (k + (d + f_a) s + J_a s^2); its constant
  // term vanishes (T_m(0) = 1), so divide by s.
  const std::vector<double> lead =
      multiply(multiply(multiply({1.0, 1.0 / w0}, {1.0, 1.0 / w0}), {1.0, 1.0 / w0}), {p.k, p.d});
  std::vector<double> num = lead;
  num[0] -= p.k;
  num[1] -= p.d + p.fa;
  num[2] -= p.Ja;
  num.erase(num.begin());
  c.rhpZeros = countRightHalfPlane(roots(num));
  return c;
}

bool LqgAnalysisOptions::isValid(std::string* why) const {
  if (!nyquist.isValid(why)) return false;
  DisturbanceStepOptions s = steps;
  s.saturationLimit = saturationLimit;
  if (!s.isValid(why)) return false;
  if (!(taBandwidth >= 0.0) || !std::isfinite(taBandwidth)) {
    if (why) *why = "taBandwidth must not be negative";
    return false;
  }
  return true;
}

LqgAnalysis analyzeLqg(const LqgOptions& designOptions, const LqgAnalysisOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("LqgAnalysisOptions: " + why);
  const auto start = std::chrono::steady_clock::now();
  LqgAnalysis a;
  a.design = designLqg(designOptions);
  auto finish = [&](Termination t, std::string message) {
    a.termination = t;
    a.message = std::move(message);
    a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return a;
  };
  if (!a.design.ok()) return finish(a.design.termination, a.design.message);
  const LqgDesign& d = a.design;

  const TransferEvaluator G(plantTransfer(d)), Fy(regulatorFy(d)), G0(stateFeedbackG0(d));
  const bool siso = d.plant.measurements() == 1;
  const ComplexFunction loopGain = [&](std::complex<double> s) {
    return siso ? Fy.scalar(s) * G.scalar(s) : (Fy(s) * G(s))(0, 0);
  };
  const ComplexFunction g0 = [&G0](std::complex<double> s) { return G0.scalar(s); };
  const Eigen::VectorXcd& plantPoles = d.plantPoles;
  std::vector<double> freqs;
  appendMagnitudes(plantPoles, freqs);
  appendMagnitudes(d.regulatorPoles, freqs);
  appendMagnitudes(d.closedLoopPoles, freqs);

  // Nyquist of F_y G, |S|, |T| (Section 8.6).
  a.loop = nyquist(loopGain, -1.0, freqs, options.nyquist);
  std::size_t peak = 0;
  for (std::size_t i = 0; i < a.loop.values.size(); ++i) {
    const std::complex<double> l = a.loop.values[i];
    a.sensitivity.push_back(1.0 / std::abs(1.0 + l));
    a.complementary.push_back(std::abs(l / (1.0 + l)));
    if (a.sensitivity[i] > a.sensitivity[peak]) peak = i;
  }
  // Golden-section search of the peak between the neighbours of the best grid point.
  auto sens = [&loopGain](double lw) {
    return 1.0 / std::abs(1.0 + loopGain({0.0, std::exp(lw)}));
  };
  const auto& wf = a.loop.frequencies;
  double lo = std::log(wf[peak > 0 ? peak - 1 : 0]);
  double hi = std::log(wf[std::min(peak + 1, wf.size() - 1)]);
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 60 && hi - lo > 1e-13; ++it) {
    const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    if (sens(x1) < sens(x2))
      lo = x1;
    else
      hi = x2;
  }
  a.maxSensitivityFrequency = std::exp(0.5 * (lo + hi));
  a.maxSensitivity = std::max(a.sensitivity[peak], sens(std::log(a.maxSensitivityFrequency)));
  if (a.maxSensitivity == a.sensitivity[peak]) a.maxSensitivityFrequency = wf[peak];
  a.minDistanceToMinusOne = 1.0 / a.maxSensitivity;

  // Encirclements expected from the poles, and Bode's integral (8.37).
  a.openLoopRhpPoles = d.rhpRegulatorPoles + countRightHalfPlane(plantPoles);
  a.expectedEncirclements = a.openLoopRhpPoles - d.rhpClosedLoopPoles;
  a.bodeIntegral = bodeSensitivityIntegral(loopGain, a.loop.frequencies);
  const double sumRe = rightHalfPlaneRealSum(d.regulatorPoles) + rightHalfPlaneRealSum(plantPoles);
  a.bodePrediction = kPi * sumRe;

  // Describing function (Section 8.5) on F_y G and on G_0 (8.35).
  a.loopCrossings = describingFunctionCrossings(loopGain, a.loop);
  a.g0 = nyquist(g0, -1.0, freqs, options.nyquist);
  a.g0Crossings = describingFunctionCrossings(g0, a.g0);

  // Figure 8.3, and the saturated loop without and with anti-windup (8.31)-(8.32).
  DisturbanceStepOptions steps = options.steps;
  steps.saturationLimit = 0.0;
  a.steps = disturbanceSteps(d, steps);
  if (options.saturationLimit > 0.0) {
    steps.saturationLimit = options.saturationLimit;
    steps.antiWindup = false;
    a.saturated = disturbanceSteps(d, steps);
    steps.antiWindup = true;
    a.saturatedAntiWindup = disturbanceSteps(d, steps);
  }
  if (options.taBandwidth > 0.0)
    a.bandwidth =
        bandwidthCriterion(designOptions.parameters, options.taBandwidth, options.nyquist);

  std::ostringstream s;
  s << d.regulatorStability() << "; max |S| = " << a.maxSensitivity << " at "
    << a.maxSensitivityFrequency << " rad/s; F_y G encircles -1 " << a.loop.encirclements
    << " times counter-clockwise";
  if (a.loop.encirclements != a.expectedEncirclements)
    s << " (the poles predict " << a.expectedEncirclements << ": refine the frequency grid)";
  if (a.loop.gridLimitReached) s << "; the frequency grid reached its point limit";
  return finish(Termination::Converged, s.str());
}

}  // namespace flexarm
