#include "core/ident/pem.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

#include <unsupported/Eigen/MatrixFunctions>

#include "core/common/balancing.h"
#include "core/ident/levenberg_marquardt.h"

namespace flexarm {

const char* toString(NoiseModel m) {
  return m == NoiseModel::OutputError ? "output-error" : "innovations";
}
std::optional<NoiseModel> noiseModelFromString(std::string_view s) {
  if (s == "output-error") return NoiseModel::OutputError;
  if (s == "innovations") return NoiseModel::Innovations;
  return std::nullopt;
}

const char* toString(ParameterScaling s) {
  switch (s) {
    case ParameterScaling::None: return "none";
    case ParameterScaling::Scale: return "scale";
    case ParameterScaling::Log: return "log";
  }
  return "none";
}
std::optional<ParameterScaling> parameterScalingFromString(std::string_view s) {
  for (auto v : {ParameterScaling::None, ParameterScaling::Scale, ParameterScaling::Log})
    if (s == toString(v)) return v;
  return std::nullopt;
}

const char* toString(CovarianceKind k) {
  return k == CovarianceKind::White ? "white" : "sandwich";
}
std::optional<CovarianceKind> covarianceKindFromString(std::string_view s) {
  if (s == "white") return CovarianceKind::White;
  if (s == "sandwich") return CovarianceKind::Sandwich;
  return std::nullopt;
}

bool PemOptions::isValid(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (maxIterations < 0) return fail("maxIterations must not be negative");
  if (!(relativeTolerance > 0.0) || !(initialDamping > 0.0))
    return fail("relativeTolerance and initialDamping must be positive");
  if (randomStarts < 0 || notchPeakStarts < 0 || screenCandidates < 0)
    return fail("numbers of starts must not be negative");
  if (!(randomFactor >= 1.0) || !(screenFactor >= 1.0))
    return fail("randomFactor and screenFactor must be at least 1");
  if (notchPeakStarts > 0 && targetNotches.empty() && targetPeaks.empty())
    return fail("starts from notches and peaks need target notch or peak frequencies");
  if (!(level > 0.0 && level < 1.0)) return fail("the level must lie strictly between 0 and 1");
  if (covarianceLags < 0) return fail("covarianceLags must not be negative");
  if (predictor && noiseModel != NoiseModel::OutputError)
    return fail("a custom predictor is output error: it excludes the innovations form");
  for (Eigen::Index n : experimentLengths)
    if (n < 1) return fail("every experiment needs at least one sample");
  return true;
}

namespace {

using Clock = std::chrono::steady_clock;

// exp of the augmented matrix [[A B],[0 0]] T, and optionally its derivative along dA, dB
// by the block-triangular identity exp([[X dX],[0 X]]) = [[e^X, L(X, dX)],[0, e^X]].
Eigen::MatrixXd augmented(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  const Eigen::Index n = A.rows(), m = B.cols();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = A;
  M.topRightCorner(n, m) = B;
  return M;
}

// e^M and, for each dM, the derivative L(M, dM) = d/dh e^{M + h dM} at h = 0, from the
// block-triangular identity exp([[M dM],[0 M]]) = [[e^M, L],[0, e^M]], computed on the
// balanced matrix.
void expWithDerivatives(const Eigen::MatrixXd& M, const std::vector<Eigen::MatrixXd>& dMs,
                        Eigen::MatrixXd& E, std::vector<Eigen::MatrixXd>& dEs) {
  const Eigen::Index k = M.rows();
  const Eigen::VectorXd d = balancingScales(M);
  const Eigen::VectorXd di = d.cwiseInverse();
  const Eigen::MatrixXd Mb = di.asDiagonal() * M * d.asDiagonal();
  E = d.asDiagonal() * Mb.exp() * di.asDiagonal();
  dEs.clear();
  Eigen::MatrixXd big = Eigen::MatrixXd::Zero(2 * k, 2 * k);
  big.topLeftCorner(k, k) = Mb;
  big.bottomRightCorner(k, k) = Mb;
  for (const auto& dM : dMs) {
    big.topRightCorner(k, k) = di.asDiagonal() * dM * d.asDiagonal();
    dEs.push_back(d.asDiagonal() * Eigen::MatrixXd(big.exp().topRightCorner(k, k)) *
                  di.asDiagonal());
  }
}

// A derivative with every matrix sized like the model's (an empty matrix means zero);
// throws std::invalid_argument on other sizes.
StateSpaceDerivative completeDerivative(StateSpaceDerivative d, const StateSpace& ss) {
  auto fix = [](Eigen::MatrixXd& m, const Eigen::MatrixXd& like, const char* what) {
    if (m.size() == 0) m = Eigen::MatrixXd::Zero(like.rows(), like.cols());
    if (m.rows() != like.rows() || m.cols() != like.cols())
      throw std::invalid_argument(std::string("grey-box model: derivative ") + what +
                                  " has the wrong size");
  };
  fix(d.dA, ss.A, "dA");
  fix(d.dB, ss.B, "dB");
  fix(d.dC, ss.C, "dC");
  fix(d.dD, ss.D, "dD");
  return d;
}

}  // namespace

SampledModel sampleZoh(const ParametricModel& model, double T, const std::vector<int>& free,
                       bool withGradient) {
  const StateSpace ss = model.stateSpace();
  std::string why;
  if (!ss.isValid(&why)) throw std::invalid_argument("grey-box model: " + why);
  if (ss.inputs() != 1 || ss.outputs() != 1)
    throw std::invalid_argument("grey-box estimation handles one input and one output");
  const Eigen::Index n = ss.states(), m = 1;
  SampledModel s;
  std::vector<Eigen::MatrixXd> dMs;
  std::vector<StateSpaceDerivative> der;
  if (withGradient)
    for (int idx : free) {
      der.push_back(completeDerivative(model.derivative(idx), ss));
      dMs.push_back(augmented(der.back().dA, der.back().dB) * T);
    }
  Eigen::MatrixXd E;
  std::vector<Eigen::MatrixXd> dEs;
  expWithDerivatives(augmented(ss.A, ss.B) * T, dMs, E, dEs);
  s.Ad = E.topLeftCorner(n, n);
  s.Bd = E.topRightCorner(n, m);
  s.C = ss.C;
  s.D = ss.D;
  for (std::size_t j = 0; j < dEs.size(); ++j) {
    s.dAd.push_back(dEs[j].topLeftCorner(n, n));
    s.dBd.push_back(dEs[j].topRightCorner(n, m));
    s.dC.push_back(der[j].dC);
    s.dD.push_back(der[j].dD);
  }
  return s;
}

namespace {

double spectralRadius(const Eigen::MatrixXd& A) {
  if (A.size() == 0) return 0.0;
  return A.eigenvalues().cwiseAbs().maxCoeff();
}

// The predictor's recursion over the samples, filling r.eps and r.psi. The per-sample work
// is a handful of products of small matrices: they are stacked so that one product serves
// every parameter (DA x holds dAd_j x for all j), evaluated coefficient-wise (lazyProduct: no
// blocking set-up for 5 x 5 matrices), and written into buffers allocated once.
void predictorLoop(const SampledModel& s, const Eigen::VectorXd& K, const Eigen::VectorXd& u,
                    const Eigen::VectorXd& y, int pf, int p, bool withGradient, PemEvaluation& r) {
  using Vec = Eigen::VectorXd;
  using Mat = Eigen::MatrixXd;
  const Eigen::Index n = s.Ad.rows(), samples = y.size();
  const Mat& Ad = s.Ad;
  const Vec bd = s.Bd.col(0);
  const Eigen::RowVectorXd c = s.C.row(0);
  const double dd = s.D(0, 0);
  Mat DA(n * pf, n);
  Mat DB(n, pf);
  Mat DC(pf, n);
  Eigen::VectorXd dDu(pf);
  bool outputDerivative = false;  // some dC or dD is not zero
  if (withGradient)
    for (int j = 0; j < pf; ++j) {
      DA.middleRows(j * n, n) = s.dAd[j];
      DB.col(j) = s.dBd[j].col(0);
      DC.row(j) = s.dC[j].row(0);
      dDu[j] = s.dD[j](0, 0);
      outputDerivative = outputDerivative || !s.dC[j].isZero(0.0) || dDu[j] != 0.0;
    }
  const bool hasK = !K.isZero(0.0);
  Vec x = Vec::Zero(n), xNext(n);
  Eigen::VectorXd fx(n * pf);
  Mat X = Mat::Zero(n, p);  // d x / d theta, the sensitivity states
  Mat force = Mat::Zero(n, p), AX(n, p);
  Eigen::RowVectorXd dy(p);
  for (Eigen::Index t = 0; t < samples; ++t) {
    const double ut = u[t];
    const double e = y[t] - (c.dot(x) + dd * ut);
    r.eps[t] = e;
    if (withGradient) {
      // (6.27) sampled: dyhat = C X + dC x + dD u; X+ = Ad X + dAd x + dBd u - K dyhat (+ eps e_j).
      dy.noalias() = c.lazyProduct(X);
      if (outputDerivative) dy.head(pf) += (DC.lazyProduct(x)).transpose() + dDu.transpose() * ut;
      fx.noalias() = DA.lazyProduct(x);
      force.leftCols(pf) = Eigen::Map<const Mat>(fx.data(), n, pf) + DB * ut;
      for (int j = pf; j < p; ++j) {
        force.col(j).setZero();
        force(j - pf, j) = e;
      }
      r.psi.row(t) = dy;
      if (hasK) force.noalias() -= K * dy;
      AX.noalias() = Ad.lazyProduct(X);
      X = AX + force;
    }
    xNext.noalias() = Ad.lazyProduct(x);
    xNext += bd * ut;
    if (hasK) xNext += K * e;
    x.swap(xNext);
  }
}

}  // namespace

StateSpace discretizeZoh(const StateSpace& c, double T) {
  std::string why;
  if (!c.isValid(&why)) throw std::invalid_argument("discretizeZoh: " + why);
  if (!(T > 0.0)) throw std::invalid_argument("discretizeZoh: the sample time must be positive");
  const Eigen::Index n = c.states(), m = c.inputs();
  Eigen::MatrixXd E;
  std::vector<Eigen::MatrixXd> none;
  expWithDerivatives(augmented(c.A, c.B) * T, {}, E, none);
  StateSpace d;
  d.A = E.topLeftCorner(n, n);
  d.B = E.topRightCorner(n, m);
  d.C = c.C;
  d.D = c.D;
  d.sampleTime = T;
  return d;
}

PemEvaluation evaluatePredictor(const ParametricModel& model, const Eigen::VectorXd& K0,
                                const Eigen::VectorXd& u, const Eigen::VectorXd& y, double T,
                                const std::vector<int>& free, bool withGradient,
                                bool gradientOfK) {
  if (u.size() != y.size())
    throw std::invalid_argument("input and output must have the same number of samples");
  const SampledModel s = sampleZoh(model, T, free, withGradient);
  const Eigen::Index n = s.Ad.rows(), N = y.size();
  const Eigen::VectorXd K = K0.size() ? K0 : Eigen::VectorXd::Zero(n);
  if (K.size() != n) throw std::invalid_argument("the gain K must have one entry per state");
  PemEvaluation r;
  const Eigen::MatrixXd F = s.Ad - K * s.C;  // predictor dynamics
  r.stable = spectralRadius(F) < 1.0;
  const int pf = static_cast<int>(free.size());
  const int p = withGradient ? pf + (gradientOfK ? static_cast<int>(n) : 0) : 0;
  r.eps.resize(N);
  if (withGradient) r.psi.resize(N, p);
  predictorLoop(s, K, u, y, pf, p, withGradient, r);
  return r;
}

PemEvaluation evaluateSampled(const SampledModel& s, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& y, bool withGradient) {
  if (u.size() != y.size())
    throw std::invalid_argument("input and output must have the same number of samples");
  PemEvaluation r;
  r.stable = spectralRadius(s.Ad) < 1.0;
  const int p = withGradient ? static_cast<int>(s.dAd.size()) : 0;
  r.eps.resize(y.size());
  if (withGradient) r.psi.resize(y.size(), p);
  predictorLoop(s, Eigen::VectorXd::Zero(s.Ad.rows()), u, y, p, p, withGradient, r);
  return r;
}

Eigen::VectorXd predictionErrors(const ParametricModel& model, const Eigen::VectorXd& K,
                                 const Eigen::VectorXd& u, const Eigen::VectorXd& y, double T) {
  return evaluatePredictor(model, K, u, y, T, {}, false, false).eps;
}

Eigen::VectorXd simulate(const ParametricModel& model, const Eigen::VectorXd& u, double T) {
  return -evaluatePredictor(model, {}, u, Eigen::VectorXd::Zero(u.size()), T, {}, false, false).eps;
}

FrequencyResponse frequencyResponse(const ParametricModel& model,
                                    const std::vector<double>& omega,
                                    const Eigen::MatrixXd& covariance,
                                    const std::vector<int>& free, double level) {
  FrequencyResponse r;
  r.omega = omega;
  r.level = level;
  const StateSpace ss = model.stateSpace();
  const Eigen::Index n = ss.states();
  const bool bands = covariance.size() > 0;
  if (bands && covariance.rows() != static_cast<Eigen::Index>(free.size()))
    throw std::invalid_argument("frequencyResponse: covariance does not match the free parameters");
  std::vector<StateSpaceDerivative> der;
  if (bands)
    for (int idx : free) der.push_back(completeDerivative(model.derivative(idx), ss));
  const Eigen::MatrixXcd A = ss.A.cast<std::complex<double>>();
  const Eigen::MatrixXcd B = ss.B.cast<std::complex<double>>();
  const Eigen::MatrixXcd C = ss.C.cast<std::complex<double>>();
  std::vector<Eigen::Matrix2d> cov;
  for (double w : omega) {
    Eigen::MatrixXcd sI = Eigen::MatrixXcd::Identity(n, n) * std::complex<double>(0.0, w) - A;
    Eigen::PartialPivLU<Eigen::MatrixXcd> lu(sI);
    const Eigen::VectorXcd RB = lu.solve(B.col(0));  // (sI - A)^{-1} B
    const Eigen::RowVectorXcd CR =  // C (sI - A)^{-1}
        Eigen::PartialPivLU<Eigen::MatrixXcd>(sI.transpose()).solve(C.row(0).transpose()).transpose();
    const std::complex<double> G = (C.row(0) * RB)(0) + ss.D(0, 0);
    r.value.push_back(G);
    if (!bands) continue;
    Eigen::MatrixXd J(2, der.size());
    for (std::size_t j = 0; j < der.size(); ++j) {
      const auto& d = der[j];
      const std::complex<double> dG = (d.dC.cast<std::complex<double>>().row(0) * RB)(0) +
                                      (CR * d.dA.cast<std::complex<double>>() * RB)(0) +
                                      (CR * d.dB.cast<std::complex<double>>().col(0))(0) +
                                      d.dD(0, 0);
      J(0, j) = dG.real();
      J(1, j) = dG.imag();
    }
    cov.push_back(J * covariance * J.transpose());
  }
  finishFrequencyResponse(r, cov);
  return r;
}

namespace {

struct Transform {
  std::vector<int> free;
  std::vector<bool> logParam;
  std::vector<double> scale, lower, upper;
  int nK = 0;

  double toTheta(int j, double phi) const {
    return logParam[j] ? std::exp(phi) : phi * scale[j];
  }
  double toPhi(int j, double theta) const {
    return logParam[j] ? std::log(theta) : theta / scale[j];
  }
  double dThetaDPhi(int j, double theta) const { return logParam[j] ? theta : scale[j]; }
};

struct StartResult {
  LeastSquaresSolution sol;
  bool ok = false;
};

}  // namespace

PemResult pem(const ParametricModel& model0, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
              double T, const PemOptions& options, const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("pem: " + why);
  if (u.size() != y.size())
    throw std::invalid_argument("pem: input and output must have the same number of samples");
  if (!(T > 0.0)) throw std::invalid_argument("pem: the sample time must be positive");
  const std::vector<Eigen::Index> lengths =
      options.experimentLengths.empty() ? std::vector<Eigen::Index>{y.size()} : options.experimentLengths;
  if (std::accumulate(lengths.begin(), lengths.end(), Eigen::Index{0}) != y.size())
    throw std::invalid_argument("pem: the experiments' lengths must add up to the samples of u and y");
  const auto t0 = Clock::now();
  const auto& params0 = model0.parameters();
  Transform tr;
  for (std::size_t i = 0; i < params0.size(); ++i)
    if (params0[i].free) tr.free.push_back(static_cast<int>(i));
  if (tr.free.empty()) throw std::invalid_argument("pem: no free parameter");
  for (const auto& us : options.userStarts)
    if (us.size() != params0.size())
      throw std::invalid_argument("pem: a user start must give every parameter");
  const bool innovations = options.noiseModel == NoiseModel::Innovations;
  const int n = model0.stateSpace().states();
  tr.nK = innovations ? n : 0;
  for (int idx : tr.free) {
    const auto& p = params0[idx];
    const bool lg = options.scaling == ParameterScaling::Log && p.lower >= 0.0 && p.value > 0.0;
    tr.logParam.push_back(lg);
    tr.scale.push_back(options.scaling == ParameterScaling::None || p.value == 0.0
                           ? 1.0 : std::abs(p.value));
    tr.lower.push_back(p.lower);
    tr.upper.push_back(p.upper);
  }
  const int pf = static_cast<int>(tr.free.size());
  const int p = pf + tr.nK;

  PemResult result;
  result.sampleTime = T;
  result.model = model0.clone();
  auto& sum = result.summary;
  if (y.size() < 2 * p + 10) {
    sum.message = "too few samples (" + std::to_string(y.size()) + ") for " + std::to_string(p) +
                  " parameters";
    return result;
  }
  if (!u.allFinite() || !y.allFinite()) {
    sum.message = "the data contain NaN or infinite values";
    return result;
  }

  std::unique_ptr<ParametricModel> work = model0.clone();
  // The bounds are applied again after the transform: exp(log(b)) or (b / s) * s may round
  // one ulp past a bound b (e.g. exp(log(1e4)) > 1e4), which setParameter would refuse.
  auto setPhi = [&](const Eigen::VectorXd& phi, Eigen::VectorXd& K) {
    for (int j = 0; j < pf; ++j)
      work->setParameter(params0[tr.free[j]].name,
                         std::clamp(tr.toTheta(j, phi[j]), tr.lower[j], tr.upper[j]));
    K = innovations ? Eigen::VectorXd(phi.tail(tr.nK)) : Eigen::VectorXd();
  };
  LeastSquaresProblem problem;
  problem.project = [&](Eigen::VectorXd& phi) {
    for (int j = 0; j < pf; ++j) {
      const double th = std::clamp(tr.toTheta(j, phi[j]), tr.lower[j], tr.upper[j]);
      if (!(tr.logParam[j] && th <= 0.0)) phi[j] = tr.toPhi(j, th);
    }
  };
  // Several experiments: each one's errors weighted by sqrt(lambda / lambda_k), lambda_k its
  // own noise variance and lambda the pooled one, once a first fit has estimated them (empty:
  // unweighted). The loss is then the likelihood's for experiments of different noise levels.
  std::vector<double> weights;
  std::vector<Eigen::Index> partRows;  // error rows of each experiment in the last evaluation
  problem.evaluate = [&](const Eigen::VectorXd& phi, Eigen::VectorXd& eps, Eigen::MatrixXd* psi) {
    Eigen::VectorXd K;
    setPhi(phi, K);
    // Each experiment from zero state at its first sample, its errors and gradient stacked.
    auto one = [&](const Eigen::VectorXd& ue, const Eigen::VectorXd& ye) {
      return options.predictor ? options.predictor(*work, ue, ye, T, tr.free, psi != nullptr)
                               : evaluatePredictor(*work, K, ue, ye, T, tr.free, psi != nullptr, innovations);
    };
    PemEvaluation ev;
    try {
      if (lengths.size() == 1) {
        ev = one(u, y);
      } else {
        std::vector<PemEvaluation> parts;
        Eigen::Index rows = 0, from = 0;
        for (Eigen::Index count : lengths) {
          parts.push_back(one(u.segment(from, count), y.segment(from, count)));
          from += count;
          rows += parts.back().eps.size();
          ev.stable = ev.stable && parts.back().stable;
        }
        ev.eps.resize(rows);
        if (psi) ev.psi.resize(rows, parts.front().psi.cols());
        Eigen::Index at = 0;
        partRows.clear();
        for (std::size_t k = 0; k < parts.size(); ++k) {
          const auto& part = parts[k];
          const double w = weights.empty() ? 1.0 : weights[k];
          ev.eps.segment(at, part.eps.size()) = w * part.eps;
          if (psi) ev.psi.middleRows(at, part.eps.size()) = w * part.psi;
          at += part.eps.size();
          partRows.push_back(part.eps.size());
        }
      }
    } catch (const std::invalid_argument&) {
      return false;  // the model rejects these values (e.g. a zero inertia)
    }
    if (!ev.stable || !ev.eps.allFinite()) return false;
    eps = std::move(ev.eps);
    if (psi) {
      *psi = std::move(ev.psi);
      for (int j = 0; j < pf; ++j)
        psi->col(j) *= tr.dThetaDPhi(j, work->parameters()[tr.free[j]].value);
    }
    return true;
  };

  // Starting points as full parameter vectors.
  std::vector<std::vector<double>> starts;
  std::vector<double> base;
  for (const auto& q : params0) base.push_back(q.value);
  starts.push_back(base);
  for (const auto& us : options.userStarts) starts.push_back(us);
  std::mt19937 rng(options.seed);
  auto randomPoint = [&](double factor) {
    std::vector<double> v = base;
    std::uniform_real_distribution<double> ud(-std::log(factor), std::log(factor));
    for (int j = 0; j < pf; ++j) {
      const int idx = tr.free[j];
      double th = tr.logParam[j] || base[idx] != 0.0 ? base[idx] * std::exp(ud(rng))
                                                     : ud(rng) * tr.scale[j];
      v[idx] = std::clamp(th, tr.lower[j], tr.upper[j]);
    }
    return v;
  };
  if (options.notchPeakStarts > 0) {
    std::vector<double> targets = options.targetNotches;
    targets.insert(targets.end(), options.targetPeaks.begin(), options.targetPeaks.end());
    const double wlo = *std::min_element(targets.begin(), targets.end()) / 4.0;
    const double whi = *std::max_element(targets.begin(), targets.end()) * 4.0;
    const auto grid = logGrid(wlo, whi, 400);
    auto score = [&](const std::vector<double>& found, const std::vector<double>& want) {
      double sc = 0.0;
      for (double w : want) {
        double best = 4.0;  // penalty when nothing is near
        for (double f : found) best = std::min(best, std::pow(std::log(w / f), 2));
        sc += best;
      }
      return sc;
    };
    std::vector<std::pair<double, std::vector<double>>> cands;
    auto probe = model0.clone();
    for (int c = 0; c < options.screenCandidates; ++c) {
      auto v = randomPoint(options.screenFactor);
      for (std::size_t i = 0; i < v.size(); ++i) probe->setParameter(params0[i].name, v[i]);
      NotchesPeaks np;
      try {
        np = notchesAndPeaks(frequencyResponse(*probe, grid), 1.0);
      } catch (const std::invalid_argument&) {
        continue;
      }
      cands.push_back({score(np.notches, options.targetNotches) +
                           score(np.peaks, options.targetPeaks), v});
    }
    std::sort(cands.begin(), cands.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (int k = 0; k < options.notchPeakStarts && k < static_cast<int>(cands.size()); ++k)
      starts.push_back(cands[k].second);
  }
  for (int k = 0; k < options.randomStarts; ++k) starts.push_back(randomPoint(options.randomFactor));

  result.starts = static_cast<int>(starts.size());
  StartResult best;
  std::string firstFailure;
  bool cancelled = false;
  int totalIterations = 0;
  for (std::size_t si = 0; si < starts.size() && !cancelled; ++si) {
    Eigen::VectorXd phi0 = Eigen::VectorXd::Zero(p);
    bool admissible = true;
    for (int j = 0; j < pf; ++j) {
      const double th = starts[si][tr.free[j]];
      if (tr.logParam[j] && !(th > 0.0)) admissible = false;
      phi0[j] = admissible ? tr.toPhi(j, th) : 0.0;
    }
    for (std::size_t i = 0; i < params0.size(); ++i)
      if (!params0[i].free) work->setParameter(params0[i].name, starts[si][i]);
    if (!admissible) {
      result.startLosses.push_back(INFINITY);
      continue;
    }
    const double ns = static_cast<double>(starts.size());
    ProgressCallback sub;
    if (progress)
      sub = [&](double f, const std::string& stage) {
        return progress((static_cast<double>(si) + f) / ns,
                        "start " + std::to_string(si + 1) + " of " + std::to_string(starts.size()) +
                            ": " + stage);
      };
    LeastSquaresSolution sol = levenbergMarquardt(problem, phi0, options.maxIterations,
                                                  options.relativeTolerance,
                                                  options.initialDamping, sub);
    totalIterations += sol.summary.iterations;
    cancelled = sol.summary.termination == Termination::Cancelled;
    const bool ok = sol.summary.termination != Termination::Failed;
    // Per error the predictor compares (a custom one may compare fewer samples than y holds).
    result.startLosses.push_back(ok ? sol.sumSquares / static_cast<double>(std::max<Eigen::Index>(1, sol.eps.size()))
                                    : INFINITY);
    if (!ok && firstFailure.empty()) firstFailure = sol.summary.message;
    if (ok && (!best.ok || sol.sumSquares < best.sol.sumSquares)) {
      best.sol = std::move(sol);
      best.ok = true;
      result.bestStart = static_cast<int>(si);
    }
  }
  if (!best.ok) {
    sum.termination = cancelled ? Termination::Cancelled : Termination::Failed;
    sum.message = cancelled ? "cancelled by the user" : "every start failed: " + firstFailure;
    sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return result;
  }
  // Fixed parameters of the best start, then the estimate.
  for (std::size_t i = 0; i < params0.size(); ++i)
    if (!params0[i].free) work->setParameter(params0[i].name, starts[result.bestStart][i]);
  if (lengths.size() > 1 && !cancelled) {
    // Each experiment's noise variance from the first fit's errors, then the weighted fit
    // from there (the covariance below is then that of the weighted loss).
    Eigen::VectorXd eps;
    if (problem.evaluate(best.sol.phi, eps, nullptr) && partRows.size() == lengths.size()) {
      const double pooled = eps.squaredNorm() / static_cast<double>(eps.size());
      Eigen::Index at = 0;
      for (Eigen::Index rows : partRows) {
        const double own = eps.segment(at, rows).squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, rows));
        weights.push_back(own > 0.0 && pooled > 0.0 ? std::sqrt(pooled / own) : 1.0);
        at += rows;
      }
      LeastSquaresSolution sol = levenbergMarquardt(problem, best.sol.phi, options.maxIterations,
                                                    options.relativeTolerance, options.initialDamping);
      totalIterations += sol.summary.iterations;
      if (sol.summary.termination != Termination::Failed) {
        best.sol = std::move(sol);
      } else {
        weights.clear();  // keep the unweighted estimate
      }
    }
  }
  Eigen::VectorXd K;
  setPhi(best.sol.phi, K);
  result.model = work->clone();
  result.K = K;
  sum = best.sol.summary;
  if (cancelled) {
    sum.termination = Termination::Cancelled;
    sum.message = "cancelled by the user; the best estimate so far is kept";
  }
  sum.iterations = totalIterations;
  if (result.starts > 1)
    sum.message += "; best of " + std::to_string(result.starts) + " starts (start " +
                   std::to_string(result.bestStart) + ")";
  fillStatistics(sum, best.sol.sumSquares, best.sol.eps.size(), p);
  // Covariance in phi, mapped to theta with the Jacobian of the transform.
  result.covarianceKind = options.covariance;
  Eigen::MatrixXd covPhi;
  if (options.covariance == CovarianceKind::Sandwich) {
    result.covarianceLags = options.covarianceLags > 0 ? options.covarianceLags
                                                       : automaticCovarianceLags(best.sol.eps);
    covPhi = sandwichCovariance(best.sol.psi, best.sol.eps, result.covarianceLags);
  } else {
    covPhi = gaussNewtonCovariance(best.sol.psi, best.sol.sumSquares);
  }
  Eigen::VectorXd jac(p);
  const auto& pe = result.model->parameters();
  for (int j = 0; j < pf; ++j) jac[j] = tr.dThetaDPhi(j, pe[tr.free[j]].value);
  for (int j = pf; j < p; ++j) jac[j] = 1.0;
  if (covPhi.size())
    result.covariance = jac.asDiagonal() * covPhi * jac.asDiagonal();
  else
    sum.message += "; the Hessian is singular, so no covariance (a parameter is not identifiable)";
  const double z = twoSidedNormalQuantile(options.level);
  for (std::size_t i = 0; i < pe.size(); ++i) {
    PemParameter q{pe[i].name, pe[i].unit, pe[i].value, pe[i].free, 0.0, pe[i].value, pe[i].value};
    result.parameters.push_back(q);
  }
  for (int j = 0; j < tr.nK; ++j)
    result.parameters.push_back({"K" + std::to_string(j + 1), "", K[j], true, 0.0, K[j], K[j]});
  for (int j = 0; j < p; ++j) {
    const std::size_t at = j < pf ? static_cast<std::size_t>(tr.free[j]) : pe.size() + (j - pf);
    result.freeNames.push_back(result.parameters[at].name);
    if (result.covariance.size() == 0) continue;
    auto& q = result.parameters[at];
    q.std = std::sqrt(std::max(0.0, result.covariance(j, j)));
    q.lower = q.value - z * q.std;
    q.upper = q.value + z * q.std;
  }
  result.freeIndices = tr.free;
  sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return result;
}

}  // namespace flexarm
