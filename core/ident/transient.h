#pragma once
// Step and impulse responses of an estimated model with their confidence bands: the
// deterministic part G of a black-box model (4.8), B / (A F), or a physical model's state
// space sampled with a zero-order hold, from rest. The band at each time is the Gauss
// approximation of Section 4.4.3 carried to the response: var y(t) = J(t) P J(t)^T, J the
// response's derivative along the estimated parameters (central differences) and P their
// covariance, +- z sqrt(var) at the level's two-sided normal quantile. As MATLAB's impulse
// does for sampled systems, the impulse is a pulse of area 1 (height 1 / T over the first
// sample).
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"
#include "core/models/physical_models.h"

namespace flexarm {

enum class TransientKind { Step, Impulse };
const char* toString(TransientKind k);  // "step", "impulse"

struct TransientResponse {
  TransientKind kind = TransientKind::Step;
  double sampleTime = 1.0;
  double level = 0.99;
  std::vector<double> time, value;  // s, the output's unit per unit input (step) or per unit area
  std::vector<double> lower, upper;  // the band; empty without a covariance
  bool hasBand() const { return !lower.empty(); }
};

// The response over `samples` samples (0: until it settles, from the slowest stable pole,
// 50 to 4000 samples). Exactly one of physical and polynomial is given; physical: sampled at
// sampleTime, covariance over parameters()[freeIndices]; polynomial: at its own sample time,
// covariance over its parameter vector. No band when the covariance is empty or does not fit.
// Throws std::invalid_argument for neither or both models or a sample time <= 0.
TransientResponse transientResponse(const PhysicalModel* physical, const Eigen::MatrixXd& covariance,
                                    const std::vector<int>& freeIndices, const PolynomialModel* polynomial,
                                    TransientKind kind, double sampleTime, double level = 0.99, int samples = 0);

}  // namespace flexarm
