// Frequency-domain checks: ETFE (4.24)-(4.25) and SPA (4.28) on a known system, the closed-loop
// warning of (4.30), and the calibration of the parametric confidence bands.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ident/blackbox.h"
#include "core/ident/evaluation.h"
#include "core/ident/nonparametric.h"
#include "core/io/log_io.h"
#include "core/signal/preprocess.h"
#include "sim_helpers.h"

namespace flexarm {
namespace {

using testing::simulateSystem;

const Poly kF{1.0, -1.5, 0.7};
const Poly kB{0.0, 1.0, 0.5};
const Poly kOne{1.0};

PolynomialModel trueOe() {
  PolyOrders o;
  o.nb = 2; o.nf = 2; o.nk = 1;
  PolynomialModel m = PolynomialModel::zero(PolyStructure::Oe, o, 1.0);
  m.b = kB;
  m.f = kF;
  return m;
}

TEST(Etfe, RawEstimateIsExactForPeriodicSteadyStateData) {
  // Two periods of a random input; the second period is in steady state, so Y/U = G exactly
  // at the DFT frequencies of one period.
  std::mt19937 rng(3);
  const int P = 256;
  Eigen::VectorXd period = testing::whiteNoise(P, 1.0, rng);
  Eigen::VectorXd u(12 * P);
  for (int i = 0; i < 12; ++i) u.segment(i * P, P) = period;
  const Eigen::VectorXd y = filter(kB, kF, u);
  const auto r = etfe(u.tail(P), y.tail(P), 1.0);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const auto t = frequencyResponse(trueOe(), r.response.omega);
  for (std::size_t i = 0; i < t.omega.size(); ++i)
    EXPECT_LT(std::abs(r.response.value[i] - t.value[i]), 1e-6 * std::abs(t.value[i]) + 1e-9);
}

TEST(Etfe, SmoothingReducesTheErrorOnNoisyData) {
  auto s = simulateSystem(kOne, kB, kOne, kOne, kF, 8192, 0.2, 5);
  const auto grid = logGrid(0.05, 3.0, 40);
  EtfeOptions raw, smooth;
  raw.omega = smooth.omega = grid;
  smooth.smoothingWidth = 30;
  const auto t = frequencyResponse(trueOe(), grid);
  double eRaw = 0.0, eSmooth = 0.0;
  const auto rr = etfe(s.u, s.y, 1.0, raw), rs = etfe(s.u, s.y, 1.0, smooth);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    eRaw += std::norm(rr.response.value[i] - t.value[i]) / std::norm(t.value[i]);
    eSmooth += std::norm(rs.response.value[i] - t.value[i]) / std::norm(t.value[i]);
  }
  EXPECT_LT(eSmooth, 0.3 * eRaw);
  EXPECT_EQ(rr.window, 1);
  EXPECT_EQ(rs.window, 30);
  EXPECT_LT(std::sqrt(eSmooth / grid.size()), 0.1);
}

TEST(Spa, EstimatesKnownSystemAndItsBandCoversTheTruth) {
  auto s = simulateSystem(kOne, kB, kOne, kOne, kF, 20000, 0.5, 8);
  SpaOptions o;
  o.windowWidth = 200;  // narrow enough in frequency to follow the resonance near 0.45 rad
  o.omega = logGrid(0.05, 3.0, 60);
  const auto r = spa(s.u, s.y, 1.0, o);
  ASSERT_EQ(r.termination, Termination::Converged);
  ASSERT_TRUE(r.response.hasBands());
  const auto t = frequencyResponse(trueOe(), o.omega);
  int inside = 0;
  for (std::size_t i = 0; i < o.omega.size(); ++i) {
    EXPECT_LT(std::abs(r.response.magnitude[i] - t.magnitude[i]), 4.0 * r.response.magnitudeStd[i])
        << o.omega[i];
    inside += t.magnitude[i] >= r.response.magnitudeLower[i] &&
              t.magnitude[i] <= r.response.magnitudeUpper[i];
  }
  ::testing::Test::RecordProperty("inside99", inside);
  // The band ignores the lag window's bias, which may push a few points out.
  EXPECT_GE(inside, 56);
  // Hamming differs from Hann but estimates the same system.
  o.window = LagWindow::Hamming;
  const auto h = spa(s.u, s.y, 1.0, o);
  EXPECT_NE(h.response.magnitude[10], r.response.magnitude[10]);
  EXPECT_NEAR(h.response.magnitude[10] / t.magnitude[10], 1.0, 0.05);
  EXPECT_EQ(h.window, 200);
  // The default lag window, which a report prints beside the estimate: N / 10 up to 30,
  // never more than N - 1.
  EXPECT_EQ(spa(s.u, s.y, 1.0).window, 30);
  EXPECT_EQ(spa(s.u.head(120), s.y.head(120), 1.0).window, 12);
}

TEST(Spa, ClosedLoopDataCarryTheBiasWarning) {
  auto s = simulateSystem(kOne, kB, kOne, kOne, kF, 2000, 0.5, 9, 0.3);
  IdData d;
  d.sampleTime = 0.01;
  auto add = [&](const char* name, ChannelRole role, const Eigen::VectorXd& v) {
    d.setChannel({name, "", role, std::vector<double>(v.data(), v.data() + v.size())});
  };
  add("u", ChannelRole::Input, s.u);
  add("y", ChannelRole::Output, s.y);
  const auto open = spa(d);
  EXPECT_FALSE(open.closedLoopBias);
  EXPECT_TRUE(open.warning.empty());
  add("r", ChannelRole::Reference, s.r);
  const auto closed = spa(d);
  EXPECT_TRUE(closed.closedLoopBias);
  EXPECT_NE(closed.warning.find("(4.30)"), std::string::npos);
  EXPECT_TRUE(etfe(d).closedLoopBias);
  // Default grid ends at the Nyquist frequency pi / T in rad/s.
  EXPECT_NEAR(closed.response.omega.back(), M_PI / 0.01, 1e-9);
}

TEST(Spa, NoiseDominatedClosedLoopTendsToMinusInverseController) {
  // (4.30) with Phi_r << |F_y|^2 Phi_v: G_hat -> -1 / F_y; here F_y = 0.5, so G_hat -> -2.
  auto s = simulateSystem(kOne, kB, kOne, kOne, kF, 20000, 1.0, 12, 0.5, 1e-3);
  SpaOptions o;
  o.windowWidth = 200;  // resolves the open-loop resonance near 0.45 rad
  o.omega = logGrid(0.1, 3.0, 10);
  const auto r = spa(s.u, s.y, 1.0, o);
  for (const auto& g : r.response.value) EXPECT_LT(std::abs(g - std::complex<double>(-2.0, 0.0)), 0.01);
  // With a strong reference a loop gives the system, not the controller (a gain of 0.2 keeps
  // the closed loop well damped, so the lag window resolves its spectra).
  auto strong = simulateSystem(kOne, kB, kOne, kOne, kF, 20000, 0.05, 12, 0.2, 1.0);
  const auto rs = spa(strong.u, strong.y, 1.0, o);
  const auto t = frequencyResponse(trueOe(), o.omega);
  for (std::size_t i = 0; i < o.omega.size(); ++i)
    EXPECT_LT(std::abs(rs.response.value[i] - t.value[i]), 0.05 * std::abs(t.value[i]) + 0.02);
}

TEST(Bands, TrueResponseLiesInsideTheBandAtThePromisedRate) {
  // OE fits over many seeds; count how often |G_true| is inside the magnitude band and the
  // true phase inside the phase band, at 99 % and at 50 % (the latter must not be too wide).
  const auto grid = logGrid(0.05, 3.0, 12);
  const auto t = frequencyResponse(trueOe(), grid);
  int in99 = 0, in50 = 0, phase99 = 0, total = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    auto s = simulateSystem(kOne, kB, kOne, kOne, kF, 500, 1.0, 1000 + seed);
    auto r = oe(s.u, s.y, 2, 2, 1);
    ASSERT_TRUE(r.summary.ok());
    const auto f99 = frequencyResponse(r.model, grid, 0.99);
    const auto f50 = frequencyResponse(r.model, grid, 0.50);
    for (std::size_t i = 0; i < grid.size(); ++i) {
      in99 += t.magnitude[i] >= f99.magnitudeLower[i] && t.magnitude[i] <= f99.magnitudeUpper[i];
      in50 += t.magnitude[i] >= f50.magnitudeLower[i] && t.magnitude[i] <= f50.magnitudeUpper[i];
      const double dp = std::remainder(t.phase[i] - f99.phase[i], 2 * M_PI);
      phase99 += std::abs(dp) <= f99.phase[i] - f99.phaseLower[i];
      ++total;
    }
  }
  ::testing::Test::RecordProperty("inside99", in99);
  ::testing::Test::RecordProperty("inside50", in50);
  ::testing::Test::RecordProperty("phase99", phase99);
  ::testing::Test::RecordProperty("total", total);
  EXPECT_GE(in99, 0.96 * total);
  EXPECT_GE(phase99, 0.96 * total);
  EXPECT_GT(in50, 0.38 * total);
  EXPECT_LT(in50, 0.62 * total);
}

TEST(Roots, NotchesAndPeaksOfAKnownResonance) {
  // Poles at radius 0.98, angle 0.6 rad; zeros at radius 0.97, angle 0.3 rad (T = 0.01 s).
  const double T = 0.01;
  auto pair = [](double rho, double th) { return Poly{1.0, -2 * rho * std::cos(th), rho * rho}; };
  PolynomialModel m = PolynomialModel::zero(PolyStructure::Oe, {0, 3, 0, 0, 2, 1}, T);
  const Poly z = pair(0.97, 0.3);
  m.b = {0.0, z[0], z[1], z[2]};
  m.f = pair(0.98, 0.6);
  const auto fr = frequencyResponse(m, logGrid(1.0, 300.0, 2000));
  const auto np = notchesAndPeaks(fr);
  ASSERT_EQ(np.notches.size(), 1u);
  ASSERT_EQ(np.peaks.size(), 1u);
  EXPECT_NEAR(np.notches[0], 30.0, 1.0);
  EXPECT_NEAR(np.peaks[0], 60.0, 2.0);
  const auto nr = notchesAndPeaksFromRoots(zeros(m), poles(m), T);
  ASSERT_EQ(nr.notches.size(), 1u);
  ASSERT_EQ(nr.peaks.size(), 1u);
  EXPECT_NEAR(nr.notches[0], std::hypot(std::log(0.97), 0.3) / T, 1e-6);
  EXPECT_NEAR(nr.peaks[0], std::hypot(std::log(0.98), 0.6) / T, 1e-6);
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

// The sample chirp sweeps 0.05-80 Hz of a 2 kHz log: above the sweep the input has no power
// and the Hann lag window's negative side lobes make the smoothed Phi_u negative there. SPA
// leaves those frequencies out and says so, instead of returning NaN.
TEST(Spa, LeavesOutFrequenciesWithoutInputPowerAndSaysSo) {
  const auto read =
      readLog(std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv");
  ASSERT_TRUE(read.ok) << read.error.problem;
  const IdData d = addDerivative(read.data);
  const auto r = spa(d);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  EXPECT_GT(r.omittedFrequencies, 0);
  EXPECT_EQ(r.response.omega.size() + static_cast<std::size_t>(r.omittedFrequencies), 128u);
  EXPECT_NE(r.message.find("left out " + std::to_string(r.omittedFrequencies)), std::string::npos)
      << r.message;
  for (std::size_t i = 0; i < r.response.omega.size(); ++i) {
    ASSERT_TRUE(std::isfinite(r.response.magnitude[i])) << r.response.omega[i];
    ASSERT_TRUE(std::isfinite(r.response.phase[i])) << r.response.omega[i];
    ASSERT_TRUE(std::isfinite(r.response.magnitudeUpper[i])) << r.response.omega[i];
  }
  // An input without power has no estimate at all: a failure with a sentence, not NaN.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(1000), y = Eigen::VectorXd::LinSpaced(1000, 0, 1);
  const auto none = spa(u, y, 0.01);
  EXPECT_EQ(none.termination, Termination::Failed);
  EXPECT_TRUE(none.response.omega.empty());
  EXPECT_FALSE(none.message.empty());
}

}  // namespace
}  // namespace flexarm
