#pragma once
// theta's entries from RecursiveOptions and the seed's R1 (6.54), shared by the estimator and
// the pre-run that chooses P(0).
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/recursive/rpem.h"

namespace flexarm {

// theta's entries from the options' names: "NAME^-1", or NAME listed in `inverted`, is held
// as its inverse. Throws std::invalid_argument for a name the model lacks, a name given twice
// or an inverse of a parameter whose bounds include zero.
std::vector<RecursiveParameter> resolveParameters(const ParametricModel& model,
                                                  const RecursiveOptions& options);

// diag R1 of Algorithm 6.2: the options' values, else the seed's (6.54) by theta's name
// (k_T 5e-8, J_a^-1 5e-7, f_m 5e-6); zeros for the forgetting-factor algorithm. Throws
// std::invalid_argument for a parameter without a seed value when none is given.
Eigen::VectorXd kalmanR1(const std::vector<RecursiveParameter>& params,
                         const RecursiveOptions& options);

// A number in messages: six significant digits, no trailing zeros.
std::string formatNumber(double v);

}  // namespace flexarm
