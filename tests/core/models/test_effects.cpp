// The nonlinear plant: without effects it is the linear model; each effect changes the
// response the way its physics says.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "core/models/analysis.h"
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
  EXPECT_FALSE(parseEffect("gravity", &why));
  EXPECT_NE(why.find("unknown effect"), std::string::npos);
  EXPECT_FALSE(parseEffect("backlash:-1", &why));
  EXPECT_FALSE(parseEffect("backlash:1,2", &why));
  EXPECT_FALSE(parseEffect("torque_ripple:0.1,abc", &why));
  const auto e = parseEffect("torque_ripple:0.1", &why);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->value(0), 0.1);
  EXPECT_EQ(e->value(1), 6.0);
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
