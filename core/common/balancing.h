#pragma once
// Diagonal balancing of a square matrix (Parlett-Reinsch): the powers of two d with which
// D^{-1} M D (D = diag(d)) has comparable row and column norms. Physical state vectors mix
// magnitudes (a spring twist of micro-radians next to motor speeds); matrix exponentials and
// norms used to bound series are only accurate on the balanced matrix.
#include <Eigen/Dense>

namespace flexarm {

Eigen::VectorXd balancingScales(const Eigen::MatrixXd& M);

}  // namespace flexarm
