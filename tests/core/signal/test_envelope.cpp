// The min/max envelope used to draw long logs keeps every extreme of the visible range and
// stays within its point budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/signal/envelope.h"

using namespace flexarm;

TEST(Envelope, KeepsExtremesWithinBudget) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise;
  std::vector<double> x(1'000'003);
  for (auto& v : x) v = noise(rng);
  x[123457] = 50.0;   // a spike that must survive
  x[777777] = -60.0;
  EnvelopePyramid env(x);
  std::vector<double> pos, val;
  for (auto [b, e] : {std::pair<std::size_t, std::size_t>{0, x.size()}, {100000, 900000},
                      {123400, 123500}, {5, 2005}}) {
    SCOPED_TRACE(b);
    env.visiblePoints(b, e, 2000, pos, val);
    ASSERT_FALSE(pos.empty());
    EXPECT_LE(pos.size(), 2000u + 8u);
    for (std::size_t i = 0; i < pos.size(); ++i) {
      const auto k = static_cast<std::size_t>(pos[i]);
      EXPECT_EQ(val[i], x[k]) << "points are real samples";
      if (i) {
        EXPECT_LE(pos[i - 1], pos[i]) << "in time order";
      }
    }
    const auto [lo, hi] = std::minmax_element(x.begin() + b, x.begin() + e);
    EXPECT_LE(*std::min_element(val.begin(), val.end()), *lo);
    EXPECT_GE(*std::max_element(val.begin(), val.end()), *hi);
  }
  env.visiblePoints(123400, 123500, 2000, pos, val);
  EXPECT_EQ(pos.size(), 100u) << "a short range is drawn sample by sample";
}
