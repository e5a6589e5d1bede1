// The closed-loop simulator: convergence as the integration step shrinks, determinism, the
// excitation signals, and the effects as seen in the logged signals.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "core/models/analysis.h"
#include "core/sim/closed_loop.h"
#include "core/sim/random.h"

namespace flexarm {
namespace {

const std::vector<double>& channel(const SimulationResult& r, const char* name) {
  const Channel* c = r.data.channel(name);
  if (!c) throw std::runtime_error(std::string("missing channel ") + name);
  return c->values;
}

double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

// Amplitude of the sinusoid at frequency f (Hz) in x: the DFT at f over a whole number of
// periods (rectangular), or with the mean removed and a Hann window for other records.
double lineAmplitude(const std::vector<double>& x, double Ts, double f, bool hann = false) {
  double mean = 0.0;
  if (hann) {
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
  }
  std::complex<double> s = 0.0;
  double weight = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double w =
        hann ? 0.5 - 0.5 * std::cos(2.0 * M_PI * static_cast<double>(k) / (x.size() - 1)) : 1.0;
    weight += w;
    s += (x[k] - mean) * w * std::polar(1.0, -2.0 * M_PI * f * Ts * static_cast<double>(k));
  }
  return 2.0 * std::abs(s) / weight;
}

SimulationOptions shortRun() {
  SimulationOptions o;
  o.durationS = 2.0;
  o.excitation.kind = ExcitationKind::Chirp;
  o.excitation.chirpStartHz = 30.0;
  o.excitation.chirpEndHz = 5.0;
  o.logMotorVelocity = true;
  return o;
}

TEST(ClosedLoop, ConvergesAtFourthOrderAsTheStepShrinks) {
  auto m = makeModel("three-mass");
  SimulationOptions o = shortRun();
  o.disturbance.encoderCountsPerRev = 0;  // quantization would make the map discontinuous
  const std::vector<Effect> effects = {Effect::withDefaults(EffectKind::CoulombFriction),
                                       Effect::withDefaults(EffectKind::NonlinearSpring)};
  auto velocity = [&](int substeps) {
    o.substeps = substeps;
    return channel(simulateClosedLoop(*m, effects, o), columns::kMotorVelocity);
  };
  const auto reference = velocity(64);
  const double e2 = maxAbsDiff(velocity(2), reference);
  const double e4 = maxAbsDiff(velocity(4), reference);
  const double e8 = maxAbsDiff(velocity(8), reference);
  EXPECT_GT(e2, 0.0);
  // Classical Runge-Kutta: each halving divides the error by about 16.
  EXPECT_GT(e2 / e4, 10.0) << e2 << " " << e4;
  EXPECT_GT(e4 / e8, 10.0) << e4 << " " << e8;
  EXPECT_LT(e8, 1e-6 * *std::max_element(reference.begin(), reference.end()));
}

TEST(ClosedLoop, DeterministicForASeed) {
  auto m = makeModel("two-mass");
  SimulationOptions o = shortRun();
  const auto a = simulateClosedLoop(*m, {}, o);
  const auto b = simulateClosedLoop(*m, {}, o);
  ASSERT_EQ(a.termination, Termination::Converged);
  EXPECT_EQ(channel(a, columns::kTorqueRef), channel(b, columns::kTorqueRef));
  EXPECT_EQ(channel(a, columns::kMotorAngle), channel(b, columns::kMotorAngle));
  o.seed = 2;
  const auto c = simulateClosedLoop(*m, {}, o);
  EXPECT_NE(channel(a, columns::kTorqueRef), channel(c, columns::kTorqueRef));
  EXPECT_EQ(channel(a, columns::kAngleRef), channel(c, columns::kAngleRef));  // chirp: no seed
}

TEST(ClosedLoop, EncoderQuantizesTheMeasuredAngle) {
  auto m = makeModel("two-mass");
  SimulationOptions o = shortRun();
  o.disturbance.encoderCountsPerRev = 4096;
  const double q = 2.0 * M_PI / 4096;
  // The result is kept by name: a range-for over a member of a temporary reads freed memory.
  const SimulationResult r = simulateClosedLoop(*m, {}, o);
  for (double v : channel(r, columns::kMotorAngle)) EXPECT_NEAR(v / q, std::round(v / q), 1e-6);
}

TEST(ClosedLoop, RandomIsReproducibleAndNormal) {
  Random r(42);
  double s = 0.0, s2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double v = r.normal();
    s += v;
    s2 += v * v;
  }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.01);
  Random a(7), b(7);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a.uniform(), b.uniform());
}

TEST(Excitation, PrbsHasMaximumLengthPeriod) {
  for (int bits = 5; bits <= 12; ++bits) {
    ExcitationOptions o;
    o.kind = ExcitationKind::Prbs;
    o.prbsBits = bits;
    o.prbsClockS = 1.0;
    o.taperS = 0.0;
    o.amplitude = 1.0;
    const std::size_t period = (1u << bits) - 1u;
    const auto x = makeExcitation(o, 1.0, 2 * period + 5, 3);
    for (std::size_t k = 0; k + period < x.size(); ++k) ASSERT_EQ(x[k], x[k + period]) << bits;
    // No shorter period: the sequence differs from itself shifted by any divisor.
    for (std::size_t p = 1; p < period; ++p) {
      if (period % p) continue;
      bool same = true;
      for (std::size_t k = 0; k + p < period && same; ++k) same = x[k] == x[k + p];
      EXPECT_FALSE(same) << bits << " bits, period " << p;
    }
    int ones = 0;
    for (std::size_t k = 0; k < period; ++k) ones += x[k] > 0;
    EXPECT_EQ(ones, static_cast<int>((period + 1) / 2));  // 2^(n-1) ones per period
  }
}

TEST(Excitation, MultisineHasEqualLinesOnTheGrid) {
  ExcitationOptions o;
  o.kind = ExcitationKind::Multisine;
  o.taperS = 0.0;
  o.amplitude = 0.1;
  const double Ts = 1.0 / 200.0;
  const auto x = makeExcitation(o, Ts, 2400, 9);  // one 12 s period at 200 Hz
  const double a = 0.1 / std::sqrt(360.0);
  for (int k : {1, 17, 180, 360}) EXPECT_NEAR(lineAmplitude(x, Ts, k / 12.0), a, 1e-9);
  EXPECT_NEAR(lineAmplitude(x, Ts, 361 / 12.0), 0.0, 1e-9);  // above 60 pi rad/s
  EXPECT_NEAR(lineAmplitude(x, Ts, 0.0), 0.0, 1e-9);      // no mean
  EXPECT_NEAR(lineAmplitude(x, Ts, 500 / 12.0), 0.0, 1e-9);
}

TEST(Excitation, ChirpSweepsFromHighToLow) {
  ExcitationOptions o;
  o.taperS = 0.0;
  const double Ts = 1e-3;
  const auto x = makeExcitation(o, Ts, 20000, 1);
  auto crossingsIn = [&](std::size_t from, std::size_t to) {
    int c = 0;
    for (std::size_t k = from + 1; k < to; ++k) c += (x[k - 1] < 0.0) != (x[k] < 0.0);
    return c;
  };
  // Linear sweep 30 -> 0.5 Hz over 20 s: about 29.7 Hz in the first second, 1.2 in the last.
  EXPECT_NEAR(crossingsIn(0, 1000) / 2.0, 29.3, 1.0);
  EXPECT_NEAR(crossingsIn(19000, 20000) / 2.0, 0.99, 1.0);
}

TEST(ClosedLoop, CoulombFrictionAddsTorqueWithTheSignOfVelocity) {
  auto m = makeModel("two-mass");
  SimulationOptions o;
  o.durationS = 6.0;
  o.excitation.chirpStartHz = 1.0;
  o.excitation.chirpEndHz = 0.5;
  o.excitation.amplitude = 0.5;
  o.disturbance.torqueNoiseStd = 0.0;
  o.disturbance.loadTorqueStd = 0.0;
  o.logMotorVelocity = true;
  Effect c = Effect::withDefaults(EffectKind::CoulombFriction);
  c.values = {0.08, 0.05};
  const auto with = simulateClosedLoop(*m, {c}, o), without = simulateClosedLoop(*m, {}, o);
  const auto& uw = channel(with, columns::kTorqueRef);
  const auto& u0 = channel(without, columns::kTorqueRef);
  const auto& v = channel(with, columns::kMotorVelocity);
  // Least squares of the torque difference on sign(v), where the motor moves clearly.
  double num = 0.0, den = 0.0;
  for (std::size_t k = 2000; k < uw.size(); ++k) {
    if (std::abs(v[k]) < 0.3) continue;
    const double s = v[k] > 0 ? 1.0 : -1.0;
    num += s * (uw[k] - u0[k]);
    den += 1.0;
  }
  ASSERT_GT(den, 1000.0);
  EXPECT_NEAR(num / den, 0.08, 0.01);
}

TEST(ClosedLoop, TorqueRippleGivesALineAtItsMultipleOfMotorSpeed) {
  auto m = makeModel("three-mass");
  SimulationOptions o;
  o.durationS = 3.0;
  o.excitation.kind = ExcitationKind::None;
  o.referenceVelocity = 20.0;  // rad/s
  o.disturbance.torqueNoiseStd = 0.0;
  o.disturbance.loadTorqueStd = 0.0;
  o.disturbance.encoderCountsPerRev = 0;
  Effect r = Effect::withDefaults(EffectKind::TorqueRipple);
  r.values = {0.1, 6.0, 0.0};  // 0.1 sin(6 phi_m)
  const auto with = simulateClosedLoop(*m, {r}, o), without = simulateClosedLoop(*m, {}, o);
  auto tail = [](const std::vector<double>& v) {
    return std::vector<double>(v.begin() + 2000, v.end());  // after the start-up transient
  };
  const auto uw = tail(channel(with, columns::kTorqueRef));
  const auto u0 = tail(channel(without, columns::kTorqueRef));
  const double Ts = with.data.sampleTime;
  const double f = 6.0 * 20.0 / (2.0 * M_PI);  // 6 periods per revolution at 20 rad/s
  const double line = lineAmplitude(uw, Ts, f, true);
  EXPECT_GT(line, 0.03);  // the loop fights the ripple: it appears in the torque reference
  EXPECT_LT(lineAmplitude(u0, Ts, f, true), 0.01 * line);
  EXPECT_LT(lineAmplitude(uw, Ts, 0.5 * f, true), 0.01 * line);
  EXPECT_LT(lineAmplitude(uw, Ts, 1.5 * f, true), 0.01 * line);
}

TEST(ClosedLoop, InputDelayShiftsTheCrossCorrelationPeak) {
  auto m = makeModel("two-mass");
  SimulationOptions o = shortRun();
  o.excitation.kind = ExcitationKind::Prbs;
  o.excitation.prbsClockS = 0.0005;
  o.excitation.amplitude = 0.002;
  o.disturbance.encoderCountsPerRev = 0;
  o.disturbance.loadTorqueStd = 0.0;
  Effect d = Effect::withDefaults(EffectKind::InputDelay);
  d.values[0] = 0.004;  // 8 samples at 2 kHz
  auto lag = [&](const std::vector<Effect>& e) {
    const auto r = simulateClosedLoop(*m, e, o);
    const auto& u = channel(r, columns::kTorqueRef);
    const auto& v = channel(r, columns::kMotorVelocity);
    int best = 0;
    double bestValue = -1.0;
    for (int l = 0; l <= 30; ++l) {
      double s = 0.0;
      for (std::size_t k = static_cast<std::size_t>(l) + 1; k < v.size(); ++k)
        s += u[k - static_cast<std::size_t>(l) - 1] * (v[k] - v[k - 1]);
      if (s > bestValue) {
        bestValue = s;
        best = l;
      }
    }
    return best;
  };
  EXPECT_EQ(lag({d}) - lag({}), 8);
}

TEST(ClosedLoop, BacklashFlattensTheGearTorqueAroundZeroDeflection) {
  auto m = makeModel("three-mass");
  SimulationOptions o = shortRun();
  o.logGear = true;
  const Effect b = Effect::withDefaults(EffectKind::Backlash);
  const auto r = simulateClosedLoop(*m, {b}, o);
  const auto& defl = channel(r, "gear_deflection_rad");
  const auto& torque = channel(r, "gear_torque_nm");
  int inside = 0;
  double outsideMax = 0.0;
  for (std::size_t k = 0; k < defl.size(); ++k) {
    if (std::abs(defl[k]) < b.value(0)) {
      ++inside;
      EXPECT_EQ(torque[k], 0.0);
    } else {
      outsideMax = std::max(outsideMax, std::abs(torque[k]));
    }
  }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outsideMax, 10.0);
  // Without backlash the same stretch carries torque.
  const auto lin = simulateClosedLoop(*m, {}, o);
  int carrying = 0;
  for (std::size_t k = 0; k < defl.size(); ++k)
    carrying += std::abs(channel(lin, "gear_deflection_rad")[k]) < b.value(0) &&
                std::abs(channel(lin, "gear_torque_nm")[k]) > 1.0;
  EXPECT_GT(carrying, 100);
}

TEST(ClosedLoop, UnstableLoopIsReportedNotThrown) {
  auto m = makeModel("two-mass");
  SimulationOptions o = shortRun();
  o.controller.kv = 50.0;  // far beyond what 2 kHz sampling allows with J_m = 9e-4
  const auto r = simulateClosedLoop(*m, {}, o);
  EXPECT_EQ(r.termination, Termination::Diverged);
  EXPECT_NE(r.message.find("unstable"), std::string::npos);
  o = shortRun();
  o.logRateHz = 300.0;  // does not divide 2000
  EXPECT_THROW(simulateClosedLoop(*m, {}, o), std::invalid_argument);
}

TEST(ClosedLoop, LogRateDecimatesTheControllerSamples) {
  auto m = makeModel("three-mass");
  SimulationOptions o = shortRun();
  const auto full = simulateClosedLoop(*m, {}, o);
  o.logRateHz = 200.0;
  const auto slow = simulateClosedLoop(*m, {}, o);
  ASSERT_EQ(slow.data.samples(), 400u);
  EXPECT_DOUBLE_EQ(slow.data.sampleTime, 0.005);
  for (std::size_t i = 0; i < slow.data.samples(); ++i)
    EXPECT_EQ(channel(slow, columns::kTorqueRef)[i], channel(full, columns::kTorqueRef)[10 * i]);
}

TEST(ClosedLoop, ParameterStepChangesThePlantFromItsTimeOn) {
  auto m = makeModel("three-mass");
  SimulationOptions o = shortRun();
  const auto healthy = simulateClosedLoop(*m, {}, o);
  o.parameterSteps = {{"k_T", 1.2, 1.0}};
  const auto faulty = simulateClosedLoop(*m, {}, o);
  ASSERT_EQ(faulty.termination, Termination::Converged);
  const auto& a = channel(healthy, columns::kMotorVelocity);
  const auto& b = channel(faulty, columns::kMotorVelocity);
  const std::size_t step = healthy.data.rangeForTimes(1.0, 1.0).begin;
  // Before the step the runs are the same sample for sample; the first sample after it still
  // is (the state is continuous), then the stronger torque shows.
  for (std::size_t k = 0; k <= step; ++k) ASSERT_EQ(a[k], b[k]) << k;
  double after = 0.0;
  for (std::size_t k = step + 1; k < a.size(); ++k) after = std::max(after, std::abs(a[k] - b[k]));
  EXPECT_GT(after, 1e-3);
  EXPECT_EQ(faulty.data.meta("parameter_steps"), "k_T=1.2@1");
  EXPECT_TRUE(healthy.data.meta("parameter_steps").empty());
}

TEST(ClosedLoop, ParameterStepAtTheStartIsTheChangedModel) {
  auto m = makeModel("three-mass");
  SimulationOptions o = shortRun();
  o.parameterSteps = {{"f_m", 0.0426, 0.0}};
  const auto stepped = simulateClosedLoop(*m, {}, o);
  m->setParameter("f_m", 0.0426);
  o.parameterSteps.clear();
  const auto changed = simulateClosedLoop(*m, {}, o);
  EXPECT_EQ(channel(stepped, columns::kMotorAngle), channel(changed, columns::kMotorAngle));
}

TEST(ClosedLoop, ParameterStepMisuseThrowsAndTextRoundTrips) {
  auto m = makeModel("three-mass");
  SimulationOptions o = shortRun();
  o.parameterSteps = {{"no_such", 1.0, 0.5}};
  EXPECT_THROW(simulateClosedLoop(*m, {}, o), std::invalid_argument);
  o.parameterSteps = {{"J_a", -1.0, 0.5}};  // below J_a's bound
  EXPECT_THROW(simulateClosedLoop(*m, {}, o), std::invalid_argument);
  o.parameterSteps = {{"J_a", 1.0, -0.5}};
  EXPECT_THROW(simulateClosedLoop(*m, {}, o), std::invalid_argument);
  std::string why;
  const auto s = parseParameterStep("J_a=1.4333333333333333@20", &why);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->name, "J_a");
  EXPECT_DOUBLE_EQ(s->value, 1.4333333333333333);
  EXPECT_DOUBLE_EQ(s->timeS, 20.0);
  EXPECT_EQ(toString(*s), "J_a=1.43333333333@20");
  for (const char* bad : {"k_T=1.2", "k_T@20", "=1@2", "k_T=x@2", "k_T=1@-1", "k_T=1@2s"}) {
    EXPECT_FALSE(parseParameterStep(bad, &why)) << bad;
    EXPECT_NE(why.find("NAME=VALUE@SECONDS"), std::string::npos);
  }
}

}  // namespace
}  // namespace flexarm
