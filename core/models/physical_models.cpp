#include "core/models/physical_models.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace flexarm {

const char* toString(ModelOutput o) {
  return o == ModelOutput::MotorAngle ? "motor-angle" : "motor-velocity";
}

std::optional<ModelOutput> modelOutputFromString(std::string_view s) {
  for (ModelOutput o : {ModelOutput::MotorVelocity, ModelOutput::MotorAngle})
    if (s == toString(o)) return o;
  return std::nullopt;
}

bool ModelOptions::isValid(std::string* why) const {
  if (why) why->clear();
  return true;
}

namespace {

using Dual = PhysicalModel::Dual;

// Forward-mode arithmetic: (v, d) carries a value and its derivative along one parameter.
Dual operator+(Dual a, Dual b) { return {a.v + b.v, a.d + b.d}; }
Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
Dual operator-(Dual a) { return {-a.v, -a.d}; }
Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
Dual operator/(Dual a, Dual b) { return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)}; }
template <class T> T constant(double x) { return T{x}; }
template <> Dual constant<Dual>(double x) { return Dual{x, 0.0}; }

ParameterInfo inertia(const char* name, double v) {
  return {name, "kg m^2", v, 1e-9, 1e6, true};
}
ParameterInfo stiffness(const char* name, double v) {
  return {name, "N m/rad", v, 1e-6, 1e10, true};
}
ParameterInfo damping(const char* name, double v) {
  // The seed reports negative identified dampings (Tables 5.4, 5.7), so they are allowed.
  return {name, "N m s/rad", v, -1e6, 1e6, true};
}
ParameterInfo friction(double v) { return {"f_m", "N m s/rad", v, 0.0, 1e4, true}; }
ParameterInfo gearRatio() { return {"r", "1", 1.0 / 118.0, 1e-4, 1.0, false}; }
ParameterInfo torqueGain() { return {"k_T", "1", 1.0, 1e-3, 1e3, false}; }

// Row-major n x n matrix filled with zeros of type T.
template <class T> std::vector<T> zeros(int n, int m) {
  return std::vector<T>(static_cast<std::size_t>(n * m), constant<T>(0.0));
}

// Rigid model (3.10): (J_m + r^2 J_a) phi_m'' + f_m phi_m' = k_T u; state phi_m'.
// Parameters: J_m, J_a, f_m, r, k_T.
struct Rigid {
  template <class T> static void fill(const std::vector<T>& p, std::vector<T>& A,
                                      std::vector<T>& B) {
    const T &Jm = p[0], &Ja = p[1], &fm = p[2], &r = p[3], &kT = p[4];
    const T J = Jm + r * r * Ja;
    A = {-(fm / J)};
    B = {kT / J};
  }
};

// Two-mass model (3.13): x = (r phi_m - phi_a, phi_m', phi_a').
template <class T> void twoMass(const T& Jm, const T& Ja, const T& fm, const T& k, const T& d,
                                const T& r, const T& kT, std::vector<T>& A, std::vector<T>& B) {
  A = zeros<T>(3, 3);
  B = zeros<T>(3, 1);
  A[1] = r;
  A[2] = constant<T>(-1.0);
  A[3] = -(r * k / Jm);
  A[4] = -((fm + r * r * d) / Jm);
  A[5] = r * d / Jm;
  A[6] = k / Ja;
  A[7] = r * d / Ja;
  A[8] = -(d / Ja);
  B[1] = kT / Jm;
}

// Parameters: J_m, J_a, f_m, k_a, d_a, r, k_T.
struct TwoMass {
  template <class T> static void fill(const std::vector<T>& p, std::vector<T>& A,
                                      std::vector<T>& B) {
    twoMass(p[0], p[1], p[2], p[3], p[4], p[5], p[6], A, B);
  }
};

// (5.5): theta_1..theta_5, r, k_T mapped to the physical parameters of (3.13). Inserted in
// (3.13d) this gives A(2,1) = -r theta_1 and A(2,2) = -theta_5; (5.6) prints both without
// the minus sign. The mapping (5.5) is taken as the definition.
template <class T> void physicalFromTheta(const std::vector<T>& p, T& Jm, T& Ja, T& fm, T& k,
                                          T& d) {
  const T &t1 = p[0], &t2 = p[1], &t3 = p[2], &t4 = p[3], &t5 = p[4], &r = p[5];
  Jm = constant<T>(1.0) / t3;
  Ja = t1 / (t2 * t3);
  fm = t5 / t3 - r * r * t1 * t4 / (t2 * t3);
  k = t1 / t3;
  d = t1 * t4 / (t2 * t3);
}

struct TwoMassTheta {
  template <class T> static void fill(const std::vector<T>& p, std::vector<T>& A,
                                      std::vector<T>& B) {
    T Jm, Ja, fm, k, d;
    physicalFromTheta(p, Jm, Ja, fm, k, d);
    twoMass(Jm, Ja, fm, k, d, p[5], p[6], A, B);
  }
};

// Three-mass model (3.21), x = (r phi_m - phi_g, phi_g - phi_a, phi_m', phi_g', phi_a') (3.20).
// Parameters: J_m, J_g, J_a, f_m, k_g, k_a, d_g, d_a, r, k_T.
struct ThreeMass {
  template <class T> static void fill(const std::vector<T>& p, std::vector<T>& A,
                                      std::vector<T>& B) {
    const T &Jm = p[0], &Jg = p[1], &Ja = p[2], &fm = p[3], &kg = p[4], &ka = p[5],
            &dg = p[6], &da = p[7], &r = p[8], &kT = p[9];
    A = zeros<T>(5, 5);
    B = zeros<T>(5, 1);
    auto a = [&A](int i, int j) -> T& { return A[static_cast<std::size_t>(i * 5 + j)]; };
    a(0, 2) = r;
    a(0, 3) = constant<T>(-1.0);
    a(1, 3) = constant<T>(1.0);
    a(1, 4) = constant<T>(-1.0);
    a(2, 0) = -(kg * r / Jm);  // (3.21); (3.19d) prints -r k_a / J_m here
    a(2, 2) = -((fm + dg * r * r) / Jm);
    a(2, 3) = dg * r / Jm;
    a(3, 0) = kg / Jg;
    a(3, 1) = -(ka / Jg);
    a(3, 2) = dg * r / Jg;
    a(3, 3) = -((dg + da) / Jg);
    a(3, 4) = da / Jg;
    a(4, 1) = ka / Ja;
    a(4, 3) = da / Ja;
    a(4, 4) = -(da / Ja);
    B[2] = kT / Jm;
  }
};

// Four-mass model (3.22), states (3.23): (r phi_m - phi_g, phi_g - phi_a, phi_g - phi_p,
// phi_m', phi_g', phi_a', phi_p'). Parameters: J_m, J_g, J_a, J_p, f_m, k_g, k_a, k_p, d_g,
// d_a, d_p, r, k_T.
struct FourMass {
  template <class T> static void fill(const std::vector<T>& p, std::vector<T>& A,
                                      std::vector<T>& B) {
    const T &Jm = p[0], &Jg = p[1], &Ja = p[2], &Jp = p[3], &fm = p[4], &kg = p[5],
            &ka = p[6], &kp = p[7], &dg = p[8], &da = p[9], &dp = p[10], &r = p[11],
            &kT = p[12];
    A = zeros<T>(7, 7);
    B = zeros<T>(7, 1);
    auto a = [&A](int i, int j) -> T& { return A[static_cast<std::size_t>(i * 7 + j)]; };
    a(0, 3) = r;
    a(0, 4) = constant<T>(-1.0);
    a(1, 4) = constant<T>(1.0);
    a(1, 5) = constant<T>(-1.0);
    a(2, 4) = constant<T>(1.0);
    a(2, 6) = constant<T>(-1.0);
    a(3, 0) = -(kg * r / Jm);
    a(3, 3) = -((fm + dg * r * r) / Jm);
    a(3, 4) = dg * r / Jm;
    a(4, 0) = kg / Jg;
    a(4, 1) = -(ka / Jg);
    a(4, 2) = -(kp / Jg);
    a(4, 3) = dg * r / Jg;
    a(4, 4) = -((dg + da + dp) / Jg);
    a(4, 5) = da / Jg;
    a(4, 6) = dp / Jg;
    a(5, 1) = ka / Ja;
    a(5, 4) = da / Ja;
    a(5, 5) = -(da / Ja);
    a(6, 2) = kp / Jp;
    a(6, 4) = dp / Jp;
    a(6, 6) = -(dp / Jp);
    B[3] = kT / Jm;
  }
};

template <class Impl> class ModelOf : public PhysicalModel {
 public:
  ModelOf(std::string name, std::string description, std::vector<ParameterInfo> params,
          ModelTopology topology, std::vector<std::string> stateNames, ModelOptions options)
      : PhysicalModel(std::move(params), std::move(topology), std::move(stateNames), options),
        name_(std::move(name)),
        description_(std::move(description)) {}
  std::string structureName() const override { return name_; }
  std::string description() const override { return description_; }
  std::unique_ptr<ParametricModel> clone() const override {
    return std::make_unique<ModelOf<Impl>>(*this);
  }
  void core(const std::vector<double>& p, std::vector<double>& A,
            std::vector<double>& B) const override {
    Impl::fill(p, A, B);
  }
  void core(const std::vector<Dual>& p, std::vector<Dual>& A,
            std::vector<Dual>& B) const override {
    Impl::fill(p, A, B);
  }

 private:
  std::string name_, description_;
};

ModelTopology topologyOf(int states, int motorVel, int armVel, int gear, const char* k,
                         const char* d) {
  ModelTopology t;
  t.coreStates = states;
  t.motorVelocityState = motorVel;
  t.armVelocityState = armVel;
  t.gearDeflectionState = gear;
  t.gearStiffness = k;
  t.gearDamping = d;
  return t;
}

}  // namespace

PhysicalModel::PhysicalModel(std::vector<ParameterInfo> params, ModelTopology topology,
                             std::vector<std::string> coreStateNames, ModelOptions options)
    : params_(std::move(params)),
      topology_(std::move(topology)),
      coreStateNames_(std::move(coreStateNames)),
      options_(options) {}

void PhysicalModel::setParameter(const std::string& name, double v) {
  const int i = indexOf(name);
  if (i < 0)
    throw std::invalid_argument("the " + structureName() + " model has no parameter '" + name +
                                "'");
  auto& p = params_[static_cast<std::size_t>(i)];
  if (!std::isfinite(v) || v < p.lower || v > p.upper) {
    std::ostringstream s;
    s << name << " = " << v << " is outside its bounds [" << p.lower << ", " << p.upper << "]";
    throw std::invalid_argument(s.str());
  }
  p.value = v;
}

void PhysicalModel::setFree(const std::string& name, bool isFree) {
  const int i = indexOf(name);
  if (i < 0)
    throw std::invalid_argument("the " + structureName() + " model has no parameter '" + name +
                                "'");
  params_[static_cast<std::size_t>(i)].free = isFree;
}

void PhysicalModel::setBounds(const std::string& name, double lower, double upper) {
  const int i = indexOf(name);
  if (i < 0)
    throw std::invalid_argument("the " + structureName() + " model has no parameter '" + name +
                                "'");
  if (std::isnan(lower) || std::isnan(upper) || !(lower <= upper)) {
    std::ostringstream s;
    s << "the bounds of " << name << " must be an interval LO <= HI, not [" << lower << ", " << upper << "]";
    throw std::invalid_argument(s.str());
  }
  params_[static_cast<std::size_t>(i)].lower = lower;
  params_[static_cast<std::size_t>(i)].upper = upper;
}

double PhysicalModel::value(const std::string& name) const {
  const int i = indexOf(name);
  if (i < 0)
    throw std::invalid_argument("the " + structureName() + " model has no parameter '" + name +
                                "'");
  return params_[static_cast<std::size_t>(i)].value;
}

void PhysicalModel::setOptions(const ModelOptions& o) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("invalid model options: " + why);
  options_ = o;
}

ModelTopology PhysicalModel::topology() const { return topology_; }

std::vector<std::string> PhysicalModel::stateNames() const {
  auto names = coreStateNames_;
  if (options_.output == ModelOutput::MotorAngle) names.push_back("phi_m");
  return names;
}

Eigen::RowVectorXd PhysicalModel::armDeflectionRow() const {
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(topology_.coreStates);
  for (std::size_t i = 0; i < coreStateNames_.size(); ++i) {
    const std::string& n = coreStateNames_[i];
    if (n == "r*phi_m - phi_a" || n == "r*phi_m - phi_g" || n == "phi_g - phi_a") row[static_cast<Eigen::Index>(i)] = 1.0;
  }
  return row;
}

std::vector<std::string> PhysicalModel::outputNames() const {
  std::vector<std::string> names = {options_.output == ModelOutput::MotorAngle ? "phi_m"
                                                                               : "phi_m'"};
  if (options_.armAcceleration) names.push_back("phi_a''");
  return names;
}

// The core matrices from core(), extended with the motor-angle state and the outputs.
template <class T>
void PhysicalModel::assemble(const std::vector<T>& p, std::vector<T>& A, std::vector<T>& B,
                             std::vector<T>& C, std::vector<T>& D, int& n, int& ny) const {
  std::vector<T> Ac, Bc;
  core(p, Ac, Bc);
  const int nc = topology_.coreStates;
  const bool angle = options_.output == ModelOutput::MotorAngle;
  n = nc + (angle ? 1 : 0);
  ny = options_.armAcceleration ? 2 : 1;
  A = zeros<T>(n, n);
  B = zeros<T>(n, 1);
  C = zeros<T>(ny, n);
  D = zeros<T>(ny, 1);
  for (int i = 0; i < nc; ++i) {
    for (int j = 0; j < nc; ++j) A[static_cast<std::size_t>(i * n + j)] = Ac[i * nc + j];
    B[static_cast<std::size_t>(i)] = Bc[static_cast<std::size_t>(i)];
  }
  const int mv = topology_.motorVelocityState;
  if (angle) A[static_cast<std::size_t>((n - 1) * n + mv)] = constant<T>(1.0);
  C[static_cast<std::size_t>(angle ? n - 1 : mv)] = constant<T>(1.0);
  if (options_.armAcceleration) {
    // phi_a'' is the arm-velocity row of x' = Ax + Bu; for the rigid model phi_a = r phi_m.
    const bool rigid = topology_.armVelocityState < 0;
    const int row = rigid ? mv : topology_.armVelocityState;
    const T scale = rigid ? p[static_cast<std::size_t>(indexOf("r"))] : constant<T>(1.0);
    for (int j = 0; j < nc; ++j)
      C[static_cast<std::size_t>(n + j)] = scale * Ac[static_cast<std::size_t>(row * nc + j)];
    D[1] = scale * Bc[static_cast<std::size_t>(row)];
  }
}

namespace {
Eigen::MatrixXd toEigen(const std::vector<double>& v, int rows, int cols) {
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = v[static_cast<std::size_t>(i * cols + j)];
  return m;
}
Eigen::MatrixXd derivativeOf(const std::vector<Dual>& v, int rows, int cols) {
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = v[static_cast<std::size_t>(i * cols + j)].d;
  return m;
}
}  // namespace

StateSpace PhysicalModel::stateSpace() const {
  std::vector<double> p(params_.size()), A, B, C, D;
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = params_[i].value;
  int n = 0, ny = 0;
  assemble(p, A, B, C, D, n, ny);
  StateSpace ss;
  ss.A = toEigen(A, n, n);
  ss.B = toEigen(B, n, 1);
  ss.C = toEigen(C, ny, n);
  ss.D = toEigen(D, ny, 1);
  return ss;
}

StateSpaceDerivative PhysicalModel::derivative(int index) const {
  if (index < 0 || index >= static_cast<int>(params_.size()))
    throw std::invalid_argument("derivative: parameter index " + std::to_string(index) +
                                " out of range");
  std::vector<Dual> p(params_.size()), A, B, C, D;
  for (std::size_t i = 0; i < p.size(); ++i)
    p[i] = Dual{params_[i].value, static_cast<int>(i) == index ? 1.0 : 0.0};
  int n = 0, ny = 0;
  assemble(p, A, B, C, D, n, ny);
  return {derivativeOf(A, n, n), derivativeOf(B, n, 1), derivativeOf(C, ny, n),
          derivativeOf(D, ny, 1)};
}

const std::vector<std::string>& modelStructureNames() {
  static const std::vector<std::string> kNames = {"rigid", "two-mass", "three-mass",
                                                  "four-mass", "two-mass-theta"};
  return kNames;
}

TwoMassPhysical twoMassFromTheta(const double theta[5], double r) {
  std::vector<double> p(theta, theta + 5);
  p.push_back(r);
  TwoMassPhysical out;
  physicalFromTheta(p, out.J_m, out.J_a, out.f_m, out.k, out.d);
  return out;
}

void thetaFromTwoMass(const TwoMassPhysical& p, double r, double theta[5]) {
  theta[2] = 1.0 / p.J_m;
  theta[0] = p.k * theta[2];
  theta[1] = p.k / p.J_a;
  theta[3] = p.d / p.J_a;
  theta[4] = (p.f_m + r * r * p.d) / p.J_m;
}

std::unique_ptr<PhysicalModel> makeModel(const std::string& s, const ModelOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("invalid model options: " + why);
  if (s == "rigid")
    return std::make_unique<ModelOf<Rigid>>(
        s, "Rigid model (3.10): (J_m + r^2 J_a) phi_m'' + f_m phi_m' = k_T u",
        std::vector<ParameterInfo>{inertia("J_m", 9e-4), inertia("J_a", 12.0), friction(0.1),
                                   gearRatio(), torqueGain()},
        topologyOf(1, 0, -1, -1, "", ""), std::vector<std::string>{"phi_m'"}, options);
  if (s == "two-mass")
    // Table 5.2: J_m 9e-4, J_a 12, f_m 0.1, k 1.5e5, d 70.
    return std::make_unique<ModelOf<TwoMass>>(
        s, "Two-mass flexible model (3.13): motor and arm joined by the gear spring k_a, d_a",
        std::vector<ParameterInfo>{inertia("J_m", 9e-4), inertia("J_a", 12.0), friction(0.1),
                                   stiffness("k_a", 1.5e5), damping("d_a", 70.0), gearRatio(),
                                   torqueGain()},
        topologyOf(3, 1, 2, 0, "k_a", "d_a"),
        std::vector<std::string>{"r*phi_m - phi_a", "phi_m'", "phi_a'"}, options);
  if (s == "two-mass-theta") {
    const double r = 1.0 / 118.0;
    double t[5];
    thetaFromTwoMass({9e-4, 12.0, 0.1, 1.5e5, 70.0}, r, t);
    auto theta = [](const char* name, const char* unit, double v) {
      return ParameterInfo{name, unit, v, -1e12, 1e12, true};
    };
    return std::make_unique<ModelOf<TwoMassTheta>>(
        s, "Two-mass model (3.13) in the parameterization (5.5): theta_1 = k/J_m, "
           "theta_2 = k/J_a, theta_3 = 1/J_m, theta_4 = d/J_a, theta_5 = (f_m + r^2 d)/J_m",
        std::vector<ParameterInfo>{theta("theta_1", "1/s^2", t[0]),
                                   theta("theta_2", "1/s^2", t[1]),
                                   theta("theta_3", "1/(kg m^2)", t[2]),
                                   theta("theta_4", "1/s", t[3]),
                                   theta("theta_5", "1/s", t[4]), gearRatio(), torqueGain()},
        topologyOf(3, 1, 2, 0, "", ""),
        std::vector<std::string>{"r*phi_m - phi_a", "phi_m'", "phi_a'"}, options);
  }
  if (s == "three-mass")
    // Table 5.7, model p6 (units as printed: J_m 1e-4, f_m 1e-2, k 1e5).
    return std::make_unique<ModelOf<ThreeMass>>(
        s, "Three-mass flexible model (3.21): motor, gear-side mass J_g and arm J_a",
        std::vector<ParameterInfo>{inertia("J_m", 4.56e-4), inertia("J_g", 9.92),
                                   inertia("J_a", 1.72), friction(3.55e-2),
                                   stiffness("k_g", 1.50e5), stiffness("k_a", 0.446e5),
                                   damping("d_g", -62.0), damping("d_a", 20.0), gearRatio(),
                                   torqueGain()},
        topologyOf(5, 2, 4, 0, "k_g", "d_g"),
        std::vector<std::string>{"r*phi_m - phi_g", "phi_g - phi_a", "phi_m'", "phi_g'",
                                 "phi_a'"},
        options);
  if (s == "four-mass")
    // Table 5.7 p6 plus a parallel mass on the gear-side mass: J_p = 0.3 kg m^2 (about 3 % of
    // J_g) on a spring tuned to 280 rad/s (k_p = J_p 280^2), above the two p6 resonances
    // (157, 209 rad/s), with damping ratio 0.02 (d_p = 2 * 0.02 * sqrt(k_p J_p)).
    return std::make_unique<ModelOf<FourMass>>(
        s, "Four-mass flexible model (3.22): the three-mass model with a parallel mass J_p "
           "on the gear-side mass",
        std::vector<ParameterInfo>{inertia("J_m", 4.56e-4), inertia("J_g", 9.92),
                                   inertia("J_a", 1.72), inertia("J_p", 0.3), friction(3.55e-2),
                                   stiffness("k_g", 1.50e5), stiffness("k_a", 0.446e5),
                                   stiffness("k_p", 0.3 * 280.0 * 280.0),
                                   damping("d_g", -62.0), damping("d_a", 20.0),
                                   damping("d_p", 2.0 * 0.02 * 0.3 * 280.0), gearRatio(),
                                   torqueGain()},
        topologyOf(7, 3, 5, 0, "k_g", "d_g"),
        std::vector<std::string>{"r*phi_m - phi_g", "phi_g - phi_a", "phi_g - phi_p", "phi_m'",
                                 "phi_g'", "phi_a'", "phi_p'"},
        options);
  std::string list;
  for (const auto& n : modelStructureNames()) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown model structure '" + s + "' (expected one of " + list +
                              ")");
}

std::unique_ptr<PhysicalModel> addMass(const PhysicalModel& m, double fraction,
                                       double omega, double zeta) {
  if (!(fraction > 0.0 && fraction < 1.0) || !(omega > 0.0) || !(zeta >= 0.0))
    throw std::invalid_argument(
        "addMass: need 0 < mass fraction < 1, frequency > 0 and damping ratio >= 0");
  const std::string s = m.structureName();
  auto copyCommon = [](const PhysicalModel& from, PhysicalModel& to) {
    for (const char* name : {"J_m", "f_m", "r", "k_T"}) {
      to.setParameter(name, from.value(name));
      to.setFree(name, from.parameters()[static_cast<std::size_t>(from.indexOf(name))].free);
    }
  };
  auto spring = [&](PhysicalModel& to, const char* J, const char* k, const char* d,
                    double inertiaValue) {
    const double kv = inertiaValue * omega * omega;
    to.setParameter(J, inertiaValue);
    to.setParameter(k, kv);
    to.setParameter(d, 2.0 * zeta * std::sqrt(kv * inertiaValue));
  };
  if (s == "rigid") {
    auto out = makeModel("two-mass", m.options());
    copyCommon(m, *out);
    spring(*out, "J_a", "k_a", "d_a", m.value("J_a"));
    return out;
  }
  if (s == "two-mass" || s == "two-mass-theta") {
    const auto* base = &m;
    std::unique_ptr<PhysicalModel> physical;
    if (s == "two-mass-theta") {
      double t[5];
      for (int i = 0; i < 5; ++i) t[i] = m.parameters()[static_cast<std::size_t>(i)].value;
      const TwoMassPhysical q = twoMassFromTheta(t, m.value("r"));
      physical = makeModel("two-mass", m.options());
      physical->setParameter("r", m.value("r"));
      physical->setParameter("k_T", m.value("k_T"));
      physical->setParameter("J_m", q.J_m);
      physical->setParameter("J_a", q.J_a);
      physical->setParameter("f_m", q.f_m);
      physical->setParameter("k_a", q.k);
      physical->setParameter("d_a", q.d);
      base = physical.get();
    }
    auto out = makeModel("three-mass", m.options());
    copyCommon(*base, *out);
    const double Ja = base->value("J_a");
    out->setParameter("J_g", (1.0 - fraction) * Ja);
    out->setParameter("k_g", base->value("k_a"));
    out->setParameter("d_g", base->value("d_a"));
    spring(*out, "J_a", "k_a", "d_a", fraction * Ja);
    return out;
  }
  if (s == "three-mass") {
    auto out = makeModel("four-mass", m.options());
    for (const auto& p : m.parameters()) {
      out->setParameter(p.name, p.value);
      out->setFree(p.name, p.free);
    }
    const double Jg = m.value("J_g");
    out->setParameter("J_g", (1.0 - fraction) * Jg);
    spring(*out, "J_p", "k_p", "d_p", fraction * Jg);
    return out;
  }
  return nullptr;
}

}  // namespace flexarm
