#pragma once
// The one-step predictor of the polynomial structure (4.8) run over a record in one pass: the
// prediction errors eps (4.5) and, for the Gauss-Newton step, the normal equations
// R = sum psi psi^T (4.21) and g = sum psi eps with psi (4.20) formed by filtering. Neither
// psi nor the filtered signals are stored whole: psi's columns are shifts of at most five
// filtered signals, so R and g are inner products of shifted signals (R by its Toeplitz
// blocks), summed block by block while a few hundred samples of each signal are in cache.
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"

namespace flexarm {

class PolyPredictor {
 public:
  // A record for models of the given orders. u and y (equal lengths) are read, not copied:
  // they must outlive the predictor.
  PolyPredictor(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const PolyOrders& orders);

  // Runs the predictor of m (of the orders given above) over the record. Returns the sum of
  // squared errors over the criterion's samples t >= criterionStart(); when R and g are
  // non-null, also the normal equations over the same samples, R = psi^T psi (p x p) and
  // g = psi^T eps with psi = -d eps / d theta (4.20) in the order of parameterVector().
  // Stops as soon as the sum exceeds `bound` and returns that partial sum (R, g unset).
  double run(const PolynomialModel& m, Eigen::MatrixXd* R = nullptr, Eigen::VectorXd* g = nullptr,
             double bound = INFINITY);

  // eps (4.5) of m over the whole record, the first samples included.
  Eigen::VectorXd errors(const PolynomialModel& m);

  // The first sample of the criterion: once every regressor holds data (as ARX does); the
  // zero initial conditions would otherwise dominate the loss of a nearly noise-free system.
  Eigen::Index criterionStart() const { return first_; }
  static Eigen::Index criterionStart(const PolyOrders& o, Eigen::Index samples);

 private:
  // The data u, y; the simulated output w = B/F u; v = A y - w; the errors e = D/C v; and
  // psi's signals yf = D/C y, uf = D/(CF) u, wf = D/(CF) w, ef = 1/C e, vf = 1/C v.
  enum Signal { U, Y, W, V, E, YF, UF, WF, EF, VF, kSignals };
  struct Coefficients;
  // Column j of psi at sample t is sign * signal(t - lag); a block is one signal at rising lags.
  struct Column {
    Signal signal;
    double sign;
    int lag, block;
  };
  static constexpr Eigen::Index kBlock = 512;  // samples run before they are summed

  double evaluate(const PolynomialModel& m, Eigen::MatrixXd* R, Eigen::VectorXd* g, double bound,
                  double* epsOut);
  template <int K, bool Noise, bool HasF, bool Gradient>
  void pass(const Coefficients& c, double* epsOut);
  void startBlock(Eigen::Index t0, Eigen::Index previousLength);
  void prepare(bool gradient, bool noise);
  bool walks(int i, int j) const;
  bool accumulate(Eigen::Index t0, Eigen::Index t1, double* epsOut);
  double valueAt(Signal s, Eigen::Index t) const;
  void finish(Eigen::MatrixXd& R, Eigen::VectorXd& g) const;

  const Eigen::VectorXd& u_;
  const Eigen::VectorXd& y_;
  PolyOrders orders_;
  Eigen::Index n_ = 0, first_ = 0, pad_ = 0, blockStart_ = 0;
  // The first pad_ + kBlock samples of u and y with pad_ zeros in front.
  std::vector<double> uHead_, yHead_;
  // Per signal: the current block with the pad_ samples before it (the filters' past), where
  // base_ points at the block's first sample; and its first samples t <= criterionStart().
  std::array<std::vector<double>, kSignals> block_, head_;
  std::array<const double*, kSignals> base_{};
  // The sums of one run over the criterion's samples: eps^2, psi^T eps without the signs,
  // and the entries of R that are summed over the samples (the others follow by Toeplitz),
  // with the operands of the current block.
  std::vector<Column> columns_;
  std::vector<std::array<int, 2>> direct_;
  std::vector<double> sums_;
  double bound_ = INFINITY;
  std::vector<const double*> left_, right_;
};

}  // namespace flexarm
