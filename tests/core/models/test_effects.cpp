// The nonlinear plant: without effects it is the linear model; each effect changes the
// response the way its physics says.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "core/models/analysis.h"
#include "core/models/effect_registry.h"
#include "core/models/nonlinear_plant.h"

namespace flexarm {
namespace {

std::vector<double> whiteTorque(std::size_t n, double std, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, std);
  std::vector<double> u(n);
  for (auto& v : u) v = g(rng);
  return u;
}

TEST(Effects, NamesRoundTrip) {
  for (EffectKind k : allEffectKinds()) {
    EXPECT_EQ(effectKindFromString(toString(k)), k);
    std::string why;
    const auto e = parseEffect(toString(Effect::withDefaults(k)), &why);
    ASSERT_TRUE(e) << why;
    EXPECT_EQ(e->values, Effect::withDefaults(k).values);
  }
  EXPECT_STREQ(toString(EffectKind::NonlinearSpring), "nonlinear_spring");
  std::string why;
  EXPECT_FALSE(parseEffect("stiction", &why));
  EXPECT_NE(why.find("unknown effect"), std::string::npos);
  EXPECT_FALSE(parseEffect("backlash:-1", &why));
  EXPECT_FALSE(parseEffect("backlash:1,2", &why));
  EXPECT_FALSE(parseEffect("torque_ripple:0.1,abc", &why));
  const auto e = parseEffect("torque_ripple:0.1", &why);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->value(0), 0.1);
  EXPECT_EQ(e->value(1), 6.0);
  EXPECT_EQ(e->value(2), 0.0);  // the cosine coefficient: A sin(n phi_m), as before phases
  // More harmonics come in pairs after b_1; an even count is refused.
  const auto two = parseEffect("torque_ripple:0.1,4,0.02,0.03,-0.01", &why);
  ASSERT_TRUE(two) << why;
  EXPECT_EQ(two->values.size(), 5u);
  EXPECT_EQ(effectParameters(*two)[3].name, "a_2");
  EXPECT_EQ(effectParameters(*two)[4].name, "b_2");
  EXPECT_EQ(parseEffect(toString(*two), &why)->values, two->values);
  EXPECT_FALSE(parseEffect("torque_ripple:0.1,4,0.02,0.03", &why));
  EXPECT_FALSE(parseEffect("coulomb_friction:0.1,0.1,3", &why));
  // Signs the physics allows: a sine/cosine coefficient and a phase either way, friction
  // never below zero, a skew either way within a second.
  EXPECT_TRUE(parseEffect("torque_ripple:-0.1,6,-0.2", &why)) << why;
  EXPECT_FALSE(parseEffect("coulomb_friction:-0.01", &why));
  EXPECT_FALSE(parseEffect("asymmetric_coulomb:0.1,-0.1", &why));
  EXPECT_TRUE(parseEffect("encoder_skew:-0.003", &why)) << why;
  EXPECT_FALSE(parseEffect("encoder_skew:2", &why));
  EXPECT_TRUE(parseEffect("gravity:50,-2.5", &why)) << why;
}

// Every effect of the registry has what the plant, fit, simulate, discovery and the help
// lists read: a name that parses back, parameters with units and meanings whose defaults are
// valid, a help line, a description of its estimates and a confirmation signature.
TEST(Effects, EveryRegisteredEffectIsComplete) {
  const std::string help = effectHelpLines();
  for (EffectKind k : allEffectKinds()) {
    const EffectDefinition& d = effectDefinition(k);
    EXPECT_EQ(d.kind(), k);
    EXPECT_NE(help.find("  " + std::string(toString(k)) + ":"), std::string::npos) << toString(k);
    const Effect e = Effect::withDefaults(k);
    std::string why;
    EXPECT_TRUE(e.isValid(&why)) << why;
    for (const auto& p : effectParameters(k)) {
      EXPECT_FALSE(p.name.empty());
      EXPECT_FALSE(p.meaning.empty()) << p.name;
      EXPECT_LE(p.lower, p.defaultValue) << p.name;
      EXPECT_GE(p.upper, p.defaultValue) << p.name;
    }
    EXPECT_FALSE(d.summary().empty());
    EXPECT_FALSE(d.signature().empty());
    std::vector<EffectParameterEstimate> est;
    for (const auto& p : effectParameters(e)) est.push_back({p.name, p.unit, p.defaultValue, 0.0, 0.0, 0.0, true, false});
    for (const auto& q : d.derivedQuantities(e)) est.push_back({q.name, q.unit, q.value(e.values), 0.0, 0.0, 0.0, true, true});
    EXPECT_FALSE(d.describe(est).empty()) << toString(k);
    // Its size scales: withMagnitude gives the size asked for.
    if (!d.structural() && std::abs(d.magnitude(e)) > 0.0) {
      EXPECT_NEAR(d.magnitude(d.withMagnitude(e, 0.5 * d.magnitude(e))), 0.5 * d.magnitude(e),
                  1e-12 * std::abs(d.magnitude(e)))
          << toString(k);
    }
  }
}

// The ripple as the physics has it: several harmonics of the order n, each with its phase
// against the encoder's zero, on the motor: sum_k A_k sin(k n phi_m + psi_k) with
// a_k = A_k cos psi_k, b_k = A_k sin psi_k.
TEST(Effects, RippleHarmonicsWithPhasesActOnTheMotor) {
  auto rigid = makeModel("rigid");
  const double r = rigid->value("r"), J = rigid->value("J_m") + r * r * rigid->value("J_a");
  const double n = 4.0, A1 = 0.3, psi1 = 2.1, A2 = 0.12, psi2 = -0.7;
  Effect ripple = Effect::withDefaults(EffectKind::TorqueRipple);
  ripple.values = {A1 * std::cos(psi1), n, A1 * std::sin(psi1), A2 * std::cos(psi2), A2 * std::sin(psi2)};
  const NonlinearPlant plant(*rigid, {ripple});
  const NonlinearPlant free(*rigid, {});
  const EffectDefinition& d = effectDefinition(EffectKind::TorqueRipple);
  const auto derived = d.derivedQuantities(ripple);
  ASSERT_EQ(derived.size(), 4u);
  EXPECT_NEAR(derived[0].value(ripple.values), A1, 1e-12);
  EXPECT_NEAR(derived[1].value(ripple.values), psi1, 1e-12);
  EXPECT_NEAR(derived[2].value(ripple.values), A2, 1e-12);
  EXPECT_NEAR(derived[3].value(ripple.values), psi2, 1e-12);
  NonlinearPlant::State x{}, dx{}, d0{};
  for (double phi : {0.0, 0.3, 1.7, -2.9, 10.4}) {
    x[1] = phi;  // rigid: phi_m' then phi_m
    plant.derivative(x.data(), 0.0, 0.0, dx.data());
    free.derivative(x.data(), 0.0, 0.0, d0.data());
    const double tau = A1 * std::sin(n * phi + psi1) + A2 * std::sin(2 * n * phi + psi2);
    EXPECT_NEAR((dx[0] - d0[0]) * J, tau, 1e-12) << phi;
  }
}

TEST(Effects, PlantWithoutEffectsIsTheLinearModel) {
  auto m = makeModel("three-mass");
  NonlinearPlant plant(*m, {});
  const double Ts = 5e-4;
  const auto u = whiteTorque(2000, 1.0, 7);
  const auto r = simulateTorque(plant, u, Ts);
  const StateSpace d = discretize(m->stateSpace(), Ts);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.states());
  double maxErr = 0.0, maxAbs = 0.0;
  for (std::size_t k = 0; k < u.size(); ++k) {
    const double y = (d.C * x)(0);
    maxErr = std::max(maxErr, std::abs(y - r.motorVelocity[k]));
    maxAbs = std::max(maxAbs, std::abs(y));
    x = d.A * x + d.B.col(0) * u[k];
  }
  EXPECT_LT(maxErr, 1e-6 * maxAbs);
}

// The arm-side effects act where the physics puts them: gravity and arm friction on the arm
// (through the gear on a rigid axis), asymmetric Coulomb friction on the motor with its own
// size each way, and the arm angle is r phi_m minus the whole deflection.
TEST(Effects, ArmSideEffectsActOnTheArm) {
  auto rigid = makeModel("rigid");
  const double r = rigid->value("r"), J = rigid->value("J_m") + r * r * rigid->value("J_a");
  Effect gravity = Effect::withDefaults(EffectKind::Gravity);
  gravity.values = {200.0, M_PI / 2};  // -200 sin(phi_a + pi/2): -200 N m at phi_a = 0
  const NonlinearPlant heavy(*rigid, {gravity});
  NonlinearPlant::State x{}, dx{};
  heavy.derivative(x.data(), 0.0, 0.0, dx.data());
  EXPECT_NEAR(dx[0], -r * 200.0 / J, 1e-9 * r * 200.0 / J);
  // The motor torque that holds the arm (k_T = 1): 200 N m at the arm is r 200 at the motor.
  heavy.derivative(x.data(), r * 200.0, 0.0, dx.data());
  EXPECT_NEAR(dx[0], 0.0, 1e-9);

  Effect asym = Effect::withDefaults(EffectKind::AsymmetricCoulomb);
  asym.values = {0.2, 0.5};
  const NonlinearPlant sticky(*rigid, {asym});
  const NonlinearPlant free(*rigid, {});
  NonlinearPlant::State dFree{};
  for (double v : {1.0, -1.0}) {
    x[0] = v;
    sticky.derivative(x.data(), 0.0, 0.0, dx.data());
    free.derivative(x.data(), 0.0, 0.0, dFree.data());
    const double expected = -(v > 0 ? 0.2 : 0.5) * std::tanh(v / 0.1) / J;  // smoothing 0.1 rad/s
    EXPECT_NEAR(dx[0] - dFree[0], expected, 1e-9 * std::abs(expected)) << v;
  }

  auto twoMass = makeModel("two-mass");
  Effect arm = Effect::withDefaults(EffectKind::ArmFriction);
  arm.values = {40.0, 0.0};
  const NonlinearPlant rubbing(*twoMass, {arm});
  const NonlinearPlant plain(*twoMass, {});
  NonlinearPlant::State y{};
  y[0] = 1e-4;  // r phi_m - phi_a
  y[1] = 0.5;   // phi_m'
  y[2] = 0.004;  // phi_a'
  y[3] = 3.0;   // phi_m
  rubbing.derivative(y.data(), 0.0, 0.0, dx.data());
  plain.derivative(y.data(), 0.0, 0.0, dFree.data());
  EXPECT_NEAR(dx[2] - dFree[2], -40.0 * 0.004 / twoMass->value("J_a"), 1e-12);
  EXPECT_DOUBLE_EQ(dx[1], dFree[1]);  // the motor feels it only through the spring
  EXPECT_DOUBLE_EQ(rubbing.armDeflection(y), 1e-4);
  EXPECT_DOUBLE_EQ(rubbing.armAngle(y), twoMass->value("r") * 3.0 - 1e-4);
  EXPECT_DOUBLE_EQ(rubbing.armVelocity(y), 0.004);

  // Three-mass: the deflection to the arm is the gear's plus the arm spring's.
  const NonlinearPlant three(*makeModel("three-mass"), {});
  NonlinearPlant::State z{};
  z[0] = 1e-4;
  z[1] = 2e-4;
  EXPECT_DOUBLE_EQ(three.armDeflection(z), 3e-4);
  EXPECT_DOUBLE_EQ(three.gearDeflection(z), 1e-4);
}

TEST(Effects, GearEffectsNeedAGearSpring) {
  auto rigid = makeModel("rigid");
  EXPECT_THROW(NonlinearPlant(*rigid, {Effect::withDefaults(EffectKind::Backlash)}),
               std::invalid_argument);
  auto two = makeModel("two-mass");
  EXPECT_THROW(NonlinearPlant(*two, {Effect::withDefaults(EffectKind::InputDelay),
                                     Effect::withDefaults(EffectKind::InputDelay)}),
               std::invalid_argument);
  EXPECT_THROW(NonlinearPlant(*makeModel("four-mass"), {Effect::withDefaults(EffectKind::ExtraMass)}),
               std::invalid_argument);
}

TEST(Effects, BacklashGivesAFlatStretchInTheGearTorque) {
  auto m = makeModel("two-mass");
  Effect b = Effect::withDefaults(EffectKind::Backlash);
  b.values[0] = 3e-4;
  const auto u = whiteTorque(4000, 2.0, 11);
  const auto with = simulateTorque(NonlinearPlant(*m, {b}), u, 5e-4);
  const auto without = simulateTorque(NonlinearPlant(*m, {}), u, 5e-4);
  int inGap = 0, inGapWithout = 0;
  for (std::size_t k = 0; k < u.size(); ++k) {
    if (std::abs(with.gearDeflection[k]) < b.value(0)) {
      ++inGap;
      EXPECT_EQ(with.gearTorque[k], 0.0);
    } else {
      EXPECT_GT(std::abs(with.gearTorque[k]) + 1e-12, 0.0);
    }
    if (std::abs(without.gearDeflection[k]) < b.value(0) && without.gearDeflection[k] != 0.0 &&
        std::abs(without.gearTorque[k]) > 1.0)
      ++inGapWithout;
  }
  EXPECT_GT(inGap, 50);          // the trajectory crosses the gap often
  EXPECT_GT(inGapWithout, 10);   // while the linear spring carries torque there
}

// Period of the free oscillation of the gear deflection from an initial deflection delta0.
double freeFrequency(const PhysicalModel& m, const std::vector<Effect>& effects, double delta0) {
  NonlinearPlant plant(m, effects);
  TorqueResponseOptions o;
  o.initialState.assign(static_cast<std::size_t>(plant.states()), 0.0);
  o.initialState[0] = delta0;
  o.substeps = 10;
  const double Ts = 1e-4;
  const auto r = simulateTorque(plant, std::vector<double>(3000, 0.0), Ts, o);
  std::vector<double> crossings;
  for (std::size_t k = 1; k < r.gearDeflection.size(); ++k)
    if (r.gearDeflection[k - 1] > 0.0 && r.gearDeflection[k] <= 0.0) {
      const double f = r.gearDeflection[k - 1] / (r.gearDeflection[k - 1] - r.gearDeflection[k]);
      crossings.push_back((static_cast<double>(k - 1) + f) * Ts);
    }
  EXPECT_GE(crossings.size(), 3u);
  return 2.0 * M_PI / (crossings[1] - crossings[0]);  // first full period: largest amplitude
}

TEST(Effects, NonlinearSpringResonanceRisesWithAmplitude) {
  auto m = makeModel("two-mass");
  m->setParameter("d_a", 5.0);
  const Effect s = Effect::withDefaults(EffectKind::NonlinearSpring);
  const double small = freeFrequency(*m, {s}, 1e-5), large = freeFrequency(*m, {s}, 2e-3);
  const double linSmall = freeFrequency(*m, {}, 1e-5), linLarge = freeFrequency(*m, {}, 2e-3);
  EXPECT_NEAR(linSmall, linLarge, 1e-3 * linSmall);  // linear: no amplitude dependence
  EXPECT_NEAR(small, linSmall, 1e-3 * linSmall);
  EXPECT_GT(large, 1.5 * small);  // beta delta^2 = 8 at 2 mrad: clearly stiffer
  const auto peaks = peakFrequencies(m->stateSpace());
  ASSERT_EQ(peaks.size(), 1u);
  EXPECT_NEAR(linSmall, peaks[0].frequency, 0.01 * peaks[0].frequency);
}

int crossCorrelationPeakLag(const std::vector<double>& u, const std::vector<double>& y,
                            int maxLag) {
  int best = 0;
  double bestValue = -1.0;
  for (int lag = 0; lag <= maxLag; ++lag) {
    double s = 0.0;
    for (std::size_t k = static_cast<std::size_t>(lag); k < y.size(); ++k)
      s += u[k - static_cast<std::size_t>(lag)] * y[k];
    if (std::abs(s) > bestValue) {
      bestValue = std::abs(s);
      best = lag;
    }
  }
  return best;
}

TEST(Effects, InputDelayShiftsTheCrossCorrelationPeak) {
  auto m = makeModel("two-mass");
  const double Ts = 5e-4;
  const auto u = whiteTorque(8000, 1.0, 3);
  Effect d = Effect::withDefaults(EffectKind::InputDelay);
  d.values[0] = 0.005;  // 10 samples
  auto accel = [&](const std::vector<Effect>& e) {
    const auto r = simulateTorque(NonlinearPlant(*m, e), u, Ts);
    std::vector<double> a(r.motorVelocity.size(), 0.0);
    for (std::size_t k = 1; k < a.size(); ++k) a[k] = r.motorVelocity[k] - r.motorVelocity[k - 1];
    return a;
  };
  const int lag0 = crossCorrelationPeakLag(u, accel({}), 40);
  const int lag1 = crossCorrelationPeakLag(u, accel({d}), 40);
  EXPECT_EQ(lag0, 1);  // the velocity change over the sample after the torque step
  EXPECT_EQ(lag1 - lag0, 10);
}

TEST(Effects, ExtraMassAddsASecondResonance) {
  auto m = makeModel("two-mass");
  m->setParameter("d_a", 20.0);
  Effect e = Effect::withDefaults(EffectKind::ExtraMass);
  e.values = {200.0, 0.3};
  NonlinearPlant plant(*m, {e});
  EXPECT_EQ(plant.model().structureName(), "three-mass");
  // Periodic multisine torque on a 1 s grid (1 rad/s spacing... 2 pi rad/s), steady state.
  const double Ts = 5e-4;
  const std::size_t P = 2000;
  std::vector<double> u(3 * P, 0.0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> ph(0.0, 2 * M_PI);
  std::vector<int> lines;
  for (int k = 5; k <= 120; ++k) lines.push_back(k);
  for (int k : lines) {
    const double phase = ph(rng);
    for (std::size_t i = 0; i < u.size(); ++i)
      u[i] += 0.05 * std::cos(2 * M_PI * k * static_cast<double>(i % P) / P + phase);
  }
  auto measured = [&](const NonlinearPlant& p) {
    const auto r = simulateTorque(p, u, Ts);
    std::vector<double> mag;
    for (int k : lines) {
      std::complex<double> U = 0.0, Y = 0.0;
      for (std::size_t i = 2 * P; i < 3 * P; ++i) {
        const std::complex<double> w = std::polar(1.0, -2 * M_PI * k * double(i - 2 * P) / P);
        U += u[i] * w;
        Y += r.motorVelocity[i] * w;
      }
      mag.push_back(std::abs(Y / U));
    }
    return mag;
  };
  auto localMaxima = [](const std::vector<double>& v) {
    int count = 0;
    for (std::size_t i = 1; i + 1 < v.size(); ++i)
      if (v[i] > v[i - 1] && v[i] > v[i + 1]) ++count;
    return count;
  };
  EXPECT_EQ(localMaxima(measured(NonlinearPlant(*m, {}))), 1);
  EXPECT_EQ(localMaxima(measured(plant)), 2);
}

}  // namespace
}  // namespace flexarm
