#pragma once
// State-space models of a single-input single-output system by subspace identification, in
// innovations form
//   x(t+1) = A x(t) + B u(t) + K e(t),   y(t) = C x(t) + e(t)        (no feed-through, D = 0)
// with e white of variance lambda. Two routes to the same model:
//   - the open-loop family (N4SID, MOESP, CVA): block Hankel matrices of past and future
//     inputs and outputs, the oblique projection of the future outputs along the future
//     inputs onto the past data, a weighted SVD whose leading left singular vectors span the
//     extended observability matrix Gamma_f; A and C from its shift invariance, then B, K and
//     the initial state by least squares on y = C (qI - A)^{-1} (B u + K e_hat) + e_hat, with
//     e_hat the innovations of a high-order ARX model. The weightings are W1 = I, W2 = I
//     (N4SID), W2 = the projection orthogonal to the future inputs (MOESP) and, in addition,
//     W1 = (Y_f Pi_Uf^perp Y_f^T)^{-1/2} (CVA). The future inputs are correlated with the past
//     noise when the data are taken in closed loop, which biases these three;
//   - the predictor route (PBSID-opt): a high-order ARX (VARX) model of the predictor,
//     y(t) = sum_k C A~^{k-1} [B K] z(t-k) + e(t), A~ = A - K C, z = [u; y], is consistent in
//     closed loop too; its Markov parameters build Gamma~_f times the state's past-data
//     map, whose SVD gives the state sequence; C from y = C x + e, then A, B and K from
//     x(t+1) = A x + B u + K e.
// The order is the one of least MDL, N log V_n + 3 n log N, over n = 1..maxOrder, V_n the
// one-step prediction-error loss (4.6) of the order-n model on the estimation data; the
// singular values are kept beside it so a user sees the gap that supports the choice. The
// model converts exactly to ARMAX polynomials (4.8), A(q) y = B(q) u + C(q) e with
// na = nb = nc = n and nk = 1: A(q) = det(I - A q^{-1}), C(q) = det(I - (A - K C) q^{-1}) and
// B(q) = det(I - (A - B C) q^{-1}) - A(q), which is how FlexArm refines it by prediction error
// (the start of an ss fit) and evaluates it everywhere else.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"

namespace flexarm {

enum class SubspaceMethod { Auto, N4sid, Moesp, Cva, Pbsid };
const char* toString(SubspaceMethod m);  // "auto", "n4sid", "moesp", "cva", "pbsid"
std::optional<SubspaceMethod> subspaceMethodFromString(std::string_view s);

struct SubspaceOptions {
  static constexpr int kMaxOrder = 40;
  static constexpr int kMaxHorizon = 200;
  SubspaceMethod method = SubspaceMethod::Auto;  // Auto: Pbsid in closed loop, Cva otherwise
  bool closedLoop = false;                       // the data were logged under feedback
  int order = 0;     // n; 0: the order of least MDL up to maxOrder
  int maxOrder = 12;
  // Past and future horizon p (block rows); 0: the ARX order of least AIC between
  // maxOrder + 1 and min(kMaxHorizon, N / 20), which makes A~^p small.
  int horizon = 0;
  // Several experiments, as in PolyEstimateOptions (empty: one).
  std::vector<Eigen::Index> experimentLengths;
  bool isValid(std::string* why) const;
};

// The discrete-time innovations model, sample time T.
struct InnovationsModel {
  Eigen::MatrixXd A;
  Eigen::VectorXd B, C, K;  // C as a column: y = C^T x + e
  double sampleTime = 1.0;
  double noiseVariance = 0.0;
  int order() const { return static_cast<int>(A.rows()); }
  // The same model as ARMAX polynomials (na = nb = nc = n, nk = 1), structure Ss.
  PolynomialModel polynomial() const;
};

// One order tried.
struct SubspaceOrder {
  int order = 0;
  double loss = 0.0;  // V_n, mean squared one-step prediction error on the estimation data
  double mdl = 0.0;   // N log V_n + 3 n log N
  bool stablePredictor = true;  // the eigenvalues of A - K C inside the unit circle
};

struct SubspaceEstimate {
  bool ok = false;
  std::string message;           // why not, when !ok
  SubspaceMethod method = SubspaceMethod::Cva;  // the one used (Auto resolved)
  int horizon = 0;                // p = f
  std::vector<double> singularValues;  // of the weighted matrix, largest first
  std::vector<SubspaceOrder> orders;   // every order tried (one when the order was given)
  int chosenOrder = 0;
  std::string orderReason;        // "n = 4: least MDL of orders 1-12; ..."
  InnovationsModel model;
};

// Subspace estimate of u -> y. Throws std::invalid_argument for u, y of different lengths or
// invalid options; a result with ok = false and a sentence for data that cannot carry it.
SubspaceEstimate subspaceEstimate(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                  double sampleTime, const SubspaceOptions& options = {});

// One-step prediction errors of an innovations model from zero initial state.
Eigen::VectorXd innovationErrors(const InnovationsModel& m, const Eigen::VectorXd& u,
                                 const Eigen::VectorXd& y);

}  // namespace flexarm
