// Finding the missing effect on closed-loop logs in which one effect is hidden (or none):
// the generator simulates the seed's Figure 5.1 loop with a known model and effect, varying
// seed, magnitude, controller tuning and excitation; discovery is told only the structure of
// the base model (two-mass, the chapter-3 model (3.13)) and must name the effect.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <thread>

#include "core/discovery/discovery.h"
#include "core/io/log_io.h"
#include "core/models/nonlinear_plant.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

struct Case {
  std::optional<EffectKind> hidden;
  int seed = 1;
  double magnitude = 1.0;  // times the effect's default size
};

// Truth: a two-mass arm whose parameters differ from the nominal ones by up to 20 % (seeded),
// plus the hidden effect; extra_mass makes the truth a three-mass arm.
std::unique_ptr<PhysicalModel> truthModel(int seed) {
  auto m = makeModel("two-mass");
  const double f[] = {1.0, 1.12, 0.9, 1.18, 0.85, 1.05, 0.95, 1.1};
  auto pick = [&f](int i) { return f[static_cast<std::size_t>(i) % 8]; };
  m->setParameter("J_m", m->value("J_m") * pick(seed));
  m->setParameter("J_a", m->value("J_a") * pick(seed + 3));
  m->setParameter("k_a", m->value("k_a") * pick(seed + 5));
  m->setParameter("f_m", m->value("f_m") * pick(seed + 1));
  return m;
}

Effect hiddenEffect(EffectKind k, double magnitude) {
  Effect e = Effect::withDefaults(k);
  switch (k) {
    case EffectKind::TorqueRipple:  // keep the number of periods, scale the amplitude
    case EffectKind::CoulombFriction:
      e.values[0] *= magnitude;
      break;
    case EffectKind::ExtraMass:  // the resonance moves with the magnitude
      e.values[0] = 100.0 * magnitude;
      break;
    default:
      e.values[0] *= magnitude;
  }
  return e;
}

// One closed-loop log: excitation and controller tuning vary with the seed; the ripple
// needs the motor to turn, so those logs (and half the logs without effect) run at a
// constant motor speed as the sample log effect_torque_ripple does.
IdData makeLog(const PhysicalModel& truth, const std::vector<Effect>& effects, int seed,
               bool validation, bool turning) {
  SimulationOptions o;
  o.durationS = 8.0;
  o.logRateHz = 2000.0;  // the controller rate; discovery fits at 1 kHz (block means of u)
  o.seed = static_cast<std::uint64_t>(seed * 2 + (validation ? 1 : 0));
  const ExcitationKind kinds[] = {ExcitationKind::Chirp, ExcitationKind::Multisine,
                                  ExcitationKind::Prbs};
  o.excitation.kind = kinds[(seed + (validation ? 1 : 0)) % 3];
  o.excitation.amplitude = o.excitation.kind == ExcitationKind::Prbs ? 0.02 : 0.05;
  o.excitation.multisinePeriodS = 4.0;
  o.excitation.multisineLastLine = 120;
  const double kp[] = {40.0, 30.0, 50.0}, kv[] = {0.3, 0.4, 0.25};
  o.controller.kp = kp[seed % 3];
  o.controller.kv = kv[(seed / 3) % 3];
  o.referenceVelocity = turning ? 5.0 : 0.0;
  const auto r = simulateClosedLoop(truth, effects, o);
  if (r.termination != Termination::Converged) throw std::runtime_error(r.message);
  return r.data;
}

struct Outcome {
  Case c;
  DiscoveryResult result;
  std::string error;  // the generator failed (an unstable loop)
};

Outcome runCase(const Case& c) {
  auto truth = truthModel(c.seed);
  std::vector<Effect> effects;
  if (c.hidden) effects.push_back(hiddenEffect(*c.hidden, c.magnitude));
  const bool turning = c.hidden ? *c.hidden == EffectKind::TorqueRipple : c.seed % 2 == 1;
  const IdData est = makeLog(*truth, effects, c.seed, false, turning);
  const IdData val = makeLog(*truth, effects, c.seed, true, turning);
  DiscoveryOptions o;
  o.threads = 1;  // the cases run in parallel
  auto base = makeModel("two-mass");
  return {c, discoverMissingEffect(*base, est, &val, o), {}};
}

std::vector<Outcome> runAll(const std::vector<Case>& cases) {
  std::vector<Outcome> out(cases.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&]() {
    for (std::size_t i = next++; i < cases.size(); i = next++) {
      try {
        out[i] = runCase(cases[i]);
      } catch (const std::exception& e) {
        out[i].c = cases[i];
        out[i].error = e.what();
      }
    }
  };
  std::thread t(worker);
  worker();
  t.join();
  return out;
}

std::string verdictName(const DiscoveryResult& r) {
  return r.effect ? toString(*r.effect) : "none";
}

TEST(Discovery, FQuantileMatchesTables) {
  // F(0.99; 1, 100) = 6.90, F(0.99; 2, 1000) = 4.63, F(0.95; 5, 20) = 2.71 (printed tables).
  EXPECT_NEAR(fQuantile(0.99, 1, 100), 6.90, 0.35);
  EXPECT_NEAR(fQuantile(0.99, 2, 1000), 4.63, 0.1);
  EXPECT_NEAR(fQuantile(0.95, 5, 20), 2.71, 0.05);
}

TEST(Discovery, RejectsMisuseAndReportsBadData) {
  auto base = makeModel("two-mass");
  DiscoveryOptions bad;
  bad.candidates.clear();
  IdData empty;
  EXPECT_THROW(discoverMissingEffect(*base, empty, nullptr, bad), std::invalid_argument);
  EXPECT_THROW(discoverMissingEffect(*makeModel("rigid"), empty, nullptr), std::invalid_argument);
  const auto r = discoverMissingEffect(*base, empty, nullptr);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("motor angle"), std::string::npos) << r.message;
}

// Naming an effect that is not there is the worst outcome: on logs whose truth has no
// effect (several seeds, both excitations, turning and not) the verdict is "none".
TEST(Discovery, AnswersNoneWhenNothingIsHidden) {
  std::vector<Case> cases;
  for (int s = 0; s < 4; ++s) cases.push_back({std::nullopt, 5 + 3 * s, 0.0});
  for (const auto& o : runAll(cases)) {
    ASSERT_TRUE(o.error.empty()) << "seed " << o.c.seed << ": " << o.error;
    ASSERT_EQ(o.result.termination, Termination::Converged) << o.result.message;
    EXPECT_FALSE(o.result.effect.has_value())
        << "named " << verdictName(o.result) << " where there is no effect (seed " << o.c.seed << ")";
    EXPECT_FALSE(o.result.candidates.empty());
  }
}

}  // namespace
}  // namespace flexarm
