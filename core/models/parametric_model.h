#pragma once
// A continuous-time linear model whose matrices are functions of named physical parameters,
// with analytic derivatives dA/dθ_i, dB/dθ_i, dC/dθ_i, dD/dθ_i for the gradient (6.27) and
// for prediction-error fitting. Physical models of chapter 3 implement it.
#include <memory>
#include <string>
#include <vector>

#include "core/common/state_space.h"

namespace flexarm {

struct ParameterInfo {
  std::string name;   // e.g. "J_m", as in the seed's Table 3.1
  std::string unit;   // e.g. "kg m^2"
  double value = 0.0;
  double lower = -1e300;  // bounds used by fitting
  double upper = 1e300;
  bool free = true;       // estimated (true) or held fixed (false)
};

// Derivatives of the four matrices with respect to one parameter.
struct StateSpaceDerivative {
  Eigen::MatrixXd dA, dB, dC, dD;
};

class ParametricModel {
 public:
  virtual ~ParametricModel() = default;

  // Structure name as used on the command line, e.g. "two-mass".
  virtual std::string structureName() const = 0;
  virtual std::unique_ptr<ParametricModel> clone() const = 0;

  // All parameters, free and fixed, in a fixed order.
  virtual const std::vector<ParameterInfo>& parameters() const = 0;
  // Sets one parameter's value; throws std::invalid_argument for an unknown name.
  virtual void setParameter(const std::string& name, double value) = 0;
  virtual void setFree(const std::string& name, bool isFree) = 0;

  // Matrices at the current parameter values.
  virtual StateSpace stateSpace() const = 0;
  // Analytic derivative with respect to parameters()[index], free or not.
  virtual StateSpaceDerivative derivative(int index) const = 0;

  // Index of a parameter by name, or -1.
  int indexOf(const std::string& name) const {
    const auto& p = parameters();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p[i].name == name) return static_cast<int>(i);
    return -1;
  }
};

}  // namespace flexarm
