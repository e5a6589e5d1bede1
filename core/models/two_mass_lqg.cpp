#include "core/models/two_mass_lqg.h"

#include <cmath>
#include <stdexcept>

namespace flexarm {
namespace {

double* field(TwoMassLqgParameters& p, const std::string& name) {
  if (name == "J_m") return &p.Jm;
  if (name == "J_a") return &p.Ja;
  if (name == "f_m") return &p.fm;
  if (name == "f_a") return &p.fa;
  if (name == "k") return &p.k;
  if (name == "d") return &p.d;
  throw std::invalid_argument("unknown two-mass parameter '" + name +
                              "' (expected J_m, J_a, f_m, f_a, k or d)");
}

}  // namespace

const std::vector<std::string>& TwoMassLqgParameters::names() {
  static const std::vector<std::string> kNames = {"J_m", "J_a", "f_m", "f_a", "k", "d"};
  return kNames;
}

std::string TwoMassLqgParameters::unit(const std::string& name) {
  TwoMassLqgParameters probe;
  field(probe, name);  // throws for an unknown name
  if (name == "J_m" || name == "J_a") return "kg m^2";
  if (name == "k") return "N m/rad";
  return "N m s/rad";
}

double TwoMassLqgParameters::get(const std::string& name) const {
  TwoMassLqgParameters copy = *this;
  return *field(copy, name);
}

void TwoMassLqgParameters::set(const std::string& name, double value) {
  *field(*this, name) = value;
}

bool TwoMassLqgParameters::isValid(std::string* why) const {
  auto fail = [why](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  for (const auto& n : names())
    if (!std::isfinite(get(n))) return fail("parameter " + n + " is not finite");
  if (Jm <= 0.0) return fail("J_m must be positive");
  if (Ja <= 0.0) return fail("J_a must be positive");
  if (k <= 0.0) return fail("k must be positive");
  if (fm < 0.0) return fail("f_m must not be negative");
  if (fa < 0.0) return fail("f_a must not be negative");
  if (d < 0.0) return fail("d must not be negative");
  return true;
}

const char* toString(LqgMeasurement m) {
  switch (m) {
    case LqgMeasurement::MotorAngle:
      return "motor-angle";
    case LqgMeasurement::MotorAngleAndArmAcceleration:
      return "motor-angle+arm-acceleration";
  }
  return "?";
}

std::optional<LqgMeasurement> lqgMeasurementFromString(std::string_view s) {
  for (auto m : {LqgMeasurement::MotorAngle, LqgMeasurement::MotorAngleAndArmAcceleration})
    if (s == toString(m)) return m;
  return std::nullopt;
}

TwoMassLqgPlant twoMassLqgPlant(const TwoMassLqgParameters& p, LqgMeasurement m) {
  std::string why;
  if (!p.isValid(&why)) throw std::invalid_argument("two-mass model: " + why);
  TwoMassLqgPlant g;
  // (8.4)
  g.A.resize(4, 4);
  g.A << 0, 1, 0, 0,                                              //
      -p.k / p.Jm, -(p.d + p.fm) / p.Jm, p.k / p.Jm, p.d / p.Jm,  //
      0, 0, 0, 1,                                                 //
      p.k / p.Ja, p.d / p.Ja, -p.k / p.Ja, -(p.d + p.fa) / p.Ja;
  g.B = Eigen::MatrixXd::Zero(4, 1);  // (8.5)
  g.B(1, 0) = 1.0 / p.Jm;
  g.Bw = g.B;
  g.Bv = Eigen::MatrixXd::Zero(4, 1);
  g.Bv(3, 0) = 1.0 / p.Ja;
  if (m == LqgMeasurement::MotorAngle) {
    g.C = Eigen::MatrixXd::Zero(1, 4);  // (8.6)
    g.C(0, 0) = 1.0;
    g.Dv = Eigen::MatrixXd::Zero(1, 1);
  } else {
    g.C = Eigen::MatrixXd::Zero(2, 4);  // (8.42): the second row is the fourth row of A
    g.C(0, 0) = 1.0;
    g.C.row(1) = g.A.row(3);
    g.Dv = Eigen::MatrixXd::Zero(2, 1);
    g.Dv(1, 0) = 1.0 / p.Ja;
  }
  return g;
}

TwoMassLqgPlant withArmLoadDisturbanceState(const TwoMassLqgPlant& g) {
  const int n = g.states();
  TwoMassLqgPlant e;
  e.A = Eigen::MatrixXd::Zero(n + 1, n + 1);
  e.A.topLeftCorner(n, n) = g.A;
  e.A.topRightCorner(n, 1) = g.Bv;
  auto pad = [n](const Eigen::MatrixXd& M) {
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n + 1, M.cols());
    out.topRows(n) = M;
    return out;
  };
  e.B = pad(g.B);
  e.Bw = pad(g.Bw);
  e.Bv = pad(g.Bv);
  e.C.resize(g.C.rows(), n + 1);
  e.C << g.C, g.Dv;
  e.Dv = g.Dv;
  return e;
}

std::complex<double> armFromMotorResponse(const TwoMassLqgParameters& p, std::complex<double> s) {
  return (p.d * s + p.k) / (p.Ja * s * s + (p.d + p.fa) * s + p.k);
}

}  // namespace flexarm
