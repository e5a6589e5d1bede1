#pragma once
// A test-local two-mass flexible model (3.13): states [r phi_m - phi_a, phi_m', phi_a'], input
// the motor torque, output the motor velocity; parameters J_m, J_a, f_m, k, d and the gear
// ratio r (fixed). Used to exercise the grey-box estimator through the ParametricModel
// interface only.
#include <memory>
#include <stdexcept>

#include "core/models/parametric_model.h"

namespace flexarm::testing {

class TwoMassTestModel : public ParametricModel {
 public:
  // Nominal values of the seed's Table 5.2; r chosen so that the peak lies near 155 rad/s.
  TwoMassTestModel() {
    params_ = {{"J_m", "kg m^2", 9e-4, 0.0, 1e300, true},
               {"J_a", "kg m^2", 12.0, 0.0, 1e300, true},
               {"f_m", "N m s/rad", 0.1, 0.0, 1e300, true},
               {"k", "N m/rad", 1.5e5, 0.0, 1e300, true},
               {"d", "N m s/rad", 70.0, -1e300, 1e300, true},
               {"r", "", 1.0 / 120.0, 0.0, 1e300, false}};
  }
  std::string structureName() const override { return "two-mass-test"; }
  std::unique_ptr<ParametricModel> clone() const override {
    return std::make_unique<TwoMassTestModel>(*this);
  }
  const std::vector<ParameterInfo>& parameters() const override { return params_; }
  void setParameter(const std::string& name, double value) override {
    const int i = indexOf(name);
    if (i < 0) throw std::invalid_argument("unknown parameter " + name);
    params_[i].value = value;
  }
  void setFree(const std::string& name, bool isFree) override {
    const int i = indexOf(name);
    if (i < 0) throw std::invalid_argument("unknown parameter " + name);
    params_[i].free = isFree;
  }
  StateSpace stateSpace() const override {
    const double Jm = v(0), Ja = v(1), fm = v(2), k = v(3), d = v(4), r = v(5);
    if (!(Jm > 0.0) || !(Ja > 0.0)) throw std::invalid_argument("inertias must be positive");
    StateSpace s;
    s.A.resize(3, 3);
    s.A << 0, r, -1,                               //
        -r * k / Jm, -(fm + r * r * d) / Jm, r * d / Jm,  //
        k / Ja, r * d / Ja, -d / Ja;
    s.B = Eigen::MatrixXd::Zero(3, 1);
    s.B(1, 0) = 1.0 / Jm;
    s.C = Eigen::MatrixXd::Zero(1, 3);
    s.C(0, 1) = 1.0;
    s.D = Eigen::MatrixXd::Zero(1, 1);
    return s;
  }
  StateSpaceDerivative derivative(int index) const override {
    const double Jm = v(0), Ja = v(1), k = v(3), d = v(4), r = v(5);
    const StateSpace s = stateSpace();
    StateSpaceDerivative g{Eigen::MatrixXd::Zero(3, 3), Eigen::MatrixXd::Zero(3, 1),
                           Eigen::MatrixXd::Zero(1, 3), Eigen::MatrixXd::Zero(1, 1)};
    switch (index) {
      case 0:  // J_m scales the second row by 1/J_m
        g.dA.row(1) = -s.A.row(1) / Jm;
        g.dB(1, 0) = -1.0 / (Jm * Jm);
        break;
      case 1: g.dA.row(2) = -s.A.row(2) / Ja; break;
      case 2: g.dA(1, 1) = -1.0 / Jm; break;
      case 3:
        g.dA(1, 0) = -r / Jm;
        g.dA(2, 0) = 1.0 / Ja;
        break;
      case 4:
        g.dA(1, 1) = -r * r / Jm;
        g.dA(1, 2) = r / Jm;
        g.dA(2, 1) = r / Ja;
        g.dA(2, 2) = -1.0 / Ja;
        break;
      case 5:
        g.dA(0, 1) = 1.0;
        g.dA(1, 0) = -k / Jm;
        g.dA(1, 1) = -2.0 * r * d / Jm;
        g.dA(1, 2) = d / Jm;
        g.dA(2, 1) = d / Ja;
        break;
      default: throw std::invalid_argument("parameter index out of range");
    }
    return g;
  }

 private:
  double v(int i) const { return params_[i].value; }
  std::vector<ParameterInfo> params_;
};

// Output of x' = A x + B u with u held constant over each sample (zero-order hold),
// integrated by RK4 with `substeps` steps per sample: independent of the matrix exponential.
inline Eigen::VectorXd rk4Simulate(const StateSpace& s, const Eigen::VectorXd& u, double T,
                                   int substeps = 20) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.states()), y(u.size());
  const double h = T / substeps;
  for (Eigen::Index t = 0; t < u.size(); ++t) {
    y[t] = (s.C * x)(0) + s.D(0, 0) * u[t];
    const Eigen::VectorXd bu = s.B.col(0) * u[t];
    for (int i = 0; i < substeps; ++i) {
      const Eigen::VectorXd k1 = s.A * x + bu;
      const Eigen::VectorXd k2 = s.A * (x + 0.5 * h * k1) + bu;
      const Eigen::VectorXd k3 = s.A * (x + 0.5 * h * k2) + bu;
      const Eigen::VectorXd k4 = s.A * (x + h * k3) + bu;
      x += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
  }
  return y;
}

}  // namespace flexarm::testing
