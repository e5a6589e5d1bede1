#include "core/ident/nonlinear_pem.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "core/ident/evaluation.h"
#include "core/signal/preprocess.h"

namespace flexarm {

LoadObserver loadObserver(const PhysicalModel& model, double bandwidthHz) {
  if (!(bandwidthHz > 0.0)) return {};
  const double r = model.value("r");
  double J = 0.0;  // J_m + r^2 (every other inertia)
  for (const auto& p : model.parameters())
    if (p.name.size() > 2 && p.name.compare(0, 2, "J_") == 0) J += p.name == "J_m" ? p.value : r * r * p.value;
  return {2.0 * M_PI * bandwidthHz, J / model.value("k_T")};
}

NonlinearSeries nonlinearSeries(const PreparedData& d, SampleRange range, bool angleOutput) {
  NonlinearSeries s;
  const auto b = static_cast<Eigen::Index>(range.begin), n = static_cast<Eigen::Index>(range.size());
  s.Ts = d.sampleTime;
  s.startTime = d.timeAt(range.begin);
  s.u.assign(d.u.data() + b, d.u.data() + b + n);
  s.y.assign(d.y.data() + b, d.y.data() + b + n);
  if (angleOutput) {
    s.phi = s.y;
    s.initialSpeed = n > 1 ? (s.y[1] - s.y[0]) / s.Ts : 0.0;
    return s;
  }
  if (d.angle.size() == d.u.size()) {
    s.phi.assign(d.angle.data() + b, d.angle.data() + b + n);
    s.resetAngle = true;
  }
  s.initialSpeed = s.y.empty() ? 0.0 : s.y[0];
  return s;
}

int defaultSubsteps(double Ts) { return std::max(2, static_cast<int>(std::ceil(Ts / 2.5e-4 - 1e-9))); }

bool predictOutput(const NonlinearPlant& plant, const NonlinearSeries& s, int substeps,
                   const LoadObserver& observer, PredictedOutput output, std::vector<double>& yhat,
                   std::vector<double>* deflection, std::vector<double>* armDeflection,
                   const PredictorVisitor* visit) {
  const std::size_t N = s.u.size();
  if (N == 0) return false;
  const bool hasAngle = s.phi.size() == N;
  const bool reset = hasAngle && s.resetAngle;
  std::vector<double> phiHat(N);
  yhat.resize(N);
  if (deflection) deflection->resize(N);
  if (armDeflection) armDeflection->resize(N);
  // Start in rigid-body motion at the given speed (a data set cut from a longer log need not
  // start at rest): phi_m' = v0, every arm-side speed r v0, the springs relaxed.
  NonlinearPlant::State x{};
  const double phi0 = hasAngle ? s.phi[0] : 0.0;
  x[static_cast<std::size_t>(plant.motorAngleState())] = phi0;
  {
    const auto names = plant.model().stateNames();
    const double r = plant.model().value("r");
    for (std::size_t i = 0; i < names.size() && i < x.size(); ++i)
      if (!names[i].empty() && names[i].back() == '\'')
        x[i] = names[i] == "phi_m'" ? s.initialSpeed : r * s.initialSpeed;
  }
  const double Ts = s.Ts, delay = plant.inputDelay();
  const double h = Ts / substeps;
  const auto& u = s.u;
  // The held torque, delayed; averaged (NonlinearSeries::averageTorque) over one Runge-Kutta
  // step around each stage point, where the average of a held signal over a window is exact
  // wherever the window holds no sample edge.
  auto held = [&u, N](double k) { return k < 0.0 ? 0.0 : u[std::min(static_cast<std::size_t>(k), N - 1)]; };
  const bool average = s.averageTorque || delay > 0.0;
  // The observer's torque acts on the motor (in units of u, undelayed): the load it stands
  // for reaches the motor through the gear at low frequency, and a motor-side correction
  // keeps acting when backlash opens the gear (an arm-side one would then lose its grip).
  double correction = 0.0;
  auto torqueAt = [&held, &correction, Ts, h, delay, average](double t) {
    if (!average) return held(std::floor((t - delay) / Ts)) + correction;
    const double a = (t - delay - 0.5 * h) / Ts, b = (t - delay + 0.5 * h) / Ts;
    const double edge = std::floor(b);
    if (edge <= a) return held(a) + correction;
    return ((edge - a) * held(a) + (b - edge) * held(b)) / (b - a) + correction;
  };
  const double wo = observer.wo, gain = observer.gain;
  const double kp = 2.0 * wo, ki = wo * wo;
  double integral = 0.0;
  const double limit = 1e6 + 1e3 * std::abs(phi0);
  // With a reset angle each sample's integration starts from the measured angle (it only
  // positions the ripple A sin(n phi_m)); the predicted angle, whose derivative is the
  // output, accumulates the simulated increments.
  const std::size_t angle = static_cast<std::size_t>(plant.motorAngleState());
  for (std::size_t k = 0; k < N; ++k) {
    if (reset) {
      phiHat[k] = k == 0 ? s.phi[0] : phiHat[k - 1] + (plant.motorAngle(x) - s.phi[k - 1]);
      x[angle] = s.phi[k];
    } else {
      phiHat[k] = plant.motorAngle(x);
    }
    const double v = plant.motorVelocity(x);
    if (!std::isfinite(phiHat[k]) || std::abs(phiHat[k]) > limit || !std::isfinite(v) || std::abs(v) > 1e9)
      return false;
    if (output == PredictedOutput::MotorVelocity) yhat[k] = v;
    if (deflection) (*deflection)[k] = plant.gearDeflection(x);
    if (armDeflection) (*armDeflection)[k] = plant.armDeflection(x) + plant.encoderSkew() * plant.armVelocity(x);
    if (wo > 0.0 && k > 0) {
      const double e = hasAngle ? ((s.phi[k] - s.phi[k - 1]) - (phiHat[k] - phiHat[k - 1])) / Ts
                                : s.y[k] - v;
      integral += e * Ts;
      correction = gain * (kp * e + ki * integral);
    }
    const double t = static_cast<double>(k) * Ts;
    if (visit) (*visit)(k, x, u[k] + correction, torqueAt(t + 0.5 * h));
    for (int i = 0; i < substeps; ++i) plant.step(x, t + i * h, h, torqueAt, 0.0);
  }
  if (output == PredictedOutput::DifferentiatedAngle) yhat = differentiate(phiHat, Ts);
  else if (output == PredictedOutput::MotorAngle) yhat = phiHat;
  return true;
}

double NonlinearCoordinate::toValue(double phi) const {
  return map == CoordinateMap::Log ? std::exp(phi) : phi * scale;
}

double NonlinearCoordinate::toPhi(double v) const {
  return map == CoordinateMap::Log ? std::log(v) : v / scale;
}

void NonlinearCoordinate::project(double& phi) const {
  if (map == CoordinateMap::NonNegative) phi = std::max(phi, 0.0);
  if (map == CoordinateMap::Fraction) phi = std::clamp(phi, 0.01 / scale, 0.95 / scale);
  if (map == CoordinateMap::Log) phi = std::clamp(phi, minPhi, maxPhi);
}

double NonlinearCoordinate::step(double phi) const {
  if (!rough) return map == CoordinateMap::Log ? 1e-4 : 1e-4 * std::max(1.0, std::abs(phi));
  return map == CoordinateMap::Log ? 2e-3 : 1e-2 * std::max(1.0, std::abs(phi));
}

double NonlinearCoordinate::slope(double phi) const {
  return map == CoordinateMap::Log ? std::exp(phi) : scale;
}

std::pair<std::unique_ptr<PhysicalModel>, std::vector<Effect>> NonlinearProblem::build(
    const Eigen::VectorXd& phi) const {
  std::unique_ptr<PhysicalModel> m(static_cast<PhysicalModel*>(base->clone().release()));
  std::vector<Effect> e = effects;
  for (std::size_t i = 0; i < coords.size(); ++i) {
    const auto& c = coords[i];
    const double v = c.toValue(phi[static_cast<Eigen::Index>(i)]);
    if (c.base)
      m->setParameter(m->parameters()[static_cast<std::size_t>(c.index)].name, v);
    else
      e[static_cast<std::size_t>(c.effect)].values[static_cast<std::size_t>(c.index)] = v;
  }
  return {std::move(m), std::move(e)};
}

std::vector<double> NonlinearSeries::targets() const {
  std::vector<double> t = y;
  if (deflection.empty()) return t;
  double mean = 0.0;
  for (double v : deflection) mean += v;
  mean /= static_cast<double>(deflection.size());
  for (double v : deflection) t.push_back(deflectionWeight * (v - mean));
  return t;
}

bool NonlinearProblem::simulate(const Eigen::VectorXd& phi, const NonlinearSeries& s, std::vector<double>& yhat,
                                std::vector<double>* deflection) const {
  try {
    auto built = build(phi);
    NonlinearPlant plant(*built.first, built.second);
    if (smoothingSpeed > 0.0) plant.setSmoothingSpeed(smoothingSpeed);
    if (s.deflection.empty()) return predictOutput(plant, s, substeps, observer, output, yhat, deflection);
    std::vector<double> arm;
    if (!predictOutput(plant, s, substeps, observer, output, yhat, deflection, &arm)) return false;
    double mean = 0.0;
    for (double v : arm) mean += v;
    mean /= static_cast<double>(arm.size());
    for (double v : arm) yhat.push_back(s.deflectionWeight * (v - mean));
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

bool NonlinearProblem::evaluate(const Eigen::VectorXd& phi, Eigen::VectorXd& eps, Eigen::MatrixXd* psi) const {
  if (cancel && cancel->load()) return false;
  std::vector<std::vector<double>> yhat(series.size());
  Eigen::Index N = 0;
  for (std::size_t s = 0; s < series.size(); ++s) {
    if (!simulate(phi, *series[s], yhat[s])) return false;
    const std::size_t outputs = series[s]->deflection.empty() ? 1 : 2;
    N += static_cast<Eigen::Index>(series[s]->fitSamples.empty() ? yhat[s].size()
                                                                 : outputs * series[s]->fitSamples.size());
  }
  // The errors that enter the loss: every sample, or the series' fitSamples (of each output
  // when the deflection is stacked after the first).
  auto stack = [this](std::size_t s, const std::vector<double>& y, auto&& put) {
    const auto& pick = series[s]->fitSamples;
    if (pick.empty()) {
      for (std::size_t k = 0; k < y.size(); ++k) put(k);
      return;
    }
    const std::size_t n = series[s]->y.size();
    for (std::size_t at = 0; at < y.size(); at += n)
      for (std::size_t k : pick) put(at + k);
  };
  eps.resize(N);
  for (std::size_t s = 0, at = 0; s < series.size(); ++s) {
    const std::vector<double> target = series[s]->deflection.empty() ? std::vector<double>{} : series[s]->targets();
    const std::vector<double>& y = target.empty() ? series[s]->y : target;
    if (y.size() != yhat[s].size()) return false;
    stack(s, yhat[s], [&](std::size_t k) { eps[static_cast<Eigen::Index>(at++)] = y[k] - yhat[s][k]; });
  }
  if (!psi) return true;
  const std::size_t p = coords.size();
  psi->resize(N, static_cast<Eigen::Index>(p));
  // Column j: a forward difference (backward when the forward point is refused or sits on a
  // bound), every experiment with the same step.
  auto column = [&](std::size_t j, std::vector<double>& y2) {
    const auto jj = static_cast<Eigen::Index>(j);
    for (int attempt = 0; attempt < 2; ++attempt) {
      Eigen::VectorXd p2 = phi;
      p2[jj] += (attempt == 0 ? 1.0 : -1.0) * coords[j].step(phi[jj]);
      coords[j].project(p2[jj]);
      const double d = p2[jj] - phi[jj];
      if (d == 0.0) continue;
      bool ok = true;
      Eigen::Index at = 0;
      for (std::size_t s = 0; s < series.size() && ok; ++s) {
        ok = simulate(p2, *series[s], y2);
        if (ok) stack(s, y2, [&](std::size_t k) { (*psi)(at++, jj) = (y2[k] - yhat[s][k]) / d; });
      }
      if (ok) return true;
    }
    return false;
  };
  std::atomic<std::size_t> next{0};
  std::atomic<bool> ok{true};
  auto worker = [&]() {
    std::vector<double> y2;
    for (;;) {
      const std::size_t j = next++;
      if (j >= p || !ok.load() || (cancel && cancel->load())) return;
      if (!column(j, y2)) ok = false;
    }
  };
  const int nt = std::max(1, std::min<int>(threads, static_cast<int>(p)));
  std::vector<std::thread> pool;
  for (int t = 1; t < nt; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return ok.load() && !(cancel && cancel->load());
}

LeastSquaresSolution NonlinearProblem::solve(const Eigen::VectorXd& phi0, int iterations, double relativeTolerance,
                                             const ProgressCallback& progress) const {
  LeastSquaresProblem lsp;
  lsp.evaluate = [this](const Eigen::VectorXd& phi, Eigen::VectorXd& eps, Eigen::MatrixXd* psi) {
    return evaluate(phi, eps, psi);
  };
  lsp.project = [this](Eigen::VectorXd& phi) {
    for (std::size_t i = 0; i < coords.size(); ++i) coords[i].project(phi[static_cast<Eigen::Index>(i)]);
  };
  const std::atomic<bool>* c = cancel;
  return levenbergMarquardt(lsp, phi0, iterations, relativeTolerance, 1e-3,
                            [c, &progress](double f, const std::string& stage) {
                              if (c && c->load()) return ProgressAction::Abort;
                              return progress ? progress(f, stage) : ProgressAction::Continue;
                            });
}

Eigen::VectorXd NonlinearProblem::coordinatesOf(const std::vector<Effect>& e) const {
  Eigen::VectorXd phi(static_cast<Eigen::Index>(coords.size()));
  const auto& ps = base->parameters();
  for (std::size_t i = 0; i < coords.size(); ++i) {
    const auto& c = coords[i];
    const double v = c.base ? ps[static_cast<std::size_t>(c.index)].value
                            : e[static_cast<std::size_t>(c.effect)].values[static_cast<std::size_t>(c.index)];
    phi[static_cast<Eigen::Index>(i)] = c.toPhi(v);
  }
  return phi;
}

std::vector<NonlinearCoordinate> baseCoordinates(const PhysicalModel& m) {
  std::vector<NonlinearCoordinate> out;
  const auto& ps = m.parameters();
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (!ps[i].free) continue;
    NonlinearCoordinate c;
    c.index = static_cast<int>(i);
    if (ps[i].lower >= 0.0 && ps[i].value > 0.0) {
      c.map = CoordinateMap::Log;
    } else {
      c.map = CoordinateMap::Scaled;
      c.scale = std::max(std::abs(ps[i].value), 1e-6);
    }
    out.push_back(c);
  }
  return out;
}

FitEffect FitEffect::defaults(EffectKind k) { return of(Effect::withDefaults(k)); }

FitEffect FitEffect::of(const Effect& e) {
  FitEffect f;
  f.effect = e;
  f.free.clear();
  for (const auto& p : effectParameters(e)) f.free.push_back(p.freeInFit);
  return f;
}

bool NonlinearPemOptions::isValid(std::string* why) const {
  auto fail = [why](const char* s) {
    if (why) *why = s;
    return false;
  };
  if (maxIterations < 1) return fail("at least one iteration is needed");
  if (!(relativeTolerance > 0.0)) return fail("the relative tolerance must be positive");
  if (!(level > 0.0 && level < 1.0)) return fail("the level must lie strictly between 0 and 1");
  if (substeps < 0 || substeps > 200) return fail("substeps must be in 0..200");
  if (threads < 1 || threads > 64) return fail("threads must be in 1..64");
  if (!(smoothingSpeed >= 0.0) || !std::isfinite(smoothingSpeed)) return fail("the smoothing speed must be >= 0");
  if (!(observerBandwidthHz >= 0.0) || !std::isfinite(observerBandwidthHz))
    return fail("the observer bandwidth must be >= 0 Hz");
  if (why) why->clear();
  return true;
}

namespace {

// Effect values are searched as their registry domain says: logarithms for values positive
// by nature (a smoothing speed, a number of periods), scaled values for those of either sign
// (a phase, a skew, a ripple's sine and cosine coefficients), non-negative scaled values for
// the others.
NonlinearCoordinate effectCoordinate(int effect, int index, const Effect& e) {
  NonlinearCoordinate c;
  c.base = false;
  c.effect = effect;
  c.index = index;
  const EffectParameterInfo info = effectParameters(e)[static_cast<std::size_t>(index)];
  const double v = e.values[static_cast<std::size_t>(index)];
  const double typical = std::max(std::abs(v), std::abs(info.defaultValue));
  switch (info.domain) {
    case ValueDomain::Positive: c.map = CoordinateMap::Log; break;
    case ValueDomain::Signed:
      c.map = CoordinateMap::Scaled;
      c.scale = typical > 0.0 ? typical : (info.unit == "s" ? 1e-3 : 1.0);
      break;
    case ValueDomain::NonNegative:
    case ValueDomain::Fraction:
      c.map = CoordinateMap::NonNegative;
      c.scale = typical > 0.0 ? typical : 1.0;  // a value that starts (and defaults) at zero
      break;
  }
  c.rough = effectDefinition(e).roughLoss();
  return c;
}

}  // namespace

NonlinearPemResult nonlinearPem(const PhysicalModel& start, const std::vector<FitEffect>& effects,
                                const std::vector<NonlinearSeries>& experiments, const NonlinearPemOptions& o,
                                const ProgressCallback& progress) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("nonlinearPem: " + why);
  if (experiments.empty()) throw std::invalid_argument("nonlinearPem: no experiment");
  for (const auto& s : experiments)
    if (s.u.size() != s.y.size() || s.u.size() < 2 || !(s.Ts > 0.0) ||
        (!s.deflection.empty() && s.deflection.size() != s.u.size()) ||
        std::abs(s.Ts - experiments.front().Ts) > 1e-9 * s.Ts)
      throw std::invalid_argument("nonlinearPem: every experiment needs u and y of equal length (>= 2) and "
                                  "the same positive sample time");
  std::vector<Effect> values;
  for (const auto& f : effects) {
    if (effectDefinition(f.effect).structural())
      throw std::invalid_argument(std::string("nonlinearPem: ") + toString(f.effect.kind) +
                                  " changes the structure; fit the larger structure");
    values.push_back(f.effect);
  }
  std::unique_ptr<PhysicalModel> base(static_cast<PhysicalModel*>(start.clone().release()));
  base->setOptions(ModelOptions{});
  { const NonlinearPlant check(*base, values); }  // throws for invalid or repeated effects
  const auto t0 = std::chrono::steady_clock::now();
  NonlinearProblem pr;
  pr.base = base.get();
  pr.effects = values;
  pr.coords = baseCoordinates(*base);
  for (std::size_t i = 0; i < effects.size(); ++i)
    for (std::size_t k = 0; k < effects[i].effect.values.size(); ++k)
      if (effects[i].isFree(k))
        pr.coords.push_back(effectCoordinate(static_cast<int>(i), static_cast<int>(k), effects[i].effect));
  if (pr.coords.empty()) throw std::invalid_argument("nonlinearPem: no free parameter");
  for (const auto& s : experiments) pr.series.push_back(&s);
  pr.substeps = o.substeps > 0 ? o.substeps : defaultSubsteps(experiments.front().Ts);
  pr.output = o.output;
  pr.observer = loadObserver(*base, o.observerBandwidthHz);
  pr.threads = o.threads;
  pr.smoothingSpeed = o.smoothingSpeed;
  LeastSquaresSolution sol =
      pr.solve(pr.coordinatesOf(values), o.maxIterations, o.relativeTolerance, progress);
  NonlinearPemResult R;
  R.summary = sol.summary;
  R.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (sol.summary.termination == Termination::Failed && sol.eps.size() == 0) {
    R.summary.message = "the start model with its effects cannot be simulated on the data: " + sol.summary.message;
    return R;
  }
  auto built = pr.build(sol.phi);
  R.model = std::move(built.first);
  R.model->setOptions(start.options());
  R.effects = std::move(built.second);
  const auto p = static_cast<Eigen::Index>(pr.coords.size());
  fillStatistics(R.summary, sol.sumSquares, sol.eps.size(), static_cast<int>(p));
  // Covariance (4.37) of the coordinates, carried into physical units.
  Eigen::MatrixXd C = gaussNewtonCovariance(sol.psi, sol.sumSquares);
  if (C.size()) {
    Eigen::VectorXd slope(p);
    for (Eigen::Index j = 0; j < p; ++j) slope[j] = pr.coords[static_cast<std::size_t>(j)].slope(sol.phi[j]);
    C = slope.asDiagonal() * C * slope.asDiagonal();
  }
  R.covariance = C;
  const double z = twoSidedNormalQuantile(o.level);
  std::vector<double> sd(static_cast<std::size_t>(p), 0.0);
  for (Eigen::Index j = 0; j < p; ++j) sd[static_cast<std::size_t>(j)] = C.size() ? std::sqrt(std::max(0.0, C(j, j))) : NAN;
  auto coordOf = [&pr](bool isBase, int effect, int index) -> int {
    for (std::size_t j = 0; j < pr.coords.size(); ++j) {
      const auto& c = pr.coords[j];
      if (c.base == isBase && c.index == index && (isBase || c.effect == effect)) return static_cast<int>(j);
    }
    return -1;
  };
  auto row = [&](const std::string& name, const std::string& unit, double value, int j) {
    PemParameter q{name, unit, value, j >= 0, 0.0, value, value};
    if (j >= 0) {
      q.std = sd[static_cast<std::size_t>(j)];
      q.lower = value - z * q.std;
      q.upper = value + z * q.std;
    }
    R.parameters.push_back(q);
  };
  const auto& ps = R.model->parameters();
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const int j = coordOf(true, 0, static_cast<int>(i));
    if (j >= 0) R.freeIndices.push_back(static_cast<int>(i));
    row(ps[i].name, ps[i].unit, ps[i].value, j);
  }
  for (std::size_t e = 0; e < R.effects.size(); ++e) {
    const auto info = effectParameters(R.effects[e]);
    for (std::size_t k = 0; k < info.size(); ++k) {
      const int j = coordOf(false, static_cast<int>(e), static_cast<int>(k));
      if (j >= 0) R.effectFree.emplace_back(static_cast<int>(e), static_cast<int>(k));
      row(info[k].name, info[k].unit, R.effects[e].values[k], j);
    }
  }
  return R;
}

Eigen::VectorXd simulateNonlinear(const PhysicalModel& model, const std::vector<Effect>& effects,
                                  const NonlinearSeries& series, const NonlinearPemOptions& o) {
  std::unique_ptr<PhysicalModel> m(static_cast<PhysicalModel*>(model.clone().release()));
  m->setOptions(ModelOptions{});
  NonlinearPlant plant(*m, effects);
  if (o.smoothingSpeed > 0.0) plant.setSmoothingSpeed(o.smoothingSpeed);
  std::vector<double> yhat;
  const int substeps = o.substeps > 0 ? o.substeps : defaultSubsteps(series.Ts);
  if (!predictOutput(plant, series, substeps, loadObserver(*m, o.observerBandwidthHz), o.output, yhat)) return {};
  return Eigen::Map<const Eigen::VectorXd>(yhat.data(), static_cast<Eigen::Index>(yhat.size()));
}

}  // namespace flexarm
