#include "core/models/nonlinear_plant.h"

#include <cmath>
#include <stdexcept>

namespace flexarm {

NonlinearPlant::NonlinearPlant(const PhysicalModel& model, const std::vector<Effect>& effects)
    : effects_(effects) {
  std::vector<bool> seen(allEffectKinds().size(), false);
  std::unique_ptr<ParametricModel> current = model.clone();
  bool gearEffects = false;
  std::string gearEffectNames;
  for (const Effect& e : effects) {
    std::string why;
    if (!e.isValid(&why)) throw std::invalid_argument(why);
    auto s = seen[static_cast<std::size_t>(e.kind)];
    if (s) throw std::invalid_argument(std::string("the effect ") + toString(e.kind) + " is given twice");
    s = true;
    const EffectDefinition& d = effectDefinition(e);
    if (d.needsGearSpring()) {
      gearEffects = true;
      gearEffectNames += (gearEffectNames.empty() ? "" : " and ") + std::string(d.name());
    }
    if (d.structural()) {
      auto bigger = d.structure(static_cast<const PhysicalModel&>(*current), e, &why);
      if (!bigger) throw std::invalid_argument(why);
      current = std::move(bigger);
    }
  }
  model_.reset(static_cast<PhysicalModel*>(current.release()));
  ModelOptions velocity;
  model_->setOptions(velocity);
  const ModelTopology topo = model_->topology();
  n_ = topo.coreStates;
  if (n_ + 1 > kMaxStates) throw std::invalid_argument("NonlinearPlant: too many states");
  mv_ = topo.motorVelocityState;
  arm_ = topo.armVelocityState < 0 ? mv_ : topo.armVelocityState;
  armScale_ = topo.armVelocityState < 0 ? model_->value("r") : 1.0;
  gear_ = topo.gearDeflectionState;
  ratio_ = model_->value("r");
  kT_ = model_->value("k_T");
  fm_ = model_->indexOf("f_m") >= 0 ? model_->value("f_m") : 0.0;
  {
    const Eigen::RowVectorXd row = model_->armDeflectionRow();
    for (int i = 0; i < n_; ++i) armDeflection_[static_cast<std::size_t>(i)] = row[i];
  }

  const StateSpace ss = model_->stateSpace();
  Eigen::MatrixXd A0 = ss.A;
  const double Jm = model_->value("J_m");
  for (int i = 0; i < n_; ++i) {
    bu_[static_cast<std::size_t>(i)] = ss.B(i, 0);
  }
  if (topo.armVelocityState < 0) {
    // Rigid: one mass J_m + r^2 J_a; torques on the motor act directly, the arm load through r.
    const double r = model_->value("r");
    const double J = Jm + r * r * model_->value("J_a");
    bm_[static_cast<std::size_t>(mv_)] = 1.0 / J;
    bl_[static_cast<std::size_t>(mv_)] = r / J;
  } else {
    bm_[static_cast<std::size_t>(mv_)] = 1.0 / Jm;
    bl_[static_cast<std::size_t>(arm_)] = 1.0 / model_->value(topo.armInertia);
  }

  for (const Effect& e : effects_) effectDefinition(e).addToPlant(e, terms_);
  collectTerms();
  gearNonlinear_ = terms_.gearLaw;
  const bool hasGear = gear_ >= 0 && !topo.gearStiffness.empty();
  if (hasGear) {
    // Gear spring distribution s_g = dA/dk_g e_delta and deflection rate delta' = A(delta,:) x.
    const auto dK = model_->derivative(model_->indexOf(topo.gearStiffness));
    k_ = model_->value(topo.gearStiffness);
    d_ = model_->value(topo.gearDamping);
    for (int i = 0; i < n_; ++i) {
      sg_[static_cast<std::size_t>(i)] = dK.dA(i, gear_);
      gearRate_[static_cast<std::size_t>(i)] = ss.A(gear_, i);
    }
    if (gearNonlinear_)
      for (int i = 0; i < n_; ++i)
        for (int j = 0; j < n_; ++j)
          A0(i, j) -= sg_[static_cast<std::size_t>(i)] *
                      (k_ * (j == gear_ ? 1.0 : 0.0) + d_ * gearRate_[static_cast<std::size_t>(j)]);
  } else if (gearEffects || !gearTerms_.empty()) {
    throw std::invalid_argument((gearEffectNames.empty() ? std::string("a torque in the gear") : gearEffectNames) +
                                " need" + (gearEffectNames.find(" and ") == std::string::npos ? "s" : "") +
                                " a model with a gear spring (two-mass, three-mass or four-mass), not " +
                                model_->structureName());
  }
  for (int i = 0; i < n_; ++i)
    for (int j = 0; j < n_; ++j) A0_[static_cast<std::size_t>(i * kMaxStates + j)] = A0(i, j);
}

void NonlinearPlant::collectTerms() {
  smoothing_ = terms_.smoothingSpeed > 0.0 ? terms_.smoothingSpeed
                                           : effectParameters(EffectKind::CoulombFriction)[1].defaultValue;
  motorTerms_.clear();
  gearTerms_.clear();
  armTerms_.clear();
  needs_ = 0u;
  for (const auto& t : terms_.torques) {
    (t.site == TorqueSite::Motor ? motorTerms_ : t.site == TorqueSite::Gear ? gearTerms_ : armTerms_)
        .push_back(t.term.get());
    needs_ |= t.term->needs();
  }
  if (!gearTerms_.empty()) needs_ |= kNeedsGearState;
}

NonlinearPlant::NonlinearPlant(const NonlinearPlant& o)
    : model_(static_cast<PhysicalModel*>(o.model_->clone().release())),
      effects_(o.effects_),
      n_(o.n_), mv_(o.mv_), arm_(o.arm_), gear_(o.gear_), armScale_(o.armScale_), ratio_(o.ratio_),
      armDeflection_(o.armDeflection_), A0_(o.A0_),
      bu_(o.bu_), bm_(o.bm_), bl_(o.bl_), sg_(o.sg_), gearRate_(o.gearRate_),
      gearNonlinear_(o.gearNonlinear_), k_(o.k_), d_(o.d_), kT_(o.kT_), fm_(o.fm_), terms_(o.terms_) {
  collectTerms();
  smoothing_ = o.smoothing_;
}

// Gear spring and damper torque with a dead zone of half-width b and stiffening beta: no
// contact (and no damping) inside the gap.
double NonlinearPlant::gearSpring(double delta, double rate) const {
  const double b = terms_.backlash;
  double e = 0.0;
  if (delta > b) e = delta - b;
  else if (delta < -b) e = delta + b;
  else return 0.0;
  return k_ * e * (1.0 + terms_.stiffening * e * e) + d_ * rate;
}

double NonlinearPlant::gearRate(const double* x) const {
  double rate = 0.0;
  for (int j = 0; j < n_; ++j) rate += gearRate_[static_cast<std::size_t>(j)] * x[j];
  return rate;
}

void NonlinearPlant::fillSignals(const double* x, JointSignals& s, unsigned needs) const {
  s.motorVelocity = x[mv_];
  s.motorAngle = x[n_];
  s.armVelocity = arm_ == mv_ ? armScale_ * x[mv_] : x[arm_];
  s.smoothingSpeed = smoothing_;
  s.ratio = ratio_;
  if (needs & kNeedsArmAngle) {
    double deflection = 0.0;
    for (int i = 0; i < n_; ++i) deflection += armDeflection_[static_cast<std::size_t>(i)] * x[i];
    s.armAngle = ratio_ * x[n_] - deflection;
  }
  if ((needs & kNeedsGearState) && gear_ >= 0) {
    s.gearDeflection = x[gear_];
    s.gearRate = gearRate(x);
  }
}

void NonlinearPlant::derivative(const double* x, double u, double load, double* dx) const {
  const int n = n_;
  for (int i = 0; i < n; ++i) {
    const double* row = &A0_[static_cast<std::size_t>(i * kMaxStates)];
    double s = 0.0;
    for (int j = 0; j < n; ++j) s += row[j] * x[j];
    dx[i] = s + bu_[static_cast<std::size_t>(i)] * u + bl_[static_cast<std::size_t>(i)] * load;
  }
  if (!terms_.torques.empty() || gearNonlinear_) {
    JointSignals s;
    fillSignals(x, s, needs_ | (gearNonlinear_ ? kNeedsGearState : 0u));
    double motor = 0.0, arm = 0.0, gear = 0.0;
    for (const TorqueTerm* t : motorTerms_) motor += t->torque(s);
    for (const TorqueTerm* t : armTerms_) arm += t->torque(s);
    for (const TorqueTerm* t : gearTerms_) gear += t->torque(s);
    if (gearNonlinear_) gear += gearSpring(s.gearDeflection, s.gearRate);
    if (motor != 0.0)
      for (int i = 0; i < n; ++i) dx[i] += bm_[static_cast<std::size_t>(i)] * motor;
    if (arm != 0.0)
      for (int i = 0; i < n; ++i) dx[i] += bl_[static_cast<std::size_t>(i)] * arm;
    if (gear != 0.0)
      for (int i = 0; i < n; ++i) dx[i] += sg_[static_cast<std::size_t>(i)] * gear;
  }
  dx[n] = x[mv_];
}

double NonlinearPlant::armAcceleration(const State& x, double u, double load) const {
  State dx;
  derivative(x.data(), u, load, dx.data());
  return armScale_ * dx[static_cast<std::size_t>(arm_)];
}

double NonlinearPlant::gearDeflection(const State& x) const {
  return gear_ < 0 ? 0.0 : x[static_cast<std::size_t>(gear_)];
}

double NonlinearPlant::armDeflection(const State& x) const {
  double s = 0.0;
  for (int i = 0; i < n_; ++i) s += armDeflection_[static_cast<std::size_t>(i)] * x[static_cast<std::size_t>(i)];
  return s;
}

double NonlinearPlant::armAngle(const State& x) const { return ratio_ * motorAngle(x) - armDeflection(x); }

void NonlinearPlant::setSmoothingSpeed(double speed) {
  if (!(speed > 0.0) || !std::isfinite(speed))
    throw std::invalid_argument("NonlinearPlant: the smoothing speed must be positive");
  if (terms_.smoothingSpeed > 0.0) return;  // an effect's own v_s rules
  smoothing_ = speed;
}

double NonlinearPlant::armVelocity(const State& x) const {
  return arm_ == mv_ ? armScale_ * x[static_cast<std::size_t>(mv_)] : x[static_cast<std::size_t>(arm_)];
}

double NonlinearPlant::gearTorque(const State& x) const {
  if (gear_ < 0 || k_ == 0.0) return 0.0;
  const double delta = x[static_cast<std::size_t>(gear_)], rate = gearRate(x.data());
  double t = gearNonlinear_ ? gearSpring(delta, rate) : k_ * delta + d_ * rate;
  if (!gearTerms_.empty()) {
    JointSignals s;
    fillSignals(x.data(), s, needs_);
    for (const TorqueTerm* term : gearTerms_) t += term->torque(s);
  }
  return t;
}

JointSignals NonlinearPlant::jointSignals(const State& x, double torqueNow, double torqueApplied) const {
  JointSignals s;
  fillSignals(x.data(), s, kNeedsArmAngle | kNeedsGearState);
  s.gearStiffness = k_;
  s.gearDamping = d_;
  s.torqueNow = kT_ * torqueNow;
  s.torqueApplied = kT_ * torqueApplied;
  return s;
}

double NonlinearPlant::motorFriction(const State& x) const { return fm_ * x[static_cast<std::size_t>(mv_)]; }

bool TorqueResponseOptions::isValid(std::string* why) const {
  if (substeps < 1) {
    if (why) *why = "substeps must be >= 1";
    return false;
  }
  if (why) why->clear();
  return true;
}

TorqueResponse simulateTorque(const NonlinearPlant& plant, const std::vector<double>& torque,
                              double Ts, const TorqueResponseOptions& options) {
  const std::size_t N = torque.size();
  TorqueResponse r;
  for (auto* v : {&r.motorAngle, &r.motorVelocity, &r.armAcceleration, &r.gearDeflection,
                  &r.gearTorque})
    v->resize(N);
  simulateTorque(plant, torque, Ts, options,
                 [&](std::size_t k, const NonlinearPlant::State& x, double u) {
                   r.motorAngle[k] = plant.motorAngle(x);
                   r.motorVelocity[k] = plant.motorVelocity(x);
                   r.armAcceleration[k] = plant.armAcceleration(x, u, 0.0);
                   r.gearDeflection[k] = plant.gearDeflection(x);
                   r.gearTorque[k] = plant.gearTorque(x);
                   return true;
                 });
  return r;
}

std::size_t simulateTorque(const NonlinearPlant& plant, const std::vector<double>& torque,
                           double Ts, const TorqueResponseOptions& options,
                           const PlantStateVisitor& visit) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("simulateTorque: " + why);
  if (!(Ts > 0.0) || !std::isfinite(Ts))
    throw std::invalid_argument("simulateTorque: the sample time must be positive");
  NonlinearPlant::State x{};
  if (!options.initialState.empty()) {
    if (static_cast<int>(options.initialState.size()) != plant.states())
      throw std::invalid_argument("simulateTorque: the initial state needs " +
                                  std::to_string(plant.states()) + " values");
    for (int i = 0; i < plant.states(); ++i) x[static_cast<std::size_t>(i)] = options.initialState[static_cast<std::size_t>(i)];
  }
  const std::size_t N = torque.size();
  const double delay = plant.inputDelay();
  // Applied torque: the sample held over [k Ts, (k+1) Ts), shifted by the delay.
  auto torqueAt = [&torque, Ts, delay, N](double t) {
    const double tau = (t - delay) / Ts;
    if (tau < 0.0) return 0.0;
    const std::size_t k = static_cast<std::size_t>(tau);
    return torque[k < N ? k : N - 1];
  };
  const double h = Ts / options.substeps;
  for (std::size_t k = 0; k < N; ++k) {
    const double t = static_cast<double>(k) * Ts;
    if (!visit(k, x, torqueAt(t))) return k + 1;
    for (int i = 0; i < options.substeps; ++i) plant.step(x, t + i * h, h, torqueAt, 0.0);
  }
  return N;
}

}  // namespace flexarm
