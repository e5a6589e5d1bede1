// A model simulated against a log (core/sim/log_simulation.h), the one call behind the Model
// panel's "Simulate against log" and the session report's model sections.
#include <gtest/gtest.h>

#include <cmath>

#include "core/sim/closed_loop.h"
#include "core/sim/log_simulation.h"

namespace flexarm {
namespace {

IdData closedLoopLog(const PhysicalModel& truth) {
  SimulationOptions o;
  o.durationS = 3.0;
  o.seed = 3;
  return simulateClosedLoop(truth, {}, o).data;
}

TEST(LogSimulation, TheTruthFitsTheLogItMadeAndAWrongModelDoesNot) {
  const auto truth = makeModel("two-mass");
  const IdData log = closedLoopLog(*truth);
  const LogSimulationResult r = simulateAgainstLog(*truth, {}, log);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.time.size(), log.samples());
  EXPECT_DOUBLE_EQ(r.time[10], log.timeAt(10));
  EXPECT_EQ(r.measured.size(), r.simulated.size());
  EXPECT_GT(r.fitPercent, 80.0);

  auto wrong = makeModel("two-mass");
  wrong->setParameter("k_a", 0.5 * truth->value("k_a"));
  const LogSimulationResult w = simulateAgainstLog(*wrong, {}, log);
  ASSERT_TRUE(w.ok()) << w.message;
  EXPECT_LT(w.fitPercent, r.fitPercent - 10.0);

  // Fit % over a range is (5.2) over those samples; a range beyond the log has none.
  const SampleRange second{log.samples() / 2, log.samples()};
  ASSERT_TRUE(r.fitPercentOver(second).has_value());
  EXPECT_NE(*r.fitPercentOver(second), r.fitPercent);
  EXPECT_DOUBLE_EQ(*r.fitPercentOver({0, log.samples()}), r.fitPercent);
  EXPECT_FALSE(r.fitPercentOver({0, log.samples() + 1}).has_value());
}

TEST(LogSimulation, ALogWithoutTheMotorSaysSoAndMisuseThrows) {
  const auto model = makeModel("two-mass");
  IdData log;
  log.sampleTime = 1e-3;
  log.setChannel(Channel{"u", "", ChannelRole::Input, std::vector<double>(100, 0.0)});
  log.setChannel(Channel{"y", "", ChannelRole::Output, std::vector<double>(100, 0.0)});
  const LogSimulationResult r = simulateAgainstLog(*model, {}, log);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("motor angle or velocity"), std::string::npos) << r.message;
  EXPECT_FALSE(r.fitPercentOver({0, 10}).has_value());
  LogSimulationOptions bad;
  bad.substeps = -1;
  EXPECT_THROW(simulateAgainstLog(*model, {}, closedLoopLog(*model), bad), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
