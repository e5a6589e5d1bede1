// Grey-box prediction-error estimation through the ParametricModel interface, with a
// test-local two-mass model (3.13): analytic gradients against finite differences, recovery of
// the true parameters within their 99 % intervals, fixed subsets, several starts, cancel.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/ident/pem.h"
#include "core/models/physical_models.h"
#include "sim_helpers.h"
#include "two_mass_test_model.h"

namespace flexarm {
namespace {

using testing::TwoMassTestModel;

constexpr double kTs = 0.005;  // 200 Hz, the seed's rate after decimation by ten

struct TwoMassData {
  Eigen::VectorXd u, y, yClean;
};

TwoMassData makeData(unsigned seed, Eigen::Index n = 3000, double noiseFraction = 0.05) {
  std::mt19937 rng(seed);
  TwoMassData d;
  d.u = testing::whiteNoise(n, 1.0, rng);
  d.yClean = testing::rk4Simulate(TwoMassTestModel().stateSpace(), d.u, kTs);
  const double sd = std::sqrt((d.yClean.array() - d.yClean.mean()).square().mean());
  d.y = d.yClean + testing::whiteNoise(n, noiseFraction * sd, rng);
  return d;
}

TEST(GreyBox, NominalNotchIsSeedEquation54) {
  // (5.4): the notch of the nominal two-mass model lies near sqrt(k / J_a) = 112 rad/s.
  const auto fr = frequencyResponse(TwoMassTestModel(), logGrid(20.0, 1000.0, 3000));
  const auto np = notchesAndPeaks(fr);
  ASSERT_EQ(np.notches.size(), 1u);
  EXPECT_NEAR(np.notches[0], 112.0, 1.0);
  ASSERT_EQ(np.peaks.size(), 1u);
  EXPECT_NEAR(np.peaks[0], 155.0, 5.0);
}

TEST(GreyBox, ZohMatchesRk4AndSensitivityMatchesFiniteDifferences) {
  const auto d = makeData(1, 400, 0.05);  // noisy: eps must depend on K
  TwoMassTestModel m;
  EXPECT_LT((simulate(m, d.u, kTs) - d.yClean).cwiseAbs().maxCoeff(),
            1e-6 * d.yClean.cwiseAbs().maxCoeff());
  const std::vector<int> free{0, 1, 2, 3, 4};
  Eigen::VectorXd K(3);
  K << 0.0, 0.2, 0.0;  // a stable predictor (spectral radius 0.83)
  for (bool withK : {false, true}) {
    const Eigen::VectorXd Kuse = withK ? K : Eigen::VectorXd();
    const auto ev = evaluatePredictor(m, Kuse, d.u, d.y, kTs, free, true, withK);
    ASSERT_TRUE(ev.stable);
    for (std::size_t j = 0; j < free.size(); ++j) {
      TwoMassTestModel mp = m, mm = m;
      const auto& p = m.parameters()[free[j]];
      const double h = 1e-6 * std::max(std::abs(p.value), 1e-3);
      mp.setParameter(p.name, p.value + h);
      mm.setParameter(p.name, p.value - h);
      const Eigen::VectorXd fd = -(predictionErrors(mp, Kuse, d.u, d.y, kTs) -
                                   predictionErrors(mm, Kuse, d.u, d.y, kTs)) / (2 * h);
      EXPECT_LT((ev.psi.col(j) - fd).norm(), 1e-5 * fd.norm() + 1e-12) << p.name << " K=" << withK;
    }
    if (withK)
      for (int j = 0; j < 3; ++j) {
        Eigen::VectorXd kp = K, km = K;
        const double h = 1e-9;  // K1 feeds the spring twist, which Ad amplifies by ~5e3
        kp[j] += h;
        km[j] -= h;
        const Eigen::VectorXd fd = -(predictionErrors(m, kp, d.u, d.y, kTs) -
                                     predictionErrors(m, km, d.u, d.y, kTs)) / (2 * h);
        EXPECT_LT((ev.psi.col(5 + j) - fd).norm(), 1e-5 * fd.norm()) << "K" << j;
      }
  }
}

void perturbStart(ParametricModel& m) {
  m.setParameter("J_m", 9e-4 * 1.2);
  m.setParameter("J_a", 12.0 * 0.85);
  m.setParameter("f_m", 0.1 * 1.3);
  m.setParameter("k", 1.5e5 * 1.1);
  m.setParameter("d", 70.0 * 1.5);
}

TEST(GreyBox, OutputErrorRecoversTwoMassParametersWithinIntervals) {
  const TwoMassTestModel truth;
  int inside = 0, total = 0;
  double worst = 0.0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const auto d = makeData(10 + seed);
    TwoMassTestModel m;
    perturbStart(m);
    const auto r = pem(m, d.u, d.y, kTs);
    ASSERT_TRUE(r.summary.ok()) << r.summary.message;
    ASSERT_EQ(r.covariance.rows(), 5);
    for (const auto& p : r.parameters) {
      if (!p.free) continue;
      const double t = truth.parameters()[truth.indexOf(p.name)].value;
      const double sig = std::abs(p.value - t) / p.std;
      worst = std::max(worst, sig);
      inside += t >= p.lower && t <= p.upper;
      ++total;
    }
  }
  ::testing::Test::RecordProperty("inside99", inside);
  ::testing::Test::RecordProperty("total", total);
  EXPECT_GE(inside, total - 1);
  EXPECT_LT(worst, 4.0);
}

TEST(GreyBox, FixedDampingStaysAtZeroLikeSeedP1) {
  const auto d = makeData(3);
  TwoMassTestModel m;
  perturbStart(m);
  m.setParameter("d", 0.0);
  m.setFree("d", false);
  const auto r = pem(m, d.u, d.y, kTs);
  ASSERT_TRUE(r.summary.ok()) << r.summary.message;
  EXPECT_EQ(r.model->parameters()[4].value, 0.0);
  EXPECT_EQ(r.parameters[4].std, 0.0);
  EXPECT_EQ(r.freeNames.size(), 4u);
  // Without damping the fit is worse than the truth's noise level but close in k / J_a (5.4).
  const double ka = r.model->parameters()[3].value / r.model->parameters()[1].value;
  EXPECT_NEAR(std::sqrt(ka), std::sqrt(1.5e5 / 12.0), 3.0);
}

TEST(GreyBox, InnovationsFormLowersTheLossOnColouredNoise) {
  auto d = makeData(4, 3000, 0.0);
  std::mt19937 rng(44);
  const Eigen::VectorXd e = testing::whiteNoise(d.u.size(), 0.02, rng);
  d.y = d.yClean + filter({1.0}, {1.0, -0.95}, e);  // slowly varying disturbance
  TwoMassTestModel m;
  PemOptions oeOpt, inOpt;
  inOpt.noiseModel = NoiseModel::Innovations;
  const auto ro = pem(m, d.u, d.y, kTs, oeOpt);
  const auto ri = pem(m, d.u, d.y, kTs, inOpt);
  ASSERT_TRUE(ro.summary.ok()) << ro.summary.message;
  ASSERT_TRUE(ri.summary.ok()) << ri.summary.message;
  EXPECT_EQ(ri.K.size(), 3);
  EXPECT_EQ(ri.parameters.size(), 6u + 3u);
  EXPECT_LT(ri.summary.loss, 0.5 * ro.summary.loss);
}

TEST(GreyBox, SeveralStartsRescueAFarStart) {
  const auto d = makeData(5);
  TwoMassTestModel far;
  far.setParameter("k", 1.5e5 * 3.5);
  far.setParameter("J_a", 12.0 * 0.4);
  far.setParameter("J_m", 9e-4 * 2.0);
  PemOptions single;
  const auto r1 = pem(far, d.u, d.y, kTs, single);
  PemOptions multi;
  multi.targetNotches = {112.0};  // as read from a non-parametric estimate
  multi.targetPeaks = {155.0};
  multi.notchPeakStarts = 2;
  multi.randomStarts = 2;
  const auto r2 = pem(far, d.u, d.y, kTs, multi);
  ASSERT_TRUE(r2.summary.ok()) << r2.summary.message;
  EXPECT_EQ(r2.starts, 5);
  EXPECT_LE(r2.summary.loss, r1.summary.loss);
  const double noiseVar = std::pow(0.05, 2) * (d.yClean.array() - d.yClean.mean()).square().mean();
  EXPECT_LT(r2.summary.loss, 1.2 * noiseVar);
  EXPECT_NEAR(r2.model->parameters()[3].value / 1.5e5, 1.0, 0.05);
}

TEST(GreyBox, AStartOnABoundIsFittedNotRefused) {
  // exp(log(1e4)) rounds one ulp past 1e4, the friction's upper bound: a start there (as a
  // random start clamped to its bounds, or a step projected onto them) ended the fit with
  // "f_m = 10000 is outside its bounds".
  const auto truth = makeModel("two-mass");
  std::mt19937 rng(8);
  const Eigen::VectorXd u = testing::whiteNoise(600, 1.0, rng);
  const Eigen::VectorXd y = testing::rk4Simulate(truth->stateSpace(), u, kTs);
  auto start = makeModel("two-mass");
  start->setParameter("f_m", 1e4);
  PemOptions o;
  o.maxIterations = 5;
  o.randomStarts = 2;
  PemResult r;
  ASSERT_NO_THROW(r = pem(*start, u, y, kTs, o));
  EXPECT_NE(r.summary.termination, Termination::Failed) << r.summary.message;
  EXPECT_EQ(r.starts, 3);
  for (const auto& p : r.model->parameters()) {
    EXPECT_GE(p.value, p.lower) << p.name;
    EXPECT_LE(p.value, p.upper) << p.name;
  }
}

TEST(GreyBox, CancelStopsTheSearch) {
  const auto d = makeData(6, 1000);
  TwoMassTestModel m;
  perturbStart(m);
  int calls = 0;
  const auto r = pem(m, d.u, d.y, kTs, {}, [&](double, const std::string&) {
    return ++calls >= 2 ? ProgressAction::Abort : ProgressAction::Continue;
  });
  EXPECT_EQ(r.summary.termination, Termination::Cancelled);
  EXPECT_EQ(calls, 2);
}

TEST(GreyBox, BandStdMatchesFiniteDifferenceLinearization) {
  // With covariance diag(s_j^2), Var |G| = sum_j (d|G|/d theta_j)^2 s_j^2 (Gauss approximation).
  TwoMassTestModel m;
  const std::vector<int> free{0, 1, 3, 4};
  Eigen::VectorXd sd(4);
  sd << 2e-5, 0.3, 3e3, 5.0;
  const Eigen::MatrixXd cov = sd.cwiseAbs2().asDiagonal();
  const std::vector<double> omega{30.0, 112.0, 150.0, 400.0};
  const auto fr = frequencyResponse(m, omega, cov, free, 0.99);
  ASSERT_TRUE(fr.hasBands());
  for (std::size_t i = 0; i < omega.size(); ++i) {
    double var = 0.0;
    for (std::size_t j = 0; j < free.size(); ++j) {
      TwoMassTestModel mp = m, mm = m;
      const auto& p = m.parameters()[free[j]];
      const double h = 1e-6 * std::abs(p.value);
      mp.setParameter(p.name, p.value + h);
      mm.setParameter(p.name, p.value - h);
      const double dmag = (frequencyResponse(mp, {omega[i]}).magnitude[0] -
                           frequencyResponse(mm, {omega[i]}).magnitude[0]) / (2 * h);
      var += dmag * dmag * sd[j] * sd[j];
    }
    EXPECT_NEAR(fr.magnitudeStd[i], std::sqrt(var), 1e-5 * std::sqrt(var)) << omega[i];
    EXPECT_NEAR(fr.magnitudeUpper[i] - fr.magnitude[i], 2.5758 * fr.magnitudeStd[i],
                1e-3 * fr.magnitudeStd[i]);
  }
}

TEST(GreyBox, MisuseThrows) {
  TwoMassTestModel m;
  Eigen::VectorXd u = Eigen::VectorXd::Ones(100), y = Eigen::VectorXd::Ones(99);
  EXPECT_THROW(pem(m, u, y, kTs), std::invalid_argument);
  for (const auto& p : std::vector<std::string>{"J_m", "J_a", "f_m", "k", "d"}) m.setFree(p, false);
  EXPECT_THROW(pem(m, u, u, kTs), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
