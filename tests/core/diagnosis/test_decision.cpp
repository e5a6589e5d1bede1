// The decision structure of the seed's Sections 7.4.2 and 7.5.2, the verdict that follows S
// over time, and the windowed sums of the hypothesis tests (7.18)-(7.21).
#include <gtest/gtest.h>

#include "core/diagnosis/decision.h"
#include "core/diagnosis/hypothesis_statistics.h"

namespace flexarm {
namespace {

const std::vector<std::string> kFaults = {"k_T", "J_a", "f_m"};

// Section 7.5.2, "after five seconds": the patterns of (T_NF, T_kT, T_Ja^-1, T_fm) and the
// diagnosis statements S the seed prints for them.
TEST(DecisionStructure, ReproducesTheSeedsTableAfterFiveSeconds) {
  const auto d = DecisionStructure::hypothesis(kFaults);
  ASSERT_EQ(d.columns().size(), 4u);
  EXPECT_EQ(modeSetString(d.diagnose({true, false, true, true}), kFaults), "{F_k_T}");
  EXPECT_EQ(modeSetString(d.diagnose({true, true, false, true}), kFaults), "{F_J_a}");
  EXPECT_EQ(modeSetString(d.diagnose({true, true, true, false}), kFaults), "{F_f_m}");
  EXPECT_EQ(modeSetString(d.diagnose({false, true, true, false}), kFaults), "{NF, F_f_m}");
  EXPECT_EQ(isolatedFault(d.diagnose({true, false, true, true})), std::optional<std::size_t>(0));
  EXPECT_EQ(isolatedFault(d.diagnose({false, true, true, false})), std::nullopt);
  // No test fired: every mode is possible.
  EXPECT_EQ(d.diagnose({false, false, false, false}), d.allModes());
  EXPECT_EQ(patternString({true, false, true, true}), "1011");
}

// The table's marks: T_NF has its 0 in the NF row only, T_i in the F_i row only (the NF row
// "got additional X:s" in Section 7.5.2).
TEST(DecisionStructure, MarksAreTheSeeds) {
  const auto d = DecisionStructure::hypothesis(kFaults);
  const char* rows[] = {"0XXX", "X0XX", "XX0X", "XXX0"};  // NF, F_kT, F_Ja, F_fm
  for (std::size_t mode = 0; mode < 4; ++mode) {
    std::string row;
    for (std::size_t c = 0; c < 4; ++c) row += d.mark(mode, c);
    EXPECT_EQ(row, rows[mode]) << d.modeName(mode);
  }
}

// Parameter tests: an alarm on one parameter isolates it; on two, no single fault is left.
TEST(DecisionStructure, ParameterAlarmsIsolateOneFault) {
  const auto d = DecisionStructure::parameters(kFaults);
  EXPECT_EQ(isolatedFault(d.diagnose({false, true, false})), std::optional<std::size_t>(1));
  EXPECT_EQ(d.diagnose({true, false, true}), 0u);
  EXPECT_TRUE(d.diagnose({false, false, false}) & 1u);  // NF kept
}

TEST(VerdictTracker, ConfirmsAndLatches) {
  const auto d = DecisionStructure::hypothesis(kFaults);
  const ModeSet none = d.allModes(), kT = d.diagnose({true, false, true, true});
  VerdictTracker t(0.5);
  t.update(0.0, none);
  t.update(1.0, kT);
  EXPECT_FALSE(t.verdict());  // not held long enough yet
  t.update(1.2, none);        // the isolation broke off: start again
  t.update(2.0, kT);
  t.update(2.4, kT);
  EXPECT_FALSE(t.verdict());
  t.update(2.5, kT);
  ASSERT_TRUE(t.verdict());
  EXPECT_EQ(*t.verdict(), 0u);
  EXPECT_DOUBLE_EQ(*t.verdictTime(), 2.5);
  EXPECT_DOUBLE_EQ(*t.detectionTime(), 2.5);
  t.update(3.0, none);  // latched
  EXPECT_TRUE(t.verdict());
}

TEST(HypothesisStatistics, CumulativeAndSlidingRatios) {
  // Cumulative (7.20): sums of squares from the first sample.
  HypothesisStatistics cumulative(2, 0);
  cumulative.update({1.0, 2.0}, 1.0);
  const auto& t = cumulative.update({1.0, 0.0}, 2.0);
  EXPECT_DOUBLE_EQ(t[0], 2.0 / 5.0);
  EXPECT_DOUBLE_EQ(t[1], 4.0 / 5.0);
  // Sliding over two samples: the first sample has left the window.
  HypothesisStatistics sliding(1, 2);
  sliding.update({10.0}, 1.0);
  sliding.update({1.0}, 1.0);
  const auto& s = sliding.update({1.0}, 1.0);
  EXPECT_DOUBLE_EQ(s[0], 1.0);
  WindowedSum w(3);
  for (int i = 1; i <= 1000; ++i) w.add(0.1 * i);
  EXPECT_NEAR(w.sum(), 100.0 * 100.0 + 99.9 * 99.9 + 99.8 * 99.8, 1e-9);
  EXPECT_EQ(w.count(), 3u);
}

}  // namespace
}  // namespace flexarm
