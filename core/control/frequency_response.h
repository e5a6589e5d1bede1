#pragma once
// Frequency responses of continuous-time state-space systems, evaluated many times at little
// cost: the transfer function C (sI - A)^-1 B + D after one Hessenberg reduction of A, so each
// point costs O(n^2) instead of a full factorization.
#include <Eigen/Dense>
#include <complex>

#include "core/common/state_space.h"

namespace flexarm {

class TransferEvaluator {
 public:
  // Throws std::invalid_argument for an invalid or discrete-time system.
  explicit TransferEvaluator(const StateSpace& system);

  // G(s) = C (sI - A)^-1 B + D, outputs x inputs. At an eigenvalue of A the entries are not
  // finite.
  Eigen::MatrixXcd operator()(std::complex<double> s) const;
  // Entry (0,0) of G(s), for single-input single-output use without a matrix result.
  std::complex<double> scalar(std::complex<double> s) const;

  int inputs() const { return static_cast<int>(Bt_.cols()); }
  int outputs() const { return static_cast<int>(Ct_.rows()); }

 private:
  // Solves (sI - H) X = Bt for the Hessenberg H by elimination with adjacent-row pivoting;
  // M (n x n) and X (n x columns) are row-major work arrays, X returns the solution.
  void solve(std::complex<double> s, int columns, std::complex<double>* M,
             std::complex<double>* X) const;

  Eigen::MatrixXd H_, Bt_, Ct_, D_;
};

}  // namespace flexarm
