#include "core/control/lqg.h"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace flexarm {
namespace {

Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& M) {
  if (M.rows() == 0) return {};
  return Eigen::EigenSolver<Eigen::MatrixXd>(M, false).eigenvalues();
}

bool diagonalIsValid(const Eigen::VectorXd& v, int size, bool positive, const char* name,
                     std::string* why) {
  auto fail = [why](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (v.size() != size)
    return fail(std::string(name) + " needs " + std::to_string(size) + " diagonal entries, got " +
                std::to_string(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v(i))) return fail(std::string(name) + " has a non-finite entry");
    if (positive ? !(v(i) > 0.0) : v(i) < 0.0)
      return fail(std::string(name) +
                  (positive ? " entries must be positive" : " entries must not be negative"));
  }
  return true;
}

StateSpace makeSystem(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D) {
  StateSpace s;
  s.A = std::move(A);
  s.B = std::move(B);
  s.C = std::move(C);
  s.D = std::move(D);
  return s;
}

}  // namespace

namespace {

// A gain result carrying the Riccati solution and its report; the caller adds the gain.
GainResult gainFromRiccati(const CareResult& care, const char* what) {
  GainResult r;
  r.termination = care.termination;
  r.message = std::string(what) + ": " + care.message;
  r.residual = care.residual;
  r.seconds = care.seconds;
  r.X = care.X;
  return r;
}

}  // namespace

GainResult lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q1,
               const Eigen::MatrixXd& Q2, const CareOptions& options) {
  GainResult r = gainFromRiccati(solveCare(A, B, Q1, Q2, options), "LQR");
  if (!r.ok()) return r;
  r.gain = Q2.llt().solve(B.transpose() * r.X);
  r.poles = eigenvalues(A - B * r.gain);
  return r;
}

GainResult kalman(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& R1,
                  const Eigen::MatrixXd& R2, const CareOptions& options) {
  GainResult r =
      gainFromRiccati(solveCare(A.transpose(), C.transpose(), R1, R2, options), "Kalman filter");
  if (!r.ok()) return r;
  r.gain = R2.llt().solve(C * r.X).transpose();  // P C' R2^-1 with R2 and P symmetric
  r.poles = eigenvalues(A - r.gain * C);
  return r;
}

LqgOptions LqgOptions::seedCaseI() { return {}; }

LqgOptions LqgOptions::seedCaseII() {
  LqgOptions o;
  o.r2 = Eigen::VectorXd::Constant(1, 1e-8);
  return o;
}

LqgOptions LqgOptions::seedAccelerationFeedback() {
  LqgOptions o;
  o.measurement = LqgMeasurement::MotorAngleAndArmAcceleration;
  o.r2 = Eigen::Vector2d(1e-8, 1e-1);
  return o;
}

bool LqgOptions::isValid(std::string* why) const {
  if (!parameters.isValid(why)) return false;
  if (!diagonalIsValid(q1, designStates(), false, "Q1", why)) return false;
  if (!diagonalIsValid(r1, designStates(), false, "R1", why)) return false;
  if (!diagonalIsValid(r2, measurements(), true, "R2", why)) return false;
  if (!(std::isfinite(q2) && q2 > 0.0)) {
    if (why) *why = "Q2 must be positive";
    return false;
  }
  return care.isValid(why);
}

namespace {

// Real parts above this lie in the open right half plane.
double rightHalfPlaneThreshold(const Eigen::VectorXcd& poles, double relativeTolerance) {
  double radius = 1.0;
  for (Eigen::Index i = 0; i < poles.size(); ++i) radius = std::max(radius, std::abs(poles(i)));
  return relativeTolerance * radius;
}

}  // namespace

int countRightHalfPlane(const Eigen::VectorXcd& poles, double relativeTolerance) {
  const double threshold = rightHalfPlaneThreshold(poles, relativeTolerance);
  return static_cast<int>((poles.real().array() > threshold).count());
}

double rightHalfPlaneRealSum(const Eigen::VectorXcd& poles, double relativeTolerance) {
  const double threshold = rightHalfPlaneThreshold(poles, relativeTolerance);
  double sum = 0.0;
  for (Eigen::Index i = 0; i < poles.size(); ++i)
    if (poles(i).real() > threshold) sum += poles(i).real();
  return sum;
}

std::string LqgDesign::regulatorStability() const {
  if (rhpRegulatorPoles == 0) return "the regulator is stable";
  std::ostringstream s;
  s << "the regulator is unstable: " << rhpRegulatorPoles
    << (rhpRegulatorPoles == 1 ? " pole" : " poles") << " in the RHP";
  return s.str();
}

LqgDesign designLqg(const LqgOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("LqgOptions: " + why);
  const auto start = std::chrono::steady_clock::now();
  LqgDesign d;
  auto finish = [&](Termination t, std::string message) {
    d.termination = t;
    d.message = std::move(message);
    d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return d;
  };
  d.plant = twoMassLqgPlant(options.parameters, options.measurement);
  d.model = options.integralAction ? withArmLoadDisturbanceState(d.plant) : d.plant;
  const int n = d.plant.states();
  const int nm = d.model.states();

  // (8.17) on the controllable four-state arm.
  const Eigen::MatrixXd Q1 = options.q1.head(n).asDiagonal();
  const Eigen::MatrixXd Q2 = Eigen::MatrixXd::Constant(1, 1, options.q2);
  const GainResult state = lqr(d.plant.A, d.plant.B, Q1, Q2, options.care);
  d.lqrResidual = state.residual;
  if (!state.ok()) return finish(state.termination, state.message);
  d.L = Eigen::RowVectorXd::Zero(nm);
  d.L.head(n) = state.gain.row(0);
  if (options.integralAction) {
    // The (1,2) block of the extended Riccati equation (see designLqg's declaration).
    const Eigen::MatrixXd X12 = (d.plant.A - d.plant.B * state.gain)
                                    .transpose()
                                    .partialPivLu()
                                    .solve(-state.X * d.plant.Bv);
    d.L(n) = (d.plant.B.transpose() * X12)(0, 0) / options.q2;
  }
  d.plantPoles = eigenvalues(d.plant.A);
  d.statePoles = state.poles;

  // (8.16) on the design model.
  const Eigen::MatrixXd R1 = options.r1.asDiagonal();
  const Eigen::MatrixXd R2 = options.r2.asDiagonal();
  const GainResult filter = kalman(d.model.A, d.model.C, R1, R2, options.care);
  d.kalmanResidual = filter.residual;
  if (!filter.ok()) return finish(filter.termination, filter.message);
  d.K = filter.gain;
  d.observerPoles = filter.poles;

  const StateSpace fy = regulatorFy(d);
  d.regulatorPoles = eigenvalues(fy.A);
  d.rhpRegulatorPoles = countRightHalfPlane(d.regulatorPoles);
  d.closedLoopPoles = eigenvalues(disturbanceClosedLoop(d).A);
  d.rhpClosedLoopPoles = countRightHalfPlane(d.closedLoopPoles);
  std::ostringstream s;
  s << (d.rhpClosedLoopPoles == 0 ? "stable closed loop; " : "UNSTABLE closed loop; ")
    << d.regulatorStability() << " (Riccati residuals " << d.lqrResidual << ", " << d.kalmanResidual
    << ")";
  return finish(Termination::Converged, s.str());
}

StateSpace plantTransfer(const LqgDesign& d) {
  return makeSystem(d.plant.A, d.plant.B, d.plant.C, Eigen::MatrixXd::Zero(d.plant.C.rows(), 1));
}

StateSpace regulatorFy(const LqgDesign& d) {
  const auto& m = d.model;
  return makeSystem(m.A - m.B * d.L - d.K * m.C, d.K, d.L, Eigen::MatrixXd::Zero(1, d.K.cols()));
}

StateSpace regulatorFr(const LqgDesign& d) {
  const auto& m = d.model;
  return makeSystem(m.A - m.B * d.L - d.K * m.C, m.B, -d.L, Eigen::MatrixXd::Ones(1, 1));
}

StateSpace closedLoopGc(const LqgDesign& d) {
  const auto& m = d.model;
  return makeSystem(m.A - m.B * d.L, m.B, m.C, Eigen::MatrixXd::Zero(m.C.rows(), 1));
}

StateSpace stateFeedbackG0(const LqgDesign& d) {
  const auto& m = d.model;
  return makeSystem(m.A, m.B, d.L, Eigen::MatrixXd::Zero(1, 1));
}

StateSpace disturbanceClosedLoop(const LqgDesign& d) {
  const auto& g = d.plant;
  const auto& m = d.model;
  const int n = g.states(), nm = m.states();
  Eigen::MatrixXd A(n + nm, n + nm), B(n + nm, 2), C = Eigen::MatrixXd::Zero(3, n + nm);
  A << g.A, -g.B * d.L, d.K * g.C, m.A - m.B * d.L - d.K * m.C;
  B << g.Bw, g.Bv, Eigen::MatrixXd::Zero(nm, 1), d.K * g.Dv;
  C(0, 2) = 1.0;                // phi_a
  C(1, 0) = 1.0;                // phi_m
  C.block(2, n, 1, nm) = -d.L;  // u = -L x_hat
  return makeSystem(A, B, C, Eigen::MatrixXd::Zero(3, 2));
}

Eigen::MatrixXcd sensitivity822(const LqgDesign& d, std::complex<double> s) {
  using C = std::complex<double>;
  const auto& m = d.model;
  const int nm = m.states(), p = m.measurements();
  const Eigen::MatrixXcd I = Eigen::MatrixXcd::Identity(nm, nm);
  const Eigen::MatrixXcd Gc =
      m.C.cast<C>() * (s * I - (m.A - m.B * d.L).cast<C>()).partialPivLu().solve(m.B.cast<C>());
  const Eigen::MatrixXcd Fo =
      d.L.cast<C>() * (s * I - (m.A - d.K * m.C).cast<C>()).partialPivLu().solve(d.K.cast<C>());
  return Eigen::MatrixXcd::Identity(p, p) - Gc * Fo;
}

}  // namespace flexarm
