// Finding the missing effect on closed-loop logs in which one effect is hidden (or none):
// the generator simulates the seed's Figure 5.1 loop with a known model and effect, varying
// seed, magnitude, controller tuning and excitation; discovery is told only the structure of
// the base model (two-mass, the chapter-3 model (3.13)) and must name the effect.
#include <gtest/gtest.h>

#include "tests/test_scale.h"

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
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"
#include "tests/core/discovery/discovery_logs.h"

namespace flexarm {
namespace {

struct Case {
  std::optional<EffectKind> hidden;
  int seed = 1;
  double magnitude = 1.0;  // times the effect's default size
};

// Truth: a two-mass arm (discovery_logs.h), plus the hidden effect; extra_mass makes the
// truth a three-mass arm.
using test::truthModel;

Effect hiddenEffect(EffectKind k, double magnitude) {
  Effect e = Effect::withDefaults(k);
  if (k == EffectKind::ExtraMass) e.values[0] = 100.0 * magnitude;  // the resonance moves
  else e.values[0] *= magnitude;  // the ripple keeps its number of periods
  return e;
}

// One closed-loop log; the ripple needs the motor to turn, so those logs (and half the logs
// without effect) run at a constant motor speed as the sample log effect_torque_ripple does.
IdData makeLog(const PhysicalModel& truth, const std::vector<Effect>& effects, int seed, bool validation,
               bool turning) {
  test::LogShape shape;
  shape.turning = turning;
  return test::closedLoopLog(truth, effects, seed, validation, shape);
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

// The log as a drive that records the motor velocity instead of the angle (issue 14): the
// angle channel replaced by its derivative, which becomes the output.
IdData velocityOnly(IdData d) {
  const Channel* angle = d.channel(columns::kMotorAngle);
  if (!angle) throw std::runtime_error("no motor angle to replace");
  Channel v{columns::kMotorVelocity, "", ChannelRole::Output, differentiate(angle->values, d.sampleTime)};
  d.channels.erase(std::remove_if(d.channels.begin(), d.channels.end(),
                                  [](const Channel& c) { return c.name == columns::kMotorAngle; }),
                   d.channels.end());
  d.setChannel(v);
  d.setRole(columns::kMotorVelocity, ChannelRole::Output);
  return d;
}

// Discovery accepts a log whose output is the motor velocity and names the hidden effect on
// it as on the log with the angle.
TEST(Discovery, AcceptsAVelocityOutput) {
  const Case c{EffectKind::CoulombFriction, 11 + 7 * 2 + static_cast<int>(EffectKind::CoulombFriction), 3.0};
  auto truth = truthModel(c.seed);
  const std::vector<Effect> effects{hiddenEffect(*c.hidden, c.magnitude)};
  const IdData est = makeLog(*truth, effects, c.seed, false, false);
  const IdData val = makeLog(*truth, effects, c.seed, true, false);
  const IdData estV = velocityOnly(est), valV = velocityOnly(val);
  ASSERT_EQ(estV.channel(columns::kMotorAngle), nullptr);
  ASSERT_EQ(estV.output()->unit, "rad/s");
  DiscoveryOptions o;
  o.threads = 1;
  auto base = makeModel("two-mass");
  const DiscoveryResult fromVelocity = discoverMissingEffect(*base, estV, &valV, o);
  ASSERT_EQ(fromVelocity.termination, Termination::Converged) << fromVelocity.message;
  ASSERT_TRUE(fromVelocity.effect.has_value()) << fromVelocity.evidence;
  EXPECT_EQ(*fromVelocity.effect, EffectKind::CoulombFriction) << fromVelocity.evidence;
  EXPECT_LE(fromVelocity.augmented.rmsValidation, 0.7 * fromVelocity.base.rmsValidation);
  // Without either channel the sentence names both.
  IdData none = estV;
  none.channels.erase(std::remove_if(none.channels.begin(), none.channels.end(),
                                     [](const Channel& ch) { return ch.name == columns::kMotorVelocity; }),
                      none.channels.end());
  const auto r = discoverMissingEffect(*base, none, nullptr, o);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("motor velocity"), std::string::npos) << r.message;
}

// The headline test: every effect hidden in several logs (three seeds and sizes each, the
// excitation, its swing and the controller tuning varying with the seed), and logs without
// an effect, on which naming anything is the worst outcome. The right name in at least 90 %
// of the cases, "none" on every log without an effect, and where the name is right the
// validation residual RMS at least 25 % lower (a 3x spring on a PRBS validation log falls 28 %).
TEST(Discovery, NamesTheHiddenEffect) {
  std::vector<Case> cases;
  // Three magnitudes of every effect and four logs without one; under the sanitizers the
  // strongest magnitude and one clean log (tests/test_scale.h).
  const bool reduced = flexarm::test::reducedSizes();
  const double magnitudes[] = {1.5, 2.0, 3.0};
  for (EffectKind k : seedEffectKinds())
    for (int s = reduced ? 2 : 0; s < 3; ++s) {
      double mag = magnitudes[s];
      if (k == EffectKind::ExtraMass) mag = 0.7 + 0.3 * s;  // 70, 100, 130 rad/s
      cases.push_back({k, 11 + 7 * s + static_cast<int>(k), mag});
    }
  for (int s = 0; s < (reduced ? 1 : 4); ++s) cases.push_back({std::nullopt, 5 + 3 * s, 0.0});

  const auto outcomes = runAll(cases);
  std::map<std::string, std::map<std::string, int>> confusion;
  int right = 0, withEffect = 0;
  double seconds = 0.0;
  for (const auto& o : outcomes) {
    const std::string truth = o.c.hidden ? toString(*o.c.hidden) : "none";
    ASSERT_TRUE(o.error.empty()) << truth << " seed " << o.c.seed << ": " << o.error;
    const std::string said = verdictName(o.result);
    confusion[truth][said]++;
    seconds = std::max(seconds, o.result.seconds);
    std::printf("%-17s seed %2d x%.1f -> %-17s val RMS %.4f -> %.4f  %s\n", truth.c_str(),
                o.c.seed, o.c.magnitude, said.c_str(), o.result.base.rmsValidation,
                o.result.augmented.rmsValidation, o.result.evidence.c_str());
    ASSERT_EQ(o.result.termination, Termination::Converged) << o.result.message;
    for (const auto& c : o.result.candidates)
      std::printf("    %-17s loss %.5f val %.4f aic %.1f F %.1f/%.1f %s %s\n", toString(c.kind),
                  c.lossEst, c.score.rmsValidation, c.aic - o.result.baseAic, c.fStatistic,
                  c.fThreshold, toString(c.effect).c_str(), c.reason.c_str());
    if (!o.c.hidden) {
      EXPECT_FALSE(o.result.effect.has_value())
          << "named " << said << " where there is no effect (seed " << o.c.seed << ")";
      continue;
    }
    ++withEffect;
    // A gap's or a delay's interval comes from a loss that is not smooth in it (issue 13:
    // 46 standard deviations off): the evidence says so; a smooth effect's does not.
    const bool rough = said == toString(EffectKind::Backlash) || said == toString(EffectKind::InputDelay);
    EXPECT_EQ(o.result.evidence.find("promises too much") != std::string::npos, rough)
        << said << ": " << o.result.evidence;
    if (said == truth) {
      ++right;
      EXPECT_LE(o.result.augmented.rmsValidation, 0.75 * o.result.base.rmsValidation)
          << truth << " seed " << o.c.seed;
    }
  }
  std::printf("\nConfusion matrix (rows: hidden effect, columns: verdict)\n%-17s", "");
  std::vector<std::string> names = {"none"};
  for (EffectKind k : seedEffectKinds()) names.push_back(toString(k));
  for (const auto& n : names) std::printf(" %6.6s", n.c_str());
  std::printf("\n");
  for (const auto& row : names) {
    std::printf("%-17s", row.c_str());
    for (const auto& col : names) std::printf(" %6d", confusion[row][col]);
    std::printf("\n");
  }
  std::printf("right %d of %d; slowest run %.1f s\n", right, withEffect, seconds);
  EXPECT_GE(right, reduced ? withEffect - 1 : static_cast<int>(std::ceil(0.9 * withEffect)));
}

}  // namespace
}  // namespace flexarm
