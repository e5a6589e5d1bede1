// theta's entries and the seed's R1, shared by the estimator and the pre-run for P(0).
#include "core/recursive/theta.h"

#include <sstream>
#include <stdexcept>

namespace flexarm {

namespace {
constexpr const char* kInverseSuffix = "^-1";

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

std::vector<RecursiveParameter> resolveParameters(const ParametricModel& model,
                                                  const RecursiveOptions& options) {
  std::vector<RecursiveParameter> out;
  for (const std::string& entry : options.estimate) {
    RecursiveParameter p;
    p.modelName = entry;
    if (endsWith(entry, kInverseSuffix)) {
      p.modelName = entry.substr(0, entry.size() - std::string(kInverseSuffix).size());
      p.inverted = true;
    }
    for (const auto& inv : options.inverted)
      if (inv == p.modelName) p.inverted = true;
    p.modelIndex = model.indexOf(p.modelName);
    if (p.modelIndex < 0)
      throw std::invalid_argument("the " + model.structureName() + " model has no parameter '" +
                                  p.modelName + "' to estimate");
    for (const auto& q : out)
      if (q.modelIndex == p.modelIndex)
        throw std::invalid_argument("'" + p.modelName + "' is estimated twice");
    const ParameterInfo& info = model.parameters()[static_cast<std::size_t>(p.modelIndex)];
    p.modelUnit = info.unit;
    if (p.inverted) {
      if (!(info.lower > 0.0) || !(info.value > 0.0))
        throw std::invalid_argument("theta can hold the inverse of " + p.modelName +
                                    " only when it is positive by its bounds");
      p.name = p.modelName + kInverseSuffix;
      p.unit = info.unit == "1" ? "1" : "1/(" + info.unit + ")";
      p.nominal = 1.0 / info.value;
      p.lower = 1.0 / info.upper;
      p.upper = 1.0 / info.lower;
    } else {
      p.name = p.modelName;
      p.unit = info.unit;
      p.nominal = info.value;
      p.lower = info.lower;
      p.upper = info.upper;
    }
    out.push_back(p);
  }
  return out;
}

Eigen::VectorXd kalmanR1(const std::vector<RecursiveParameter>& params,
                         const RecursiveOptions& options) {
  const auto p = static_cast<Eigen::Index>(params.size());
  Eigen::VectorXd r1 = Eigen::VectorXd::Zero(p);
  if (options.algorithm != RecursiveAlgorithm::Kalman) return r1;
  if (!options.r1.empty()) {
    for (Eigen::Index i = 0; i < p; ++i) r1[i] = options.r1[static_cast<std::size_t>(i)];
    return r1;
  }
  for (Eigen::Index i = 0; i < p; ++i) {
    const std::string& name = params[static_cast<std::size_t>(i)].name;
    if (name == "k_T") r1[i] = 5e-8;            // (6.54): rho * 5, rho = 1e-8
    else if (name == "J_a^-1") r1[i] = 5e-7;    //         rho * 50
    else if (name == "f_m") r1[i] = 5e-6;       //         rho * 500
    else
      throw std::invalid_argument("R1 has no seed value for " + name +
                                  "; give R1 (one value per estimated parameter)");
  }
  return r1;
}

std::string formatNumber(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

}  // namespace flexarm
