#pragma once
// One sample of the extended system (6.27) under a zero-order hold: the predictor state x and,
// for each parameter j, its sensitivity X_j = dx/dtheta_j, carried from t to t+1 at the
// current theta with the input held:
//     x+   = Ad x + Bd u,
//     X_j+ = Ad X_j + dAd_j x + dBd_j u,
// where Ad = e^{AT}, Bd = int_0^T e^{As} ds B and dAd_j, dBd_j their exact derivatives. These
// are the blocks of the exponential of the extended matrix [[A, dA_j], [0, A]] (with the input
// as a constant extra state), so the step is that exponential applied to the extended state.
// It is formed as the exponential's action on the vector (its Taylor series with scaling, to
// double precision, as sampleZoh's matrices are), which costs matrix-vector products of the
// model matrices instead of exponentials of 2(n+1)-square matrices for every parameter.
#include <vector>

#include <Eigen/Dense>

namespace flexarm {

class ExtendedZoh {
 public:
  // Weights of the norm that decides where the series stops: x_i is measured in units of
  // stateScale_i, X_j,i in units of stateScale_i * blockScale_j. scalesFor() chooses them.
  void setScales(const Eigen::VectorXd& stateScale, const Eigen::VectorXd& blockScale);
  // Scales from the balancing of A and the size of each dA_j, dB_j next to A, so that every
  // block of the extended matrix counts alike in the norm.
  void setScalesFor(const Eigen::MatrixXd& A, const std::vector<Eigen::MatrixXd>& dA,
                    const std::vector<Eigen::VectorXd>& dB);

  // Advances x (n) and X (n x p, p = dA.size(), possibly 0) by one sample of length T with u
  // held. A is n x n, B n x 1, dA[j] n x n, dB[j] n x 1.
  void advance(const Eigen::MatrixXd& A, const Eigen::VectorXd& B,
               const std::vector<Eigen::MatrixXd>& dA, const std::vector<Eigen::VectorXd>& dB,
               double T, double u, Eigen::VectorXd& x, Eigen::MatrixXd& X);

  // Terms of the series summed in the last advance() (for tests and the bench).
  int lastTerms() const { return lastTerms_; }

  // Sub-steps one sample may take. A sample time far longer than the model's fastest time
  // scale (a log with a time step of 1e6 s) would need billions: advance() then leaves x NaN
  // and tooLongSubsteps() says how many it would have needed (0 otherwise).
  static constexpr double kMaxSubsteps = 1e5;
  double tooLongSubsteps() const { return tooLong_; }

 private:
  Eigen::VectorXd stateScale_, blockScale_;
  Eigen::MatrixXd weight_;  // of x and each X_j, one column each
  int lastTerms_ = 0;
  double tooLong_ = 0.0;
};

}  // namespace flexarm
