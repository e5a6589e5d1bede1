#pragma once
// Linear time-invariant state-space system x' = Ax + Bu, y = Cx + Du (continuous time) or
// x(k+1) = Ax(k) + Bu(k), y(k) = Cx(k) + Du(k) (discrete time, sampleTime > 0).
#include <Eigen/Dense>
#include <string>

namespace flexarm {

struct StateSpace {
  Eigen::MatrixXd A, B, C, D;
  double sampleTime = 0.0;  // 0 for continuous time, seconds otherwise

  int states() const { return static_cast<int>(A.rows()); }
  int inputs() const { return static_cast<int>(B.cols()); }
  int outputs() const { return static_cast<int>(C.rows()); }
  bool isDiscrete() const { return sampleTime > 0.0; }

  // True when the dimensions agree and all entries are finite; otherwise says why.
  bool isValid(std::string* why = nullptr) const;
};

}  // namespace flexarm
