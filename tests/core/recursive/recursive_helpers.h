#pragma once
// Shared by the recursive-identification tests: the seed's three-mass arm (Table 5.7 p6, the
// truth of the chapter-6/7 sample logs), a first-order model for Example 6.1, and open-loop
// data simulated exactly under a zero-order hold.
#include <memory>
#include <random>

#include <Eigen/Dense>

#include "core/ident/pem.h"
#include "core/models/physical_models.h"

namespace flexarm::testing {

// Table 5.7 p6, as sample_logs/diagnosis_no_fault.truth.json holds it.
inline std::unique_ptr<PhysicalModel> threeMassP6() {
  auto m = makeModel("three-mass");
  m->setParameter("J_m", 0.000456);
  m->setParameter("J_g", 9.92);
  m->setParameter("J_a", 1.72);
  m->setParameter("f_m", 0.0355);
  m->setParameter("k_g", 150000.0);
  m->setParameter("k_a", 44600.0);
  m->setParameter("d_g", -62.0);
  m->setParameter("d_a", 20.0);
  return m;
}

inline Eigen::VectorXd gaussian(Eigen::Index n, double sigma, std::mt19937& rng) {
  std::normal_distribution<double> nd(0.0, sigma);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = nd(rng);
  return x;
}

// The first-order system of Example 6.1 in continuous time: x' = -a x + theta u, y = x. Sampled
// with a zero-order hold it is y(t) = theta beta / (1 - alpha q^-1) q^-1 u(t) with
// alpha = e^{-aT}, beta = (1 - alpha) / a: the gain theta of (6.42), one sample later.
class FirstOrderModel : public ParametricModel {
 public:
  FirstOrderModel(double a, double theta, double thetaLower = -1e6) {
    params_ = {{"a", "1/s", a, 1e-6, 1e6, false}, {"theta", "1", theta, thetaLower, 1e6, true}};
  }
  std::string structureName() const override { return "first-order"; }
  std::unique_ptr<ParametricModel> clone() const override {
    return std::make_unique<FirstOrderModel>(*this);
  }
  const std::vector<ParameterInfo>& parameters() const override { return params_; }
  void setParameter(const std::string& name, double value) override {
    const int i = indexOf(name);
    if (i < 0) throw std::invalid_argument("no parameter " + name);
    auto& p = params_[static_cast<std::size_t>(i)];
    if (!(value >= p.lower && value <= p.upper)) throw std::invalid_argument(name + " out of bounds");
    p.value = value;
  }
  void setFree(const std::string& name, bool isFree) override {
    params_[static_cast<std::size_t>(indexOf(name))].free = isFree;
  }
  StateSpace stateSpace() const override {
    StateSpace s;
    s.A = Eigen::MatrixXd::Constant(1, 1, -params_[0].value);
    s.B = Eigen::MatrixXd::Constant(1, 1, params_[1].value);
    s.C = Eigen::MatrixXd::Ones(1, 1);
    s.D = Eigen::MatrixXd::Zero(1, 1);
    return s;
  }
  StateSpaceDerivative derivative(int index) const override {
    StateSpaceDerivative d;
    d.dA = Eigen::MatrixXd::Constant(1, 1, index == 0 ? -1.0 : 0.0);
    d.dB = Eigen::MatrixXd::Constant(1, 1, index == 1 ? 1.0 : 0.0);
    d.dC = Eigen::MatrixXd::Zero(1, 1);
    d.dD = Eigen::MatrixXd::Zero(1, 1);
    return d;
  }

 private:
  std::vector<ParameterInfo> params_;
};

}  // namespace flexarm::testing
