// End to end on a real log nobody here simulated: the DaISy flexible robot arm (96-009),
// headerless, column 1 u, column 2 y, T = 1. ETFE, SPA, ARX, OE, BJ and residual tests.
#include <gtest/gtest.h>

#include "core/ident/blackbox.h"
#include "core/ident/evaluation.h"
#include "core/ident/nonparametric.h"
#include "core/ident/residuals.h"
#include "core/io/log_io.h"
#include "tests/core/ident/daisy_data.h"

namespace flexarm {
namespace {

TEST(Daisy, RobotArmGetsNonparametricBlackBoxAndResidualAnalysis) {
  Eigen::VectorXd u, y;
  ASSERT_TRUE(testing::daisyRobotArm(u, y));
  ASSERT_EQ(u.size(), 1024);
  const Eigen::Index ne = 700;  // estimation 0..699, validation 700..1023
  const Eigen::VectorXd ue = u.head(ne), ye = y.head(ne);

  SpaOptions so;
  so.windowWidth = 60;
  const auto s = spa(ue, ye, 1.0, so);
  ASSERT_EQ(s.termination, Termination::Converged);
  EXPECT_FALSE(s.closedLoopBias);
  const auto e = etfe(ue, ye, 1.0, EtfeOptions{8, s.response.omega});
  ASSERT_EQ(e.termination, Termination::Converged);
  const auto npS = notchesAndPeaks(s.response, 3.0);
  EXPECT_GE(npS.peaks.size(), 1u);  // a flexible arm shows at least one resonance

  auto check = [&](const PolyEstimate& r, double minFitVal, const char* name) {
    ASSERT_TRUE(r.summary.ok()) << name << ": " << r.summary.message;
    const Eigen::VectorXd sim = simulate(r.model, u);
    const double fitEst = fitPercent(y, sim, 0, ne);
    const double fitVal = fitPercent(y, sim, ne, y.size());
    ::testing::Test::RecordProperty(std::string(name) + "_fit_est_x10", static_cast<int>(fitEst * 10));
    ::testing::Test::RecordProperty(std::string(name) + "_fit_val_x10", static_cast<int>(fitVal * 10));
    EXPECT_GT(fitVal, minFitVal) << name;
    EXPECT_LE(fitVal, 100.0) << name;
    const auto fr = frequencyResponse(r.model, s.response.omega);
    EXPECT_TRUE(fr.hasBands()) << name;
    // The parametric response agrees with SPA near SPA's main peak within a factor of two.
    std::size_t k = 0;
    for (std::size_t i = 1; i < s.response.magnitude.size(); ++i)
      if (s.response.magnitude[i] > s.response.magnitude[k]) k = i;
    EXPECT_NEAR(std::log(fr.magnitude[k] / s.response.magnitude[k]), 0.0, std::log(2.0)) << name;
  };
  const auto a = arx(ue, ye, 6, 6, 1);
  check(a, 90.0, "arx661");
  const auto o = oe(ue, ye, 6, 6, 1);
  check(o, 90.0, "oe661");
  const auto b = bj(ue, ye, 6, 2, 2, 6, 1);
  check(b, 90.0, "bj62261");

  const auto ra = residualAnalysis(predictionErrors(a.model, ue, ye), ue);
  const auto rb = residualAnalysis(predictionErrors(b.model, ue, ye), ue);
  EXPECT_FALSE(ra.verdict.empty());
  // The Box-Jenkins noise model whitens the residuals more than ARX's 1/A.
  EXPECT_LT(rb.whitenessStatistic, ra.whitenessStatistic);
  ::testing::Test::RecordProperty("arx_whiteness_x10", static_cast<int>(ra.whitenessStatistic * 10));
  ::testing::Test::RecordProperty("bj_whiteness_x10", static_cast<int>(rb.whitenessStatistic * 10));
}

}  // namespace
}  // namespace flexarm
