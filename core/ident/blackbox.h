#pragma once
// Black-box models of the general structure (4.8), A y = B/F u + C/D e, and their estimation
// by prediction error: ARX by least squares via QR (4.13)-(4.16); ARMAX, OE and Box-Jenkins
// by damped Gauss-Newton / Levenberg-Marquardt (4.17)-(4.21) with psi (4.20) from filtering.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/polynomial.h"

namespace flexarm {

// Ss: a state-space model of order n in innovations form (core/ident/subspace.h), kept as its
// ARMAX polynomials (na = nb = nc = n, nk = 1), started by subspace identification and refined
// by prediction error; its spec and name list only n ("ss:4", "ss[4]"), and n = 0 asks the
// data for the order.
enum class PolyStructure { Arx, Armax, Oe, Bj, Ss };
const char* toString(PolyStructure s);
std::optional<PolyStructure> polyStructureFromString(std::string_view s);

// One order of (4.8): the degrees of A, B, C, D, F and the delay nk.
enum class PolyOrder { Na, Nb, Nc, Nd, Nf, Nk };
const char* toString(PolyOrder o);  // "na", "nb", "nc", "nd", "nf", "nk"
// The orders a structure takes, in the order its name ("oe[2 2 1]") and a model spec
// ("oe:2,2,1") list them: arx na nb nk, armax na nb nc nk, oe nb nf nk, bj nb nc nd nf nk.
const std::vector<PolyOrder>& polyOrdersOf(PolyStructure s);
bool takesOrder(PolyStructure s, PolyOrder o);

// Orders of (4.8): na, nb, nc, nd, nf and the delay nk (B = b1 q^{-nk} + ... (4.10)).
struct PolyOrders {
  static constexpr int kMaxOrder = 2000;    // of each polynomial, and of all together
  static constexpr int kMaxDelay = 1000000;  // nk, samples
  int na = 0, nb = 1, nc = 0, nd = 0, nf = 0, nk = 1;
  int& operator[](PolyOrder o);
  int operator[](PolyOrder o) const;
  // These orders with the ones structure s does not take set to 0 (Ss: nb = nc = na, nk = 1).
  PolyOrders of(PolyStructure s) const;
  // The orders of a state-space model of order n (Ss); n = 0: to be chosen by the data.
  static PolyOrders stateSpace(int n);
  // na + nb + nc + nd + nf, computed without overflow (saturates at INT_MAX).
  int parameters() const;
  bool isValid(std::string* why) const;
  // Whether a structure of these orders can be estimated from `samples` samples in bounded
  // time: enough samples after the delay and the longest regressor, and a least-squares
  // problem (samples x parameters^2) of at most a few 1e9 operations per iteration. False
  // with a sentence naming the limit otherwise.
  bool fitsData(PolyStructure s, long long samples, std::string* why) const;
};

// One estimated polynomial model (4.8) with its parameter covariance. The parameter vector is
// [a1..a_na b1..b_nb c1..c_nc d1..d_nd f1..f_nf].
struct PolynomialModel {
  PolyStructure structure = PolyStructure::Arx;
  PolyOrders orders;
  Poly a{1.0}, b{0.0}, c{1.0}, d{1.0}, f{1.0};  // b holds nk leading zeros
  double sampleTime = 1.0;
  double noiseVariance = 0.0;  // lambda, variance of e
  Eigen::MatrixXd covariance;  // of the parameter vector; empty when unknown

  // Short name such as "bj[5 5 5 5 1]".
  std::string name() const;
  Eigen::VectorXd parameterVector() const;
  void setParameterVector(const Eigen::VectorXd& theta);
  std::vector<std::string> parameterNames() const;
  // Standard deviations (square roots of the covariance diagonal), empty when unknown.
  Eigen::VectorXd standardDeviations() const;
  // A model of the given structure and orders with all parameters zero.
  static PolynomialModel zero(PolyStructure s, const PolyOrders& o, double sampleTime);
};

// How an iterative estimate ended, with its statistics.
struct EstimateSummary {
  Termination termination = Termination::Failed;
  std::string message;
  int iterations = 0;
  double seconds = 0.0;
  double loss = 0.0;  // V_N (4.6): mean squared one-step prediction error
  double fpe = 0.0;   // Akaike's final prediction error V (1 + p/N) / (1 - p/N)
  double aic = 0.0;   // N log V + 2 p
  std::vector<double> lossHistory;
  bool ok() const {
    return termination == Termination::Converged || termination == Termination::MaxIterations;
  }
};

struct SubspaceEstimate;
struct PolyEstimate {
  PolynomialModel model;
  EstimateSummary summary;
  // Ss: the subspace estimate the fit started from (singular values, the order and why).
  std::shared_ptr<const SubspaceEstimate> subspace;
};

struct PolyEstimateOptions {
  int maxIterations = 100;
  double relativeTolerance = 1e-7;   // stop when the loss improves by less than this fraction
  double initialDamping = 1e-3;      // Levenberg-Marquardt lambda relative to diag(R) (4.21)
  bool enforceStability = true;      // reflect roots of C, D, F into the unit circle
  // Several experiments: u and y hold them one after another and these are their sample
  // counts (they sum to the samples of u); empty: one experiment. The loss (4.6) is summed
  // over the experiments, each filtered from zero initial conditions at its own first sample
  // with its first max(na, nb + nk - 1, nc, nd, nf) errors left out (ARX: no regressor
  // reaches into another experiment); the covariance comes from the stacked gradient. The
  // start values are computed from the experiments joined (a start only). Iterative
  // structures are then refined with each experiment's errors weighted by
  // sqrt(lambda / lambda_k), lambda_k its noise variance from the first fit and lambda the
  // pooled one (the likelihood's loss for experiments of different noise levels); ARX keeps
  // plain least squares.
  std::vector<Eigen::Index> experimentLengths;
  // Ss: the data were logged in closed loop, so the subspace start takes the predictor route
  // (PBSID), which feedback does not bias.
  bool closedLoop = false;
  bool isValid(std::string* why) const;
};

// ARX by least squares via QR (4.16); any orders (very high order included). u, y equal length;
// experimentLengths as in PolyEstimateOptions (empty: one experiment).
PolyEstimate arx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int na, int nb, int nk,
                 double sampleTime = 1.0, const std::vector<Eigen::Index>& experimentLengths = {});

// Prediction-error estimate of any structure (4.8) by Levenberg-Marquardt (4.17)-(4.21), started
// from SITB-like initial values (ARX, instrumental variables, Hannan-Rissanen for the noise).
PolyEstimate estimatePolynomial(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                PolyStructure structure, const PolyOrders& orders,
                                double sampleTime = 1.0, const PolyEstimateOptions& options = {},
                                const ProgressCallback& progress = {});

// Prediction-error estimate from a given initial model (its structure and orders are kept).
PolyEstimate refinePolynomial(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                              const PolynomialModel& initial,
                              const PolyEstimateOptions& options = {},
                              const ProgressCallback& progress = {});

inline PolyEstimate armax(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int na, int nb,
                          int nc, int nk, double ts = 1.0, const PolyEstimateOptions& o = {}) {
  PolyOrders ord;
  ord.na = na; ord.nb = nb; ord.nc = nc; ord.nk = nk;
  return estimatePolynomial(u, y, PolyStructure::Armax, ord, ts, o);
}
inline PolyEstimate oe(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int nb, int nf,
                       int nk, double ts = 1.0, const PolyEstimateOptions& o = {}) {
  PolyOrders ord;
  ord.nb = nb; ord.nf = nf; ord.nk = nk;
  return estimatePolynomial(u, y, PolyStructure::Oe, ord, ts, o);
}
inline PolyEstimate bj(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int nb, int nc,
                       int nd, int nf, int nk, double ts = 1.0,
                       const PolyEstimateOptions& o = {}) {
  PolyOrders ord;
  ord.nb = nb; ord.nc = nc; ord.nd = nd; ord.nf = nf; ord.nk = nk;
  return estimatePolynomial(u, y, PolyStructure::Bj, ord, ts, o);
}

// One-step prediction errors eps (4.5)-(4.6) of a polynomial model on data.
Eigen::VectorXd predictionErrors(const PolynomialModel& m, const Eigen::VectorXd& u,
                                 const Eigen::VectorXd& y);

}  // namespace flexarm
