// The recursive estimator of chapter 6, one sample at a time.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/ident/pem.h"
#include "core/recursive/covariance_update.h"
#include "core/recursive/extended_zoh.h"
#include "core/recursive/rpem.h"
#include "core/recursive/theta.h"

namespace flexarm {

namespace {

}  // namespace

// A model owned by value: copies clone it, so that the estimator's state copies as a whole.
class OwnedModel {
 public:
  explicit OwnedModel(const ParametricModel& m) : p_(m.clone()) {}
  OwnedModel(const OwnedModel& o) : p_(o.p_->clone()) {}
  OwnedModel& operator=(const OwnedModel& o) {
    if (this != &o) p_ = o.p_->clone();
    return *this;
  }
  ParametricModel* operator->() const { return p_.get(); }
  const ParametricModel& operator*() const { return *p_; }

 private:
  std::unique_ptr<ParametricModel> p_;
};

// A copy of an estimator's state owned by value (a hypothesis of the bank); copies are deep,
// so that a copied estimator's bank continues on its own.
class ImplCopy {
 public:
  explicit ImplCopy(std::unique_ptr<RecursiveEstimator::Impl> p);
  ImplCopy(const ImplCopy& o);
  ImplCopy& operator=(const ImplCopy& o);
  ImplCopy(ImplCopy&&) noexcept = default;
  ImplCopy& operator=(ImplCopy&&) noexcept = default;
  ~ImplCopy();
  RecursiveEstimator::Impl& operator*() const { return *p_; }
  RecursiveEstimator::Impl* operator->() const { return p_.get(); }

 private:
  std::unique_ptr<RecursiveEstimator::Impl> p_;
};

// An estimator of the bank: started at `start` (s), with the sums of squared prediction errors
// since then of its own and of the running estimate.
struct Hypothesis {
  double start = 0.0;
  ImplCopy estimator;
  double own = 0.0, running = 0.0;
};

struct RecursiveEstimator::Impl {
  OwnedModel model;  // holds theta's current values
  double T = 0.0, startTime = 0.0;
  RecursiveOptions options;
  std::vector<RecursiveParameter> params;
  Eigen::VectorXd theta0, theta, thetaNew;
  Eigen::VectorXd evaluatedAt;  // theta at which A, B, C, D and the derivatives were formed
  Eigen::MatrixXd P0, P, Pnew;
  CovarianceUpdate update;
  ExtendedZoh zoh;
  Eigen::Index n = 0, p = 0;

  // The predictor of the next sample, at theta(t-1): state, sensitivities, output matrices.
  Eigen::VectorXd x;
  Eigen::MatrixXd X;
  Eigen::RowVectorXd C;
  double D = 0.0;
  Eigen::MatrixXd dC;  // p x n
  Eigen::VectorXd dD;  // p
  // Difference gradient (6.33): the next sample's state and output matrices at theta +- Delta/2.
  std::vector<Eigen::VectorXd> xPlus, xMinus;
  std::vector<Eigen::RowVectorXd> cPlus, cMinus;
  Eigen::VectorXd dPlus, dMinus, delta;

  // Model matrices at the values last set.
  Eigen::MatrixXd A;
  Eigen::VectorXd B;
  std::vector<Eigen::MatrixXd> dA;
  std::vector<Eigen::VectorXd> dB;
  std::vector<Eigen::MatrixXd> noDerivatives;
  std::vector<Eigen::VectorXd> noInputDerivatives;
  Eigen::MatrixXd noSensitivities;

  // A theta that never moves (updateParameters false, or nothing estimated: the pre-run for
  // P(0), a fixed predictor): the model is sampled once with sampleZoh's exact matrices and
  // their derivatives, and the predictor runs on products.
  bool fixedTheta = false;
  SampledModel fixed;                               // at theta, derivatives in theta's coordinates
  std::vector<SampledModel> fixedPlus, fixedMinus;  // difference gradient: theta +- Delta/2
  Eigen::VectorXd scratch;

  RecursiveStep step;
  Eigen::VectorXd psi, gain;
  std::size_t count = 0;
  std::size_t heldRun = 0, heldTotal = 0;  // samples held at the bounds: in a row, in all
  double heldSince = 0.0;
  std::string firstHeld;
  bool good = true;
  std::string message;
  double lambda0 = 0.0;
  // The noise variance the tracking compares with: options.noiseVariance, else estimated with
  // the prediction errors clipped at 3 sigma once one memory has passed, so that the errors
  // after a change do not raise it.
  double trackingVariance = 0.0;
  // The bank of hypothesised change times (RecursiveTracking::Bank).
  std::vector<Hypothesis> bank;
  std::size_t nextHypothesis = 0;
  // The weight of one sample in the bank's sums: T / designSampleTime, so that they count per
  // design sample (5 ms) and the threshold means the same at any rate (the prediction errors
  // of a faster log are no more independent per second).
  double sampleWeight = 1.0;
  std::size_t changes = 0;  // accepted so far
  double lastChange = 0.0;  // the hypothesised time of the last one, s

  Impl(const ParametricModel& nominal, double sampleTime, const RecursiveOptions& o, double t0)
      : model(nominal),
        T(sampleTime),
        startTime(t0),
        options(o),
        update(o.algorithm, o.lambda, Eigen::VectorXd(), o.r2, o.mu) {}

  double timeOf(std::size_t index) const { return startTime + static_cast<double>(index) * T; }

  // Sets the model's parameters to theta's values th; false (with a sentence) when the model
  // refuses one of them.
  bool setTheta(const Eigen::VectorXd& th, std::string* why) {
    for (Eigen::Index i = 0; i < p; ++i) {
      const RecursiveParameter& q = params[static_cast<std::size_t>(i)];
      try {
        model->setParameter(q.modelName, q.toModel(th[i]));
      } catch (const std::invalid_argument& e) {
        if (why) *why = e.what();
        return false;
      }
    }
    return true;
  }

  // A, B, C, D at the model's values and, when asked, the derivatives along theta (the
  // model's exact derivatives, times d value / d theta = -value^2 for an inverse).
  void evaluate(bool withDerivatives, Eigen::RowVectorXd& c, double& d) {
    const StateSpace ss = model->stateSpace();
    A = ss.A;
    B = ss.B.col(0);
    c = ss.C.row(0);
    d = ss.D(0, 0);
    if (!withDerivatives) return;
    for (Eigen::Index j = 0; j < p; ++j) {
      const RecursiveParameter& q = params[static_cast<std::size_t>(j)];
      const StateSpaceDerivative der = model->derivative(q.modelIndex);
      const double value = model->parameters()[static_cast<std::size_t>(q.modelIndex)].value;
      const double chain = q.inverted ? -value * value : 1.0;
      const auto sj = static_cast<std::size_t>(j);
      dA[sj] = der.dA.size() ? Eigen::MatrixXd(der.dA * chain) : Eigen::MatrixXd::Zero(n, n);
      dB[sj] = der.dB.size() ? Eigen::VectorXd(der.dB.col(0) * chain) : Eigen::VectorXd::Zero(n);
      dC.row(j) = der.dC.size() ? Eigen::RowVectorXd(der.dC.row(0) * chain)
                                : Eigen::RowVectorXd::Zero(n);
      dD[j] = der.dD.size() ? der.dD(0, 0) * chain : 0.0;
    }
  }

  void stop(const std::string& why) {
    good = false;
    message = why;
    step.ok = false;
  }

  // Carries the predictor (and its gradient) from the sample just processed to the next one
  // with the model at theta and u held. False (after stop()) when the model refuses theta or
  // a perturbed theta, or the state is no longer finite.
  // Samples the held model once (see fixedTheta).
  void sampleFixed() {
    std::vector<int> indices;
    for (const auto& q : params) indices.push_back(q.modelIndex);
    const bool sensitivity = options.gradient == RecursiveGradient::Sensitivity;
    std::string why;
    if (!setTheta(theta0, &why)) throw std::invalid_argument("theta(0) is refused: " + why);
    fixed = sampleZoh(*model, T, sensitivity ? indices : std::vector<int>{}, sensitivity);
    for (std::size_t j = 0; j < fixed.dAd.size(); ++j) {
      const RecursiveParameter& q = params[j];
      const double value = q.toModel(theta0[static_cast<Eigen::Index>(j)]);
      const double chain = q.inverted ? -value * value : 1.0;
      fixed.dAd[j] *= chain;
      fixed.dBd[j] *= chain;
      fixed.dC[j] *= chain;
      fixed.dD[j] *= chain;
    }
    fixedPlus.clear();
    fixedMinus.clear();
    if (!sensitivity)
      for (Eigen::Index j = 0; j < p; ++j) {
        const double step = theta0[j] != 0.0 ? options.differenceStep * std::abs(theta0[j])
                                             : options.differenceStep;
        for (int side : {+1, -1}) {
          Eigen::VectorXd th = theta0;
          th[j] += side * 0.5 * step;
          if (!setTheta(th, &why))
            throw std::invalid_argument("the difference gradient (6.33) needs " +
                                        params[static_cast<std::size_t>(j)].name + " = " +
                                        formatNumber(th[j]) + ", which the model refuses: " + why);
          (side > 0 ? fixedPlus : fixedMinus).push_back(sampleZoh(*model, T, {}, false));
        }
      }
    setTheta(theta0, &why);
  }

  // propagate() for a held theta: products with the matrices sampled once.
  void propagateFixed(double u) {
    for (Eigen::Index j = 0; j < p; ++j) {
      const auto sj = static_cast<std::size_t>(j);
      if (options.gradient == RecursiveGradient::Sensitivity) {
        scratch.noalias() = fixed.Ad * X.col(j);
        scratch.noalias() += fixed.dAd[sj] * x;
        scratch += fixed.dBd[sj].col(0) * u;
        X.col(j) = scratch;
      } else {
        const SampledModel& plus = fixedPlus[sj];
        const SampledModel& minus = fixedMinus[sj];
        xPlus[sj].noalias() = plus.Ad * x;
        xPlus[sj] += plus.Bd.col(0) * u;
        xMinus[sj].noalias() = minus.Ad * x;
        xMinus[sj] += minus.Bd.col(0) * u;
        cPlus[sj] = plus.C.row(0);
        cMinus[sj] = minus.C.row(0);
        dPlus[j] = plus.D(0, 0);
        dMinus[j] = minus.D(0, 0);
        delta[j] = theta[j] != 0.0 ? options.differenceStep * std::abs(theta[j])
                                   : options.differenceStep;
      }
    }
    scratch.noalias() = fixed.Ad * x;
    scratch += fixed.Bd.col(0) * u;
    x = scratch;
  }

  bool propagate(double u) {
    std::string why;
    const double t = timeOf(count);
    if (fixedTheta) {
      propagateFixed(u);
      if (!x.allFinite() || !X.allFinite()) {
        stop("The predictor's state is no longer finite at t = " + formatNumber(t) +
             " s: the nominal model is unstable.");
        return false;
      }
      return true;
    }
    if (options.gradient == RecursiveGradient::Difference) {
      for (Eigen::Index j = 0; j < p; ++j) {
        const auto sj = static_cast<std::size_t>(j);
        delta[j] = theta[j] != 0.0 ? options.differenceStep * std::abs(theta[j])
                                   : options.differenceStep;
        for (int side : {+1, -1}) {
          Eigen::VectorXd th = theta;
          th[j] += side * 0.5 * delta[j];
          if (!setTheta(th, &why)) {
            stop("The difference gradient (6.33) needs " + params[sj].name + " = " +
                 formatNumber(th[j]) + " at t = " + formatNumber(t) + " s, which the model refuses: " + why +
                 ".");
            return false;
          }
          Eigen::VectorXd& xs = side > 0 ? xPlus[sj] : xMinus[sj];
          xs = x;
          evaluate(false, side > 0 ? cPlus[sj] : cMinus[sj], side > 0 ? dPlus[j] : dMinus[j]);
          zoh.advance(A, B, noDerivatives, noInputDerivatives, T, u, xs, noSensitivities);
        }
      }
    }
    // The model is sampled anew only when theta moved (a held theta - the pre-run for P(0), a
    // fixed predictor - keeps its matrices).
    const bool sensitivity = options.gradient == RecursiveGradient::Sensitivity;
    if (!sensitivity || evaluatedAt.size() != theta.size() || evaluatedAt != theta) {
      if (!setTheta(theta, &why)) {
        stop("The model refuses the estimate at t = " + formatNumber(t) + " s: " + why + ".");
        return false;
      }
      evaluate(sensitivity, C, D);
      evaluatedAt = theta;
    }
    if (sensitivity)
      zoh.advance(A, B, dA, dB, T, u, x, X);
    else
      zoh.advance(A, B, noDerivatives, noInputDerivatives, T, u, x, noSensitivities);
    if (zoh.tooLongSubsteps() > 0.0) {
      stop("The sample time of " + formatNumber(T) + " s is far longer than the model's fastest time scale: " +
           "one sample would take " + formatNumber(zoh.tooLongSubsteps()) + " integration steps (at most " +
           formatNumber(ExtendedZoh::kMaxSubsteps) + "); check the log's time column or resample it.");
      return false;
    }
    if (!x.allFinite() || !X.allFinite()) {
      stop("The predictor's state is no longer finite at t = " + formatNumber(t) +
           " s: the model at the estimate is unstable.");
      return false;
    }
    return true;
  }

  // Which theta entry is outside its bounds or not finite (-1: none).
  Eigen::Index outOfBounds(const Eigen::VectorXd& th) const {
    for (Eigen::Index i = 0; i < p; ++i) {
      const RecursiveParameter& q = params[static_cast<std::size_t>(i)];
      if (!std::isfinite(th[i]) || th[i] < q.lower || th[i] > q.upper) return i;
    }
    return -1;
  }

  // Checks P after an update; a sentence when it blew up, else empty.
  std::string covarianceProblem(const Eigen::MatrixXd& Pt, double t) const {
    if (!Pt.allFinite()) return "P is no longer finite at t = " + formatNumber(t) + " s.";
    for (Eigen::Index i = 0; i < p; ++i) {
      const std::string& name = params[static_cast<std::size_t>(i)].name;
      if (!(Pt(i, i) > 0.0))
        return "P lost its positive diagonal at t = " + formatNumber(t) + " s (P for " + name +
               " is " + formatNumber(Pt(i, i)) + ").";
      if (Pt(i, i) > options.covarianceLimit * P0(i, i))
        return "P blew up at t = " + formatNumber(t) + " s: its diagonal element for " + name +
               " grew to " + formatNumber(Pt(i, i) / P0(i, i)) + " times its initial value.";
    }
    return {};
  }

  void fillSigma() {
    const double s = options.algorithm == RecursiveAlgorithm::Kalman ? options.r2 : 1.0;
    step.pDiagonal = P.diagonal();
    step.sigma = (lambda0 / s * step.pDiagonal.array()).sqrt().matrix();
    step.noiseVariance = lambda0;
  }

  void reset() {
    theta = theta0;
    P = P0;
    x = Eigen::VectorXd::Zero(n);
    X = Eigen::MatrixXd::Zero(n, p);
    for (Eigen::Index j = 0; j < p; ++j) {
      const auto sj = static_cast<std::size_t>(j);
      xPlus[sj] = Eigen::VectorXd::Zero(n);
      xMinus[sj] = Eigen::VectorXd::Zero(n);
    }
    count = 0;
    heldRun = heldTotal = 0;
    heldSince = 0.0;
    firstHeld.clear();
    good = true;
    message = "No sample processed yet.";
    lambda0 = options.noiseVariance;
    trackingVariance = options.noiseVariance;
    bank.clear();
    nextHypothesis = bankSpacing();
    changes = 0;
    std::string why;
    if (!setTheta(theta, &why)) throw std::invalid_argument("theta(0) is refused: " + why);
    evaluate(options.gradient == RecursiveGradient::Sensitivity, C, D);
    evaluatedAt = theta;
    if (options.gradient == RecursiveGradient::Difference)
      for (Eigen::Index j = 0; j < p; ++j) {
        // At rest the perturbed predictions are zero like the nominal one.
        cPlus[static_cast<std::size_t>(j)] = C;
        cMinus[static_cast<std::size_t>(j)] = C;
        dPlus[j] = dMinus[j] = D;
        delta[j] = 1.0;
      }
    step = RecursiveStep{};
    step.time = timeOf(0);
    step.theta = theta;
    step.psi = Eigen::VectorXd::Zero(p);
    step.gain = Eigen::VectorXd::Zero(p);
    fillSigma();
  }

  const RecursiveStep& process(double u, double y) {
    if (!good) return step;
    const double t = timeOf(count);
    if (!std::isfinite(u) || !std::isfinite(y)) {
      stop("The sample at t = " + formatNumber(t) + " s is not a finite number.");
      return step;
    }
    const double yhat = C.dot(x) + D * u;  // (6.21) at theta(t-1)
    if (options.gradient == RecursiveGradient::Sensitivity) {
      // (6.22): psi_j = C z_j + C'_j x (+ D'_j u)
      psi.noalias() = X.transpose() * C.transpose();
      psi.noalias() += dC * x;
      psi += dD * u;
    } else {
      for (Eigen::Index j = 0; j < p; ++j) {
        const auto sj = static_cast<std::size_t>(j);
        const double plus = cPlus[sj].dot(xPlus[sj]) + dPlus[j] * u;
        const double minus = cMinus[sj].dot(xMinus[sj]) + dMinus[j] * u;
        psi[j] = (plus - minus) / delta[j];  // (6.33)
      }
    }
    const double eps = y - yhat;  // (6.12)/(6.17)
    const double forgetting = forgettingFactor(eps);
    if (options.noiseVariance == 0.0) {
      const double w = std::max(1.0 / static_cast<double>(count + 1), 1.0 - options.lambda);
      lambda0 += w * (eps * eps - lambda0);
      const bool warm = static_cast<double>(count) * (1.0 - options.lambda) > 1.0;
      const double e2 = warm ? std::min(eps * eps, 9.0 * trackingVariance) : eps * eps;
      const double slow = std::max(1.0 / static_cast<double>(count + 1), 0.1 * (1.0 - options.lambda));
      trackingVariance += slow * (e2 - trackingVariance);
    }
    if (p > 0) {
      Pnew = P;
      if (!update(psi, Pnew, gain, forgetting)) {
        stop("The gain cannot be formed at t = " + formatNumber(t) +
             " s: psi^T P psi is no longer a finite number.");
        return step;
      }
      thetaNew = theta;
      if (options.updateParameters) thetaNew.noalias() += gain * eps;  // (6.15)/(6.20)
      if (!thetaNew.allFinite()) {
        stop("The estimate is no longer a finite number at t = " + formatNumber(t) + " s.");
        return step;
      }
      step.held = false;
      const Eigen::Index bad = outOfBounds(thetaNew);
      if (bad >= 0) {
        // Projection: the update is held back while it would leave the bounds.
        const RecursiveParameter& q = params[static_cast<std::size_t>(bad)];
        const std::string where = "the estimate of " + q.name + " would have left its bounds [" +
                                  formatNumber(q.lower) + ", " + formatNumber(q.upper) + "]";
        if (heldRun == 0) heldSince = t;
        ++heldRun;
        if (heldTotal++ == 0)
          firstHeld = where + " at t = " + formatNumber(t) + " s (as " + formatNumber(thetaNew[bad]) + ")";
        if (static_cast<double>(heldRun) * T > options.maxHeldSeconds) {
          stop("The estimate left its bounds: from t = " + formatNumber(heldSince) + " s on, " +
               where + " for " + std::to_string(heldRun) + " samples in a row.");
          return step;
        }
        thetaNew = theta;
        step.held = true;
      } else {
        heldRun = 0;
      }
      const std::string problem = covarianceProblem(Pnew, t);
      if (!problem.empty()) {
        stop(problem);
        return step;
      }
      theta.swap(thetaNew);
      P.swap(Pnew);
    }
    step.index = count;
    step.time = t;
    step.u = u;
    step.y = y;
    step.yhat = yhat;
    step.epsilon = eps;
    step.theta = theta;
    step.psi = psi;
    step.gain = gain;
    step.lambda = options.algorithm == RecursiveAlgorithm::ForgettingFactor ? forgetting : 1.0;
    step.change = false;
    fillSigma();
    propagate(u);
    ++count;
    if (options.tracking == RecursiveTracking::Bank && good && p > 0) followBank(u, y, eps);
    return step;
  }

  // The forgetting factor of this sample: lambda, or with variable forgetting Fortescue's
  // lambda(t) = 1 - eps^2 (1 - lambda) / (sigma^2 (1 + psi^T P(t-1) psi)), within
  // [lambdaMin, 1].
  double forgettingFactor(double eps) const {
    if (options.tracking != RecursiveTracking::Variable || p == 0 || !(trackingVariance > 0.0))
      return options.lambda;
    const double s = 1.0 + psi.dot(P * psi);
    const double lambda = 1.0 - eps * eps * (1.0 - options.lambda) / (trackingVariance * s);
    return std::clamp(lambda, options.lambdaMin, 1.0);
  }

  std::size_t bankSpacing() const {
    return std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(options.bankSpacingS / T)));
  }

  // The bank (RecursiveTracking::Bank) after the running estimate processed a sample with
  // prediction error eps: every hypothesis processes it too; the one that explains the data
  // since its start best, by more than bankThreshold noise variances, becomes the running
  // estimate; then a new hypothesis starts at the next sample when one is due.
  void followBank(double u, double y, double eps) {
    Hypothesis* best = nullptr;
    double bestGain = options.bankThreshold * trackingVariance;
    for (auto it = bank.begin(); it != bank.end();) {
      const RecursiveStep& s = (*it->estimator).process(u, y);
      if (!s.ok) {
        it = bank.erase(it);
        continue;
      }
      it->own += sampleWeight * s.epsilon * s.epsilon;
      it->running += sampleWeight * eps * eps;
      const bool ripe = timeOf(count) - it->start >= options.bankMinAgeS - 1e-12;
      if (ripe && it->running - it->own > bestGain) {
        bestGain = it->running - it->own;
        best = &*it;
      }
      ++it;
    }
    if (best) {
      const double changeTime = best->start;
      Impl chosen = *best->estimator;
      const RecursiveOptions mine = options;
      const std::size_t next = nextHypothesis;
      const std::size_t held = heldTotal;
      const std::string first = firstHeld;
      const std::size_t accepted = changes + 1;
      bank.clear();
      *this = std::move(chosen);
      options = mine;
      changes = accepted;
      lastChange = changeTime;
      heldTotal += held;
      if (firstHeld.empty()) firstHeld = first;
      nextHypothesis = next;
      step.change = true;
      step.changeTime = changeTime;
    }
    if (count < nextHypothesis) return;
    nextHypothesis = count + bankSpacing();
    std::vector<Hypothesis> kept = std::move(bank);
    bank.clear();
    auto h = std::make_unique<Impl>(*this);
    bank = std::move(kept);
    h->options.tracking = RecursiveTracking::Fixed;
    h->P = P0 * options.bankCovarianceScale;
    h->heldRun = h->heldTotal = 0;
    h->firstHeld.clear();
    bank.push_back(Hypothesis{timeOf(count), ImplCopy(std::move(h)), 0.0, 0.0});
    if (bank.size() > static_cast<std::size_t>(options.bankSize)) bank.erase(bank.begin());
  }
};

ImplCopy::ImplCopy(std::unique_ptr<RecursiveEstimator::Impl> p) : p_(std::move(p)) {}
ImplCopy::ImplCopy(const ImplCopy& o) : p_(std::make_unique<RecursiveEstimator::Impl>(*o.p_)) {}
ImplCopy& ImplCopy::operator=(const ImplCopy& o) {
  if (this != &o) p_ = std::make_unique<RecursiveEstimator::Impl>(*o.p_);
  return *this;
}
ImplCopy::~ImplCopy() = default;

RecursiveEstimator::RecursiveEstimator(const ParametricModel& nominal, double sampleTime,
                                       const RecursiveOptions& options, double startTime) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("recursive identification: " + why);
  if (!(sampleTime > 0.0) || !std::isfinite(sampleTime))
    throw std::invalid_argument("recursive identification: the sample time must be positive");
  const StateSpace ss = nominal.stateSpace();
  if (!ss.isValid(&why)) throw std::invalid_argument("recursive identification: " + why);
  if (ss.inputs() != 1 || ss.outputs() != 1)
    throw std::invalid_argument("recursive identification handles one input and one output");
  impl_ = std::make_unique<Impl>(nominal, sampleTime, options, startTime);
  Impl& m = *impl_;
  m.params = resolveParameters(nominal, options);
  m.p = static_cast<Eigen::Index>(m.params.size());
  m.n = ss.states();
  m.options = perSample(options, sampleTime, m.params);
  m.sampleWeight = options.designSampleTime > 0.0 ? sampleTime / options.designSampleTime : 1.0;
  m.update = CovarianceUpdate(m.options.algorithm, m.options.lambda, kalmanR1(m.params, m.options),
                              m.options.r2, m.options.mu);
  m.theta0.resize(m.p);
  for (Eigen::Index i = 0; i < m.p; ++i) {
    const RecursiveParameter& q = m.params[static_cast<std::size_t>(i)];
    m.theta0[i] = options.thetaStart.empty() ? options.startScale * q.nominal
                                             : options.thetaStart[static_cast<std::size_t>(i)];
    if (!(m.theta0[i] >= q.lower && m.theta0[i] <= q.upper))
      throw std::invalid_argument("theta(0) for " + q.name + " = " + formatNumber(m.theta0[i]) +
                                  " lies outside its bounds [" + formatNumber(q.lower) + ", " +
                                  formatNumber(q.upper) + "]");
  }
  if (m.p > 0 && options.p0.empty())
    throw std::invalid_argument(
        "recursive identification: P(0) is needed (steadyStateCovariance gives the seed's "
        "choice)");
  m.P0 = Eigen::MatrixXd::Zero(m.p, m.p);
  for (Eigen::Index i = 0; i < m.p; ++i) m.P0(i, i) = options.p0[static_cast<std::size_t>(i)];
  const auto sp = static_cast<std::size_t>(m.p);
  m.dA.assign(sp, Eigen::MatrixXd::Zero(m.n, m.n));
  m.dB.assign(sp, Eigen::VectorXd::Zero(m.n));
  m.dC = Eigen::MatrixXd::Zero(m.p, m.n);
  m.dD = Eigen::VectorXd::Zero(m.p);
  m.xPlus.assign(sp, Eigen::VectorXd::Zero(m.n));
  m.xMinus = m.xPlus;
  m.cPlus.assign(sp, Eigen::RowVectorXd::Zero(m.n));
  m.cMinus = m.cPlus;
  m.dPlus = m.dMinus = m.delta = Eigen::VectorXd::Ones(m.p);
  m.psi = m.gain = Eigen::VectorXd::Zero(m.p);
  m.noSensitivities.resize(m.n, 0);
  m.fixedTheta = !options.updateParameters || m.p == 0;
  if (m.fixedTheta) m.sampleFixed();
  // The norm weights of the exponential's series, from the nominal model and its derivatives.
  std::string refused;
  if (!m.setTheta(m.theta0, &refused)) throw std::invalid_argument("theta(0) is refused: " + refused);
  m.evaluate(true, m.C, m.D);
  m.zoh.setScalesFor(m.A, m.dA, m.dB);
  m.reset();
}

RecursiveEstimator::RecursiveEstimator(const RecursiveEstimator& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
RecursiveEstimator& RecursiveEstimator::operator=(const RecursiveEstimator& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
RecursiveEstimator::RecursiveEstimator(RecursiveEstimator&&) noexcept = default;
RecursiveEstimator& RecursiveEstimator::operator=(RecursiveEstimator&&) noexcept = default;
RecursiveEstimator::~RecursiveEstimator() = default;

const RecursiveStep& RecursiveEstimator::update(double u, double y) { return impl_->process(u, y); }
double RecursiveEstimator::prediction() const { return impl_->C.dot(impl_->x); }
const RecursiveStep& RecursiveEstimator::last() const { return impl_->step; }
std::size_t RecursiveEstimator::samples() const { return impl_->count; }
double RecursiveEstimator::sampleTime() const { return impl_->T; }
const std::vector<RecursiveParameter>& RecursiveEstimator::parameters() const { return impl_->params; }
const Eigen::VectorXd& RecursiveEstimator::theta() const { return impl_->theta; }
const Eigen::MatrixXd& RecursiveEstimator::covariance() const { return impl_->P; }
const Eigen::MatrixXd& RecursiveEstimator::initialCovariance() const { return impl_->P0; }
const Eigen::VectorXd& RecursiveEstimator::initialTheta() const { return impl_->theta0; }
const RecursiveOptions& RecursiveEstimator::options() const { return impl_->options; }
bool RecursiveEstimator::ok() const { return impl_->good; }
Termination RecursiveEstimator::termination() const {
  return impl_->good ? Termination::Converged : Termination::Diverged;
}
const std::string& RecursiveEstimator::message() const {
  if (impl_->good && impl_->count > 0) {
    impl_->message = "Processed " + std::to_string(impl_->count) + " samples; ";
    if (impl_->heldTotal == 0)
      impl_->message += "the estimates stayed within their bounds.";
    else
      impl_->message += "the update was held back at the bounds in " +
                        std::to_string(impl_->heldTotal) + " of them (first: " +
                        impl_->firstHeld + ").";
    if (impl_->changes > 0)
      impl_->message += " The bank accepted " + std::to_string(impl_->changes) + " change" +
                        (impl_->changes == 1 ? "" : "s") + " (the last at t = " +
                        formatNumber(impl_->lastChange) + " s).";
  }
  return impl_->message;
}
void RecursiveEstimator::reset() { impl_->reset(); }

std::unique_ptr<ParametricModel> RecursiveEstimator::model() const {
  auto copy = impl_->model->clone();
  for (const auto& q : impl_->params) {
    const double v = impl_->theta[static_cast<Eigen::Index>(&q - impl_->params.data())];
    copy->setParameter(q.modelName, q.toModel(v));
  }
  return copy;
}

}  // namespace flexarm
