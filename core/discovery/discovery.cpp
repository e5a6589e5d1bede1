#include "core/discovery/discovery.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <thread>

#include <Eigen/Dense>

#include "core/ident/evaluation.h"
#include "core/ident/fit_data.h"
#include "core/ident/levenberg_marquardt.h"
#include "core/ident/nonlinear_pem.h"
#include "core/models/analysis.h"
#include "core/models/nonlinear_plant.h"
#include "core/signal/preprocess.h"

namespace flexarm {

bool DiscoveryOptions::isValid(std::string* why) const {
  auto fail = [why](const char* s) {
    if (why) *why = s;
    return false;
  };
  if (candidates.empty()) return fail("at least one candidate effect is needed");
  for (EffectKind k : candidates)
    if (std::find(seedEffectKinds().begin(), seedEffectKinds().end(), k) == seedEffectKinds().end())
      return fail("discovery looks for the effects of the seed's Section 3.2 assumptions; the arm-side effects "
                  "are fitted with fit --effect");
  if (!(observerBandwidthHz >= 0.0) || !std::isfinite(observerBandwidthHz))
    return fail("the observer bandwidth must be >= 0 Hz");
  if (!(maxRateHz > 0.0)) return fail("the maximum rate must be positive");
  if (substeps < 0 || substeps > 200) return fail("substeps must be in 0..200");
  if (baseIterations < 1 || candidateIterations < 1) return fail("iterations must be >= 1");
  if (!(level > 0.5 && level < 1.0)) return fail("the level must be in (0.5, 1)");
  if (!(minValidationImprovement >= 0.0 && minValidationImprovement < 1.0))
    return fail("the minimum validation improvement must be in [0, 1)");
  if (!(tieTolerance >= 0.0 && tieTolerance < 1.0)) return fail("the tie tolerance must be in [0, 1)");
  if (threads < 1 || threads > 64) return fail("threads must be in 1..64");
  if (why) why->clear();
  return true;
}

double fQuantile(double p, int d1, int d2) {
  if (d1 < 1 || d2 < 1 || !(p > 0.0 && p < 1.0))
    throw std::invalid_argument("fQuantile: needs d1, d2 >= 1 and 0 < p < 1");
  // Paulson's normal approximation of the cube root of F, solved for the quantile.
  const double z = twoSidedNormalQuantile(2.0 * p - 1.0);
  const double c1 = 2.0 / (9.0 * d1), c2 = 2.0 / (9.0 * d2);
  const double a = 1.0 - c2, b = 1.0 - c1;
  const double qa = a * a - z * z * c2;
  const double disc = std::max(0.0, a * a * b * b - qa * (b * b - z * z * c1));
  const double w = (a * b + std::sqrt(disc)) / qa;
  return w * w * w;
}

namespace {

using Clock = std::chrono::steady_clock;

// The data set through the fit pipeline's preparation (core/ident/fit_data.h), the same
// steps every estimator runs: the channels (the input role, else the torque reference; the
// motor angle as the output), decimation behind the anti-alias FIR with the input held as its
// mean over each new period (the impulse of the torque the controller held at the log's
// rate, what the plant integrates), the means kept (friction and backlash act on the real
// velocity, the ripple on the real angle). The angle is differentiated here, at the fitting
// rate, exactly as the predicted angle is.
//
// A log whose output is the motor velocity (motor_velocity_rad_s, or an output channel in
// rad/s, as the physical models give it) is integrated to an angle from zero (trapezoids),
// and that angle is differentiated like a measured one, so the measured and the predicted
// velocity pass the same central differences. Only the ripple, which acts on the absolute
// angle, then sees an angle offset by the unknown start.
const Channel* velocityChannel(const IdData& data) {
  if (const Channel* v = data.channel(columns::kMotorVelocity)) return v;
  const Channel* out = data.output();
  return out && out->unit == "rad/s" ? out : nullptr;
}

std::optional<NonlinearSeries> makeSeries(const IdData& data, double maxRateHz, std::string* why) {
  const Channel* in = data.input();
  if (!in) in = data.channel(columns::kTorqueRef);
  const Channel* angle = data.channel(columns::kMotorAngle);
  const Channel* velocity = angle ? nullptr : velocityChannel(data);
  const Channel* measured = angle ? angle : velocity;
  if (!in || !measured || in == measured) {
    *why = "the log needs the torque reference (input) and the motor angle " +
           std::string(columns::kMotorAngle) + " or the motor velocity " +
           std::string(columns::kMotorVelocity) + " (or an output in rad/s)";
    return std::nullopt;
  }
  FitDataOptions o;
  o.input = in->name;
  o.output = measured->name;
  o.reference = "";
  o.decimation = std::max(1, static_cast<int>(std::floor(data.sampleRateHz() / maxRateHz + 0.5)));
  o.decimatedInput = FitDataOptions::DecimatedInput::HeldMean;
  o.removeMeans = false;
  o.minimumSamples = 400;
  const PreparedData p = prepareFitData(data, o);
  if (!p.ok()) {
    *why = p.message;
    return std::nullopt;
  }
  NonlinearSeries s;
  s.resetAngle = true;
  s.averageTorque = true;
  s.Ts = p.sampleTime;
  s.startTime = p.startTime;
  s.u.assign(p.u.data(), p.u.data() + p.u.size());
  s.phi.assign(p.y.data(), p.y.data() + p.y.size());
  if (velocity) {  // the angle from the velocity, from zero
    double phi = 0.0, previous = s.phi.empty() ? 0.0 : s.phi[0];
    for (auto& x : s.phi) {
      const double v = x;
      phi += 0.5 * s.Ts * (previous + v);
      previous = v;
      x = phi;
    }
  }
  for (std::size_t k = 0; k < s.u.size(); ++k)
    if (!std::isfinite(s.u[k]) || !std::isfinite(s.phi[k])) {
      *why = "the log holds a non-finite value near sample " + std::to_string(k * static_cast<std::size_t>(o.decimation));
      return std::nullopt;
    }
  s.y = differentiate(s.phi, s.Ts);
  s.initialSpeed = s.y[0];
  return s;
}

// Moment of inertia of the whole axis seen from the motor: J_m + r^2 (sum of the others).
double totalInertia(const PhysicalModel& m) {
  const double r = m.value("r");
  double J = 0.0;
  for (const auto& p : m.parameters())
    if (p.name.size() > 2 && p.name.compare(0, 2, "J_") == 0)
      J += p.name == "J_m" ? p.value : r * r * p.value;
  return J;
}

// The 99th percentile of |a|.
double percentile99(const std::vector<double>& a) {
  if (a.empty()) return 0.0;
  std::vector<double> m(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) m[k] = std::abs(a[k]);
  const std::size_t q = std::min(m.size() - 1, m.size() * 99 / 100);
  std::nth_element(m.begin(), m.begin() + static_cast<long>(q), m.end());
  return m[q];
}

double rms(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return a.empty() ? 0.0 : std::sqrt(s / static_cast<double>(a.size()));
}

FitPercents fitPercentOf(const std::vector<double>& y, const std::vector<double>& yhat) {
  const Eigen::Map<const Eigen::VectorXd> a(y.data(), static_cast<Eigen::Index>(y.size()));
  const Eigen::Map<const Eigen::VectorXd> b(yhat.data(), static_cast<Eigen::Index>(yhat.size()));
  return fitPercents(a, b);
}

// Both fit percentages of the estimation (or validation) data into a score.
void setFit(DiscoveryScore& s, bool validation, const FitPercents& f) {
  (validation ? s.fitPercentValidation : s.fitPercent) = f.seed52;
  (validation ? s.fitPercentValidationNrmse : s.fitPercentNrmse) = f.nrmse;
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n < 2) return 0.0;
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < n; ++k) ma += a[k], mb += b[k];
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t k = 0; k < n; ++k) {
    sab += (a[k] - ma) * (b[k] - mb);
    saa += (a[k] - ma) * (a[k] - ma);
    sbb += (b[k] - mb) * (b[k] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

// Variance inflation 1 + 2 sum (1 - k/(M+1)) rho(k) of a correlated residual (Bartlett): the
// number of independent samples is N divided by it.
double correlationInflation(const Eigen::VectorXd& e) {
  const Eigen::Index N = e.size();
  const Eigen::Index M = std::min<Eigen::Index>(100, N / 4);
  const double r0 = e.squaredNorm();
  if (!(r0 > 0.0)) return 1.0;
  double s = 1.0;
  for (Eigen::Index k = 1; k <= M; ++k) {
    const double rk = e.head(N - k).dot(e.tail(N - k)) / r0;
    s += 2.0 * (1.0 - static_cast<double>(k) / (M + 1)) * rk;
  }
  return std::max(1.0, s);
}

// Variance of coordinate j by the Gauss approximation, lambda / |psi_j - P psi_j|^2 with P
// the projection on the other columns of psi (rank-revealing QR): the (j, j) element of
// lambda (psi^T psi)^{-1} when that exists, and still meaningful when other parameters are
// collinear among themselves; infinite when psi_j lies in their span.
double conditionalVariance(const LeastSquaresSolution& sol, Eigen::Index j) {
  const Eigen::MatrixXd& psi = sol.psi;
  const Eigen::Index n = psi.rows(), p = psi.cols();
  if (n <= p) return INFINITY;
  const double lambda = sol.sumSquares / static_cast<double>(n - p);
  Eigen::MatrixXd others(n, p - 1);
  for (Eigen::Index c = 0, o = 0; c < p; ++c)
    if (c != j) others.col(o++) = psi.col(c);
  Eigen::VectorXd rest = psi.col(j);
  if (p > 1) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(others);
    qr.setThreshold(1e-9);
    const Eigen::VectorXd coef = qr.solve(rest);
    rest -= others * coef;
  }
  const double norm2 = rest.squaredNorm();
  if (!(norm2 > 1e-12 * psi.col(j).squaredNorm()) || !(norm2 > 0.0)) return INFINITY;
  return lambda / norm2;
}

struct FitOutcome {
  LeastSquaresSolution sol;
  std::unique_ptr<PhysicalModel> model;
  Effect effect;
  Eigen::MatrixXd covariance;  // of the coordinates, inflated for correlated residuals
  double inflation = 1.0;
};

FitOutcome finish(const NonlinearProblem& pr, LeastSquaresSolution sol) {
  FitOutcome f;
  auto built = pr.build(sol.phi);
  f.model = std::move(built.first);
  f.effect = built.second.empty() ? Effect{} : built.second.front();
  if (sol.eps.size() > 0) {
    f.inflation = correlationInflation(sol.eps);
    f.covariance = gaussNewtonCovariance(sol.psi, sol.sumSquares);
    if (f.covariance.size()) f.covariance *= f.inflation;
  }
  f.sol = std::move(sol);
  return f;
}

bool hasGearSpring(const PhysicalModel& m) {
  return !m.topology().gearStiffness.empty() && m.topology().gearDeflectionState >= 0;
}

bool gearEffect(EffectKind k) {
  return k == EffectKind::Backlash || k == EffectKind::NonlinearSpring;
}

// Index of the effect parameter whose interval must exclude zero for the effect to exist.
int mainParameter(EffectKind k) { return k == EffectKind::ExtraMass ? 1 : 0; }

struct CandidateWork {
  CandidateFit fit;
  FitOutcome outcome;
  std::vector<double> yhatEst, yhatVal;
};

// Fits one candidate: short screening fits from a few starts, then the full refit. `base`
// is the base model refitted without the effect, `nominal` the engineer's: an effect the
// linear refit has bent its parameters to imitate (a soft spring for a backlash gap) is
// found again from the engineer's values.
void fitCandidate(EffectKind kind, const PhysicalModel& base, const PhysicalModel& nominal,
                  const NonlinearSeries& est, const NonlinearSeries* val, const DiscoveryOptions& o,
                  int substeps, const LoadObserver& observer, double residualPeakRadS,
                  double baseResonance, double gapRange, const std::vector<double>& eBase,
                  const std::atomic<bool>& cancel, CandidateWork& w) {
  NonlinearProblem pr;
  pr.base = &base;
  pr.effects = {Effect::withDefaults(kind)};
  pr.series = {&est};
  pr.substeps = substeps;
  pr.observer = observer;
  pr.cancel = &cancel;
  pr.coords = baseCoordinates(base);
  const auto& info = effectParameters(kind);
  // Effect coordinates, started well away from the defaults (half of them, or a grid).
  auto addEffect = [&pr, &info](int index, CoordinateMap map) {
    NonlinearCoordinate c;
    c.base = false;
    c.rough = true;
    c.index = index;
    c.map = map;
    c.scale = std::abs(info[static_cast<std::size_t>(index)].defaultValue);
    pr.coords.push_back(c);
  };
  std::vector<Effect> starts;
  std::vector<const PhysicalModel*> startModels;  // base parameters of each start (default: base)
  Effect e0 = pr.effects.front();
  int extraCount = 0;  // parameters chosen on a grid (count in the penalty)
  switch (kind) {
    case EffectKind::CoulombFriction:
      addEffect(0, CoordinateMap::NonNegative);
      e0.values[0] = 0.5 * info[0].defaultValue;
      starts.push_back(e0);
      break;
    case EffectKind::Backlash: {
      // The response is far from smooth in the gap b (each contact moves with it), so the
      // gap is first profiled on a logarithmic grid up to the gear travel the data show, from
      // both the refitted base and the engineer's values; the best three grid points start
      // the screening fits. A gap wider than the travel is a motor that never meets the arm:
      // its loss is flat in b and its interval does not exclude zero.
      addEffect(0, CoordinateMap::Log);
      const double range = std::max(gapRange, 1e-3 * info[0].defaultValue);
      pr.coords.back().minPhi = std::log(1e-3 * range);
      pr.coords.back().maxPhi = std::log(range);
      struct GridPoint {
        double loss;
        const PhysicalModel* model;
        double b;
      };
      std::vector<GridPoint> grid;
      std::vector<double> yhat;
      const int points = 32;
      auto gapAt = [range, points](double i) { return range * std::pow(10.0, -2.0 + 2.0 * i / (points - 1)); };
      for (const PhysicalModel* m : {&base, &nominal}) {
        NonlinearProblem gp = pr;
        gp.base = m;
        auto lossAt = [&gp, &e0, &est, &yhat](double gap) {
          Effect e = e0;
          e.values[0] = gap;
          return gp.simulate(gp.coordinatesOf({e}), est, yhat) ? rms(est.y, yhat) : INFINITY;
        };
        double bestLoss = INFINITY;
        int best = -1;
        for (int i = 0; i < points && !cancel.load(); ++i) {
          const double l = lossAt(gapAt(i));
          if (l < bestLoss) bestLoss = l, best = i;
        }
        if (best < 0) continue;
        // The minimum is sharp (a gap a little too wide loses the contacts): golden-section
        // search between the neighbouring grid points.
        double a = best - 1.0, c = best + 1.0;
        const double g = 0.5 * (std::sqrt(5.0) - 1.0);
        double x1 = c - g * (c - a), x2 = a + g * (c - a);
        double f1 = lossAt(gapAt(x1)), f2 = lossAt(gapAt(x2));
        for (int it = 0; it < 10 && !cancel.load(); ++it) {
          if (f1 < f2) {
            c = x2, x2 = x1, f2 = f1;
            x1 = c - g * (c - a);
            f1 = lossAt(gapAt(x1));
          } else {
            a = x1, x1 = x2, f1 = f2;
            x2 = a + g * (c - a);
            f2 = lossAt(gapAt(x2));
          }
        }
        grid.push_back({bestLoss, m, gapAt(best)});
        grid.push_back({std::min(f1, f2), m, gapAt(f1 < f2 ? x1 : x2)});
      }
      std::sort(grid.begin(), grid.end(),
                [](const GridPoint& a, const GridPoint& b) { return a.loss < b.loss; });
      for (std::size_t i = 0; i < grid.size() && i < 3; ++i) {
        e0.values[0] = grid[i].b;
        starts.push_back(e0);
        startModels.push_back(grid[i].model);
      }
      if (starts.empty()) {
        e0.values[0] = 0.3 * range;
        starts.push_back(e0);
      }
      break;
    }
    case EffectKind::NonlinearSpring:
    case EffectKind::InputDelay:
      // Responses far from linear in the value: a few starts over a decade.
      addEffect(0, CoordinateMap::NonNegative);
      for (double f : {0.2, 0.5, 1.2}) {
        e0.values[0] = f * info[0].defaultValue;
        starts.push_back(e0);
      }
      break;
    case EffectKind::TorqueRipple: {
      addEffect(0, CoordinateMap::NonNegative);
      extraCount = 1;
      e0.values[0] = 0.5 * info[0].defaultValue;
      for (int n = 1; n <= 12; ++n) {
        Effect e = e0;
        e.values[1] = n;
        starts.push_back(e);
      }
      break;
    }
    case EffectKind::ExtraMass: {
      addEffect(0, CoordinateMap::Log);
      // The new mode lies within a band around the base model's resonance that the data
      // inform (0.25 to 6 times it): far below it a mass on a very soft spring would stand
      // for a motor running free of the arm, which is not a mass the arm has.
      pr.coords.back().minPhi = std::log(0.25 * baseResonance);
      pr.coords.back().maxPhi = std::log(6.0 * baseResonance);
      addEffect(1, CoordinateMap::Fraction);
      std::vector<double> omegas = {0.5 * baseResonance, 0.8 * baseResonance,
                                    1.3 * baseResonance, 2.0 * baseResonance};
      if (residualPeakRadS > 1.2 * baseResonance) omegas.push_back(residualPeakRadS);
      for (double om : omegas) {
        Effect e = e0;
        e.values[0] = om;
        e.values[1] = 0.25;
        starts.push_back(e);
      }
      break;
    }
    default: break;  // not a candidate (DiscoveryOptions::isValid)
  }
  // Screening: a few iterations from every start; the ripple grid fits A alone (linear in A).
  LeastSquaresSolution bestSol;
  Effect bestStart = starts.front();
  double bestSum = INFINITY;
  if (starts.size() > 1) {
    for (std::size_t i = 0; i < starts.size(); ++i) {
      if (cancel.load()) break;
      const Effect& s = starts[i];
      NonlinearProblem sp = pr;
      if (i < startModels.size()) sp.base = startModels[i];
      sp.effects = {s};
      if (kind == EffectKind::TorqueRipple) {
        sp.coords.erase(sp.coords.begin(), sp.coords.end() - 1);  // A only
      }
      auto sol = sp.solve(sp.coordinatesOf({s}), 3);
      if (sol.eps.size() && sol.sumSquares < bestSum) {
        bestSum = sol.sumSquares;
        auto built = sp.build(sol.phi);
        bestStart = built.second.front();
        if (kind != EffectKind::TorqueRipple) bestSol = std::move(sol);
      }
    }
  }
  pr.effects = {bestStart};
  const Eigen::VectorXd phi0 =
      bestSol.phi.size() ? bestSol.phi : pr.coordinatesOf({bestStart});
  FitOutcome f = finish(pr, pr.solve(phi0, o.candidateIterations));
  CandidateFit& c = w.fit;
  c.kind = kind;
  c.termination = cancel.load() ? Termination::Cancelled : f.sol.summary.termination;
  c.effect = f.effect;
  c.parameterCount = static_cast<int>(pr.coords.size()) + extraCount;
  if (!f.sol.summary.ok() || f.sol.eps.size() == 0) {
    c.reason = "the fit did not finish: " + f.sol.summary.message;
    w.outcome = std::move(f);
    return;
  }
  const double z = twoSidedNormalQuantile(o.level);
  for (std::size_t i = 0; i < info.size(); ++i) {
    EffectParameterEstimate p;
    p.name = info[i].name;
    p.unit = info[i].unit;
    p.value = f.effect.values[i];
    p.estimated = false;
    for (std::size_t j = 0; j < pr.coords.size(); ++j) {
      const auto& cj = pr.coords[j];
      if (cj.base || cj.index != static_cast<int>(i)) continue;
      p.estimated = true;
      const double slope = cj.slope(f.sol.phi[static_cast<Eigen::Index>(j)]);
      p.std = std::abs(slope) * std::sqrt(f.inflation * conditionalVariance(f.sol, static_cast<Eigen::Index>(j)));
    }
    p.lower = p.value - z * p.std;
    p.upper = p.value + z * p.std;
    c.parameters.push_back(p);
  }
  const auto& mp = c.parameters[static_cast<std::size_t>(mainParameter(kind))];
  c.intervalExcludesZero = std::isfinite(mp.std) && mp.lower > 0.0;
  c.lossEst = f.sol.sumSquares / static_cast<double>(f.sol.eps.size());
  pr.simulate(f.sol.phi, est, w.yhatEst);
  c.score.rmsEstimation = rms(est.y, w.yhatEst);
  setFit(c.score, false, fitPercentOf(est.y, w.yhatEst));
  if (val && pr.simulate(f.sol.phi, *val, w.yhatVal)) {
    c.score.rmsValidation = rms(val->y, w.yhatVal);
    setFit(c.score, true, fitPercentOf(val->y, w.yhatVal));
  } else if (val) {
    c.score.rmsValidation = INFINITY;
    setFit(c.score, true, {-INFINITY, -INFINITY});
  }
  std::vector<double> share(w.yhatEst.size());
  for (std::size_t k = 0; k < share.size(); ++k) share[k] = w.yhatEst[k] - (est.y[k] - eBase[k]);
  c.rho = correlation(eBase, share);
  w.outcome = std::move(f);
}

std::string number(double v, int digits = 3) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string plusMinus(const EffectParameterEstimate& p, double factor = 1.0) {
  return number(p.value * factor) + " +- " + number(p.std * factor, 2);
}

// The effect named in plain words with its fitted size.
std::string describeEffect(const CandidateFit& c) {
  const auto& p = c.parameters;
  switch (c.kind) {
    case EffectKind::CoulombFriction:
      return "Coulomb friction of " + plusMinus(p[0]) + " N m on the motor side";
    case EffectKind::Backlash:
      return "backlash in the gear, a dead zone of half-width " + plusMinus(p[0], 1e3) +
             " mrad (arm side)";
    case EffectKind::NonlinearSpring:
      return "a stiffening gear spring, k delta (1 + beta delta^2) with beta = " +
             plusMinus(p[0]) + " 1/rad^2";
    case EffectKind::InputDelay:
      return "an input delay of " + plusMinus(p[0], 1e3) +
             " ms between the torque reference and the applied torque";
    case EffectKind::TorqueRipple:
      return "torque ripple of " + plusMinus(p[0]) + " N m, " + number(p[1].value) +
             " periods per motor revolution";
    case EffectKind::ExtraMass:
      return "an extra mass: " + plusMinus(p[1], 100.0) +
             " % of the outermost inertia on a spring resonating at " + number(p[0].value) +
             " +- " + number(p[0].std, 2) + " rad/s";
    default: break;
  }
  return toString(c.kind);
}

}  // namespace

DiscoveryResult discoverMissingEffect(const PhysicalModel& base, const IdData& estimation,
                                      const IdData* validation, const DiscoveryOptions& o,
                                      const ProgressCallback& progress) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("discoverMissingEffect: " + why);
  if (!hasGearSpring(base) || base.structureName() == "two-mass-theta")
    throw std::invalid_argument("discoverMissingEffect: the base model needs a gear spring "
                                "(two-mass, three-mass or four-mass), not " + base.structureName());
  const auto t0 = Clock::now();
  DiscoveryResult R;
  auto done = [&R, t0](Termination t, std::string msg) {
    R.termination = t;
    R.message = std::move(msg);
    R.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return std::move(R);
  };
  auto est = makeSeries(estimation, o.maxRateHz, &why);
  if (!est) return done(Termination::Failed, "estimation data: " + why);
  std::optional<NonlinearSeries> val;
  if (validation) {
    val = makeSeries(*validation, o.maxRateHz, &why);
    if (!val) return done(Termination::Failed, "validation data: " + why);
    if (std::abs(val->Ts - est->Ts) > 1e-9 * est->Ts)
      return done(Termination::Failed, "the validation data's sample time differs from the estimation data's");
  }
  R.sampleTime = est->Ts;
  R.hasValidation = val.has_value();
  const NonlinearSeries* valp = val ? &*val : nullptr;
  const int substeps = o.substeps > 0 ? o.substeps : defaultSubsteps(est->Ts);
  const LoadObserver observer{2.0 * M_PI * o.observerBandwidthHz,
                          totalInertia(base) / base.value("k_T")};
  std::atomic<bool> cancel{false};
  std::mutex progressMutex;
  auto report = [&](double f, const std::string& stage) {
    std::lock_guard<std::mutex> lock(progressMutex);
    if (reportProgress(progress, f, stage)) cancel = true;
  };

  // 1. The base model by the same predictor.
  report(0.0, "fitting the base model");
  std::unique_ptr<PhysicalModel> baseCopy(static_cast<PhysicalModel*>(base.clone().release()));
  baseCopy->setOptions(ModelOptions{});
  NonlinearProblem bp;
  bp.base = baseCopy.get();
  bp.series = {&*est};
  bp.substeps = substeps;
  bp.observer = observer;
  bp.cancel = &cancel;
  bp.coords = baseCoordinates(*baseCopy);
  if (bp.coords.empty()) return done(Termination::Failed, "the base model has no free parameter");
  FitOutcome bf = finish(bp, bp.solve(bp.coordinatesOf({}), o.baseIterations));
  if (cancel.load()) return done(Termination::Cancelled, "cancelled by the user");
  if (!bf.sol.summary.ok() || bf.sol.eps.size() == 0)
    return done(Termination::Failed, "the base model could not be fitted: " + bf.sol.summary.message);
  std::shared_ptr<const PhysicalModel> baseFit(std::move(bf.model));
  R.baseModel = baseFit;
  R.baseParameterCount = static_cast<int>(bp.coords.size());
  const std::size_t N = est->y.size();
  std::vector<double> yBase, deflection, yBaseVal;
  {
    NonlinearProblem fixedBase = bp;
    fixedBase.base = baseFit.get();
    fixedBase.simulate(fixedBase.coordinatesOf({}), *est, yBase, &deflection);
    if (valp) fixedBase.simulate(fixedBase.coordinatesOf({}), *valp, yBaseVal);
  }
  std::vector<double> eBase(N);
  for (std::size_t k = 0; k < N; ++k) eBase[k] = est->y[k] - yBase[k];
  R.baseLoss = bf.sol.sumSquares / static_cast<double>(N);
  const double inflation = bf.inflation;
  const double nEff = static_cast<double>(N) / inflation;
  R.baseAic = nEff * std::log(R.baseLoss) + 2.0 * R.baseParameterCount;
  R.base.rmsEstimation = rms(est->y, yBase);
  setFit(R.base, false, fitPercentOf(est->y, yBase));
  if (valp) {
    R.base.rmsValidation = rms(valp->y, yBaseVal);
    setFit(R.base, true, fitPercentOf(valp->y, yBaseVal));
  }

  // 2. Where the disagreement lives.
  DisagreementMap& D = R.disagreement;
  D.time.resize(N);
  for (std::size_t k = 0; k < N; ++k) D.time[k] = est->startTime + static_cast<double>(k) * est->Ts;
  D.residual = eBase;
  D.motorVelocity = est->y;
  D.gearDeflection = deflection;
  D.motorAngle = est->phi;
  const auto spec = amplitudeSpectrum(eBase, est->Ts, static_cast<int>(std::min<std::size_t>(4096, N / 2)));
  D.spectrumHz = spec.frequencyHz;
  D.spectrum = spec.amplitude;
  double peak = 0.0;
  for (std::size_t i = 0; i < spec.frequencyHz.size(); ++i)
    if (2.0 * M_PI * spec.frequencyHz[i] > 5.0 && spec.amplitude[i] > peak) {
      peak = spec.amplitude[i];
      D.spectrumPeakRadS = 2.0 * M_PI * spec.frequencyHz[i];
    }
  double baseResonance = 0.0;
  for (const auto& m : peakFrequencies(baseFit->stateSpace())) {
    D.resonancesRadS.push_back(m.frequency);
    baseResonance = std::max(baseResonance, m.frequency);
  }
  if (baseResonance <= 0.0) baseResonance = 100.0;
  {
    const Eigen::Map<const Eigen::VectorXd> e(eBase.data(), static_cast<Eigen::Index>(N));
    const Eigen::Map<const Eigen::VectorXd> u(est->u.data(), static_cast<Eigen::Index>(N));
    D.tests = residualAnalysis(e, u);
  }
  {
    std::vector<double> speed(N), sgn(N);
    for (std::size_t k = 0; k < N; ++k) {
      speed[k] = std::abs(est->y[k]);
      sgn[k] = (est->y[k] > 0) - (est->y[k] < 0);
    }
    std::vector<double> sorted = speed;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(N / 2), sorted.end());
    const double median = sorted[N / 2];
    double lo = 0, hi = 0;
    std::size_t nl = 0, nh = 0;
    for (std::size_t k = 0; k < N; ++k) {
      if (speed[k] < median) lo += eBase[k] * eBase[k], ++nl;
      else hi += eBase[k] * eBase[k], ++nh;
    }
    D.rmsLowSpeed = nl ? std::sqrt(lo / nl) : 0.0;
    D.rmsHighSpeed = nh ? std::sqrt(hi / nh) : 0.0;
    D.correlationSignVelocity = correlation(eBase, sgn);
  }
  {
    std::string s = "Base model: fit " + number(R.base.fitPercent) + " %, residual RMS " +
                    number(R.base.rmsEstimation) + " rad/s on the estimation data";
    if (valp) s += " and " + number(R.base.rmsValidation) + " rad/s on the validation data";
    s += ". Residual RMS " + number(D.rmsLowSpeed) + " rad/s at low motor speed, " +
         number(D.rmsHighSpeed) + " at high speed; correlation with the sign of the velocity " +
         number(D.correlationSignVelocity, 2) + ". Largest residual line at " +
         number(D.spectrumPeakRadS) + " rad/s (model resonances:";
    for (double w : D.resonancesRadS) s += " " + number(w);
    s += " rad/s). " + D.tests.verdict;
    D.summary = s;
  }

  // How wide a backlash gap the data can show: the gear travel, r times the motor's swing
  // about its 0.5 s moving mean (a gap the motor never crosses is invisible), or the base
  // model's gear deflections if larger; 99th percentiles of the absolute values.
  double gapRange = percentile99(deflection);
  {
    const std::size_t half = std::max<std::size_t>(1, static_cast<std::size_t>(0.25 / est->Ts));
    std::vector<double> swing(N);
    double sum = 0.0;
    std::size_t lo = 0, hi = 0;  // the window [lo, hi)
    for (std::size_t k = 0; k < N; ++k) {
      for (; hi < std::min(N, k + half + 1); ++hi) sum += est->phi[hi];
      for (; lo + half < k; ++lo) sum -= est->phi[lo];
      swing[k] = est->phi[k] - sum / static_cast<double>(hi - lo);
    }
    gapRange = std::max(gapRange, baseFit->value("r") * percentile99(swing));
  }

  // 3. Candidates in parallel.
  std::vector<EffectKind> kinds;
  for (EffectKind k : o.candidates) {
    if (gearEffect(k) && !hasGearSpring(*baseFit)) continue;
    if (k == EffectKind::ExtraMass && baseFit->structureName() == "four-mass") continue;
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
  }
  std::vector<CandidateWork> work(kinds.size());
  std::atomic<std::size_t> next{0}, finished{0};
  auto worker = [&]() {
    for (;;) {
      const std::size_t i = next++;
      if (i >= kinds.size() || cancel.load()) return;
      fitCandidate(kinds[i], *baseFit, *baseCopy, *est, valp, o, substeps, observer,
                   D.spectrumPeakRadS, baseResonance, gapRange, eBase, cancel, work[i]);
      const std::size_t f = ++finished;
      report(0.15 + 0.8 * static_cast<double>(f) / kinds.size(),
             std::string("fitted ") + toString(kinds[i]));
    }
  };
  report(0.15, "fitting the candidate effects");
  {
    std::vector<std::thread> pool;
    const int nt = std::min<int>(o.threads, static_cast<int>(kinds.size()));
    for (int t = 1; t < nt; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
  }
  if (cancel.load()) return done(Termination::Cancelled, "cancelled by the user");

  // 4. Statistics and the verdict.
  for (auto& w : work) {
    CandidateFit& c = w.fit;
    if (c.termination == Termination::Failed || c.lossEst <= 0.0) {
      c.aic = INFINITY;
      R.candidates.push_back(std::move(c));
      continue;
    }
    c.aic = nEff * std::log(c.lossEst) + 2.0 * c.parameterCount;
    const int q = std::max(1, c.parameterCount - R.baseParameterCount);
    const double d2 = std::max(1.0, nEff - c.parameterCount);
    c.fStatistic = (R.baseLoss - c.lossEst) / c.lossEst * d2 / q;
    c.fThreshold = fQuantile(o.level, q, static_cast<int>(d2));
    const bool fOk = c.fStatistic > c.fThreshold;
    const bool aicOk = c.aic < R.baseAic;
    const bool valOk = !valp || c.score.rmsValidation <=
                                    (1.0 - o.minValidationImprovement) * R.base.rmsValidation;
    const auto& mp = c.parameters[static_cast<std::size_t>(mainParameter(c.kind))];
    // Without curvature in the effect's parameter (a backlash gap wider than any deflection
    // in the data leaves the loss flat in b: a motor running free of the arm, which explains
    // much of any data) the effect is not named.
    c.significant = fOk && aicOk && valOk && c.intervalExcludesZero;
    if (c.significant) {
      c.reason = "significant: F = " + number(c.fStatistic) + " > " + number(c.fThreshold) +
                 ", " + mp.name + " interval excludes 0";
    } else if (!c.intervalExcludesZero) {
      c.reason = "the " + number(100 * o.level, 2) + " % interval of " + mp.name + " [" +
                 number(mp.lower) + ", " + number(mp.upper) + "] includes 0";
    } else if (!fOk || !aicOk) {
      c.reason = "the loss drop does not pay for the extra parameters (F = " +
                 number(c.fStatistic) + ", threshold " + number(c.fThreshold) + ")";
    } else {
      c.reason = "the validation residual improves by only " +
                 number(100.0 * (1.0 - c.score.rmsValidation / R.base.rmsValidation), 2) + " %";
    }
    R.candidates.push_back(std::move(c));
  }
  auto measure = [&R, valp](const CandidateFit& c) {
    return valp ? c.score.rmsValidation : std::sqrt(c.lossEst);
  };
  for (std::size_t i = 0; i < R.candidates.size(); ++i)
    if (R.candidates[i].significant &&
        (R.best < 0 || measure(R.candidates[i]) < measure(R.candidates[static_cast<std::size_t>(R.best)])))
      R.best = static_cast<int>(i);
  // Among candidates that explain the data equally well, the one with fewer parameters is
  // named (the others are reported as tied).
  if (R.best >= 0) {
    const double bestMeasure = measure(R.candidates[static_cast<std::size_t>(R.best)]);
    for (std::size_t i = 0; i < R.candidates.size(); ++i) {
      const CandidateFit& c = R.candidates[i];
      const CandidateFit& b = R.candidates[static_cast<std::size_t>(R.best)];
      if (c.significant && measure(c) <= (1.0 + o.tieTolerance) * bestMeasure &&
          (c.parameterCount < b.parameterCount ||
           (c.parameterCount == b.parameterCount && c.aic < b.aic)))
        R.best = static_cast<int>(i);
    }
  }

  R.estimation.time = D.time;
  R.estimation.measured = est->y;
  R.estimation.base = yBase;
  if (valp) {
    R.validation.time.resize(valp->y.size());
    for (std::size_t k = 0; k < valp->y.size(); ++k)
      R.validation.time[k] = valp->startTime + static_cast<double>(k) * valp->Ts;
    R.validation.measured = valp->y;
    R.validation.base = yBaseVal;
  }
  const std::string valText =
      valp ? "validation residual RMS " + number(R.base.rmsValidation) + " -> "
           : "estimation residual RMS " + number(R.base.rmsEstimation) + " -> ";
  if (R.best < 0) {
    R.augmented = R.base;
    R.estimation.augmented = yBase;
    R.validation.augmented = yBaseVal;
    R.augmentedModel = baseFit;
    std::string s = "No missing effect: none of the " + std::to_string(R.candidates.size()) +
                    " candidates is significant at " + number(100 * o.level, 2) + " %";
    double bestRms = INFINITY;
    const CandidateFit* closest = nullptr;
    for (const auto& c : R.candidates)
      if (c.termination != Termination::Failed && measure(c) < bestRms) {
        bestRms = measure(c);
        closest = &c;
      }
    if (closest)
      s += "; the closest, " + std::string(toString(closest->kind)) + ", " + closest->reason;
    s += ". Base model " + valText.substr(0, valText.size() - 4) + " rad/s.";
    R.evidence = s;
    return done(Termination::Converged, "no missing effect found");
  }
  const std::size_t bi = static_cast<std::size_t>(R.best);
  CandidateFit& b = R.candidates[bi];
  R.effect = b.kind;
  for (std::size_t i = 0; i < R.candidates.size(); ++i)
    if (i != bi && R.candidates[i].significant &&
        std::abs(measure(R.candidates[i]) / measure(b) - 1.0) <= o.tieTolerance)
      R.tied.push_back(R.candidates[i].kind);
  R.augmented = b.score;
  R.estimation.augmented = work[bi].yhatEst;
  R.validation.augmented = work[bi].yhatVal;
  std::shared_ptr<const PhysicalModel> augModel(std::move(work[bi].outcome.model));
  R.augmentedModel = augModel;
  b.model = augModel;
  R.augmentedEffects = {b.effect};
  std::string s = describeEffect(b);
  s[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
  s += "; the base residual correlates with the effect's simulated share, rho = " +
       number(b.rho, 2);
  if (b.kind == EffectKind::CoulombFriction)
    s += ", with the sign of the velocity rho = " + number(D.correlationSignVelocity, 2);
  s += "; " + valText + number(valp ? b.score.rmsValidation : b.score.rmsEstimation) +
       " rad/s (fit " + number(valp ? R.base.fitPercentValidation : R.base.fitPercent) +
       " -> " + number(valp ? b.score.fitPercentValidation : b.score.fitPercent) + " %).";
  if (!R.tied.empty()) {
    s += " Tie: ";
    for (std::size_t i = 0; i < R.tied.size(); ++i) s += (i ? ", " : "") + std::string(toString(R.tied[i]));
    s += " explain the data as well; compare them before choosing.";
  }
  // A gap or a delay moves the response in small steps (the integration grid, the moments
  // the gap opens), so the loss is not the smooth quadratic its finite-difference Jacobian
  // assumes near the optimum: the interval from it can be far narrower than the error (issue
  // 13: a 0.2 mrad gap came out 0.187 +- 0.00028 mrad, 46 standard deviations off).
  if (b.kind == EffectKind::Backlash || b.kind == EffectKind::InputDelay)
    s += " The " + std::string(toString(b.kind)) +
         " interval promises too much: the loss is not smooth in that parameter, so the "
         "estimate can be off by many of its standard deviations.";
  R.evidence = s;
  report(1.0, "done");
  return done(Termination::Converged, std::string("missing effect: ") + toString(b.kind));
}

}  // namespace flexarm
