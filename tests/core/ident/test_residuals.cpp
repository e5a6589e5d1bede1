// Residual analysis (SITB's resid): the whiteness test rejects a model with the wrong noise
// description, the independence test rejects a model missing dynamics, the right model passes.
#include <gtest/gtest.h>

#include "core/ident/blackbox.h"
#include "core/ident/residuals.h"
#include "sim_helpers.h"

namespace flexarm {
namespace {

const Poly kA{1.0, -1.5, 0.7};
const Poly kB{0.0, 1.0, 0.5};
const Poly kC{1.0, 0.8};
const Poly kOne{1.0};

TEST(Residuals, ChiSquareQuantileMatchesTables) {
  EXPECT_NEAR(chiSquareQuantile(0.99, 25), 44.314, 0.1);
  EXPECT_NEAR(chiSquareQuantile(0.95, 10), 18.307, 0.1);
}

TEST(Residuals, RightModelPassesWrongModelsFail) {
  int rightPasses = 0, oeFails = 0, lowOrderFails = 0;
  const int runs = 8;
  for (unsigned seed = 1; seed <= runs; ++seed) {
    auto s = testing::simulateSystem(kA, kB, kC, kOne, kOne, 2000, 0.5, 40 + seed);
    auto right = armax(s.u, s.y, 2, 2, 1, 1);
    auto rr = residualAnalysis(predictionErrors(right.model, s.u, s.y), s.u);
    rightPasses += rr.white && rr.independent;
    // OE has no noise model: the coloured disturbance shows in the autocorrelation.
    auto wrongNoise = oe(s.u, s.y, 2, 2, 1);
    auto rw = residualAnalysis(predictionErrors(wrongNoise.model, s.u, s.y), s.u);
    oeFails += !rw.white;
    // First-order ARX misses dynamics: residuals correlate with past inputs.
    auto low = arx(s.u, s.y, 1, 1, 1);
    auto rl = residualAnalysis(predictionErrors(low.model, s.u, s.y), s.u);
    lowOrderFails += !rl.independent;
    EXPECT_EQ(rr.lags.size(), 26u);
    EXPECT_EQ(rr.crossLags.size(), 51u);
    EXPECT_NEAR(rr.autocorrelation[0], 1.0, 1e-12);
    EXPECT_NEAR(rr.autocorrelationBound, 2.5758 / std::sqrt(2000.0), 1e-3);
  }
  EXPECT_GE(rightPasses, runs - 1);
  EXPECT_EQ(oeFails, runs);
  EXPECT_EQ(lowOrderFails, runs);
}

}  // namespace
}  // namespace flexarm
