// The 95 % upper bound printed beside every false-alarm rate of the calibration: the exact
// Poisson bound, i.e. half the chi-square 0.95 quantile with 2(n+1) degrees of freedom. The
// large count is the regime of a threshold far too low (thousands of alarms in a few
// simulated hours), where exp(-mu) underflows and a bound computed from it falls below the
// rate itself.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "core/diagnosis/calibration.h"

namespace flexarm {
namespace {

TEST(PoissonUpper95, ExactBounds) {
  EXPECT_NEAR(poissonUpper95(0), -std::log(0.05), 1e-6);  // 2.996
  EXPECT_NEAR(poissonUpper95(1), 4.7439, 1e-3);
  EXPECT_NEAR(poissonUpper95(10), 16.962, 1e-3);
}

TEST(PoissonUpper95, LargeCountsStayAboveTheCount) {
  // Wilson-Hilferty: 2075.14 for n = 2000.
  EXPECT_NEAR(poissonUpper95(2000), 2075.14, 0.05);
  for (int n : {500, 800, 3000}) EXPECT_GT(poissonUpper95(n), n + 1.5 * std::sqrt(n)) << n;
  EXPECT_THROW(poissonUpper95(-1), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
