// The recursive estimator's contract: options and misuse, the fixed predictor, copies and
// reset, the seed's P(0) against (6.51)/(6.52), the regularisation (6.9) against a P that
// blows up, the projection at the bounds, and data failures as sentences.
#include <gtest/gtest.h>

#include <random>

#include "core/recursive/rpem.h"
#include "recursive_helpers.h"

namespace flexarm {
namespace {

constexpr double kTs = 0.005;

struct Data {
  Eigen::VectorXd u, y;
};

// The first-order system of Example 6.1 driven by white noise, a little output noise.
Data firstOrderData(double a, double theta, Eigen::Index n, unsigned seed, double noise = 0.001) {
  std::mt19937 rng(seed);
  Data d;
  d.u = testing::gaussian(n, 1.0, rng);
  d.y = simulate(testing::FirstOrderModel(a, theta), d.u, kTs) + testing::gaussian(n, noise, rng);
  return d;
}

RecursiveOptions thetaOnly() {
  RecursiveOptions o;
  o.estimate = {"theta"};
  o.inverted.clear();
  return o;
}

TEST(RecursiveOptions, InvalidValuesAreSentences) {
  std::string why;
  RecursiveOptions o;
  EXPECT_TRUE(o.isValid(&why)) << why;
  o.lambda = 1.5;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("forgetting factor"), std::string::npos);
  o = RecursiveOptions{};
  o.r1 = {1e-8};
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("R1"), std::string::npos);
  o = RecursiveOptions{};
  o.estimate = {"k_T", "k_T"};
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_EQ(toString(RecursiveAlgorithm::Kalman), std::string("kalman"));
  EXPECT_EQ(recursiveAlgorithmFromString("forgetting"), RecursiveAlgorithm::ForgettingFactor);
  EXPECT_EQ(recursiveGradientFromString("difference"), RecursiveGradient::Difference);
  EXPECT_FALSE(recursiveGradientFromString("euler"));
}

TEST(RecursiveEstimator, MisuseThrows) {
  const auto m = testing::threeMassP6();
  RecursiveOptions o;
  EXPECT_THROW(RecursiveEstimator(*m, kTs, o), std::invalid_argument);  // P(0) missing
  o.p0 = {1, 1, 1};
  EXPECT_NO_THROW(RecursiveEstimator(*m, kTs, o));
  EXPECT_THROW(RecursiveEstimator(*m, 0.0, o), std::invalid_argument);
  RecursiveOptions unknown = o;
  unknown.estimate = {"k_T", "J_x", "f_m"};
  EXPECT_THROW(RecursiveEstimator(*m, kTs, unknown), std::invalid_argument);
  RecursiveOptions inverseOfSigned = o;
  inverseOfSigned.estimate = {"k_T", "d_a^-1", "f_m"};  // d_a may be negative
  EXPECT_THROW(RecursiveEstimator(*m, kTs, inverseOfSigned), std::invalid_argument);
  RecursiveOptions kalman = o;
  kalman.algorithm = RecursiveAlgorithm::Kalman;
  kalman.estimate = {"k_T", "J_a", "k_g"};  // k_g has no value in (6.54)
  EXPECT_THROW(RecursiveEstimator(*m, kTs, kalman), std::invalid_argument);
  kalman.r1 = {1e-8, 1e-8, 1e-8};
  EXPECT_NO_THROW(RecursiveEstimator(*m, kTs, kalman));
  RecursiveOptions outside = o;
  outside.startScale = 1e12;  // k_T beyond its upper bound of 1000
  EXPECT_THROW(RecursiveEstimator(*m, kTs, outside), std::invalid_argument);
  ModelOptions two;
  two.armAcceleration = true;  // two outputs
  EXPECT_THROW(RecursiveEstimator(*makeModel("three-mass", two), kTs, o), std::invalid_argument);
}

TEST(RecursiveEstimator, NamesUnitsAndTheStartInTheSeedsParameterisation) {
  const auto m = testing::threeMassP6();
  RecursiveOptions o;
  o.p0 = {1, 1, 1};
  o.startScale = 1.2;
  RecursiveEstimator est(*m, kTs, o);
  const auto& p = est.parameters();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].name, "k_T");
  EXPECT_EQ(p[1].name, "J_a^-1");
  EXPECT_EQ(p[1].modelName, "J_a");
  EXPECT_EQ(p[1].unit, "1/(kg m^2)");
  EXPECT_TRUE(p[1].inverted);
  EXPECT_DOUBLE_EQ(est.theta()[1], 1.2 / 1.72);  // 20 % above in theta, as the seed
  EXPECT_DOUBLE_EQ(p[1].toModel(est.theta()[1]), 1.72 / 1.2);
  EXPECT_DOUBLE_EQ(p[1].sigmaToModel(0.5, 0.01), 0.04);
  const auto model = est.model();
  EXPECT_DOUBLE_EQ(model->parameters()[static_cast<std::size_t>(model->indexOf("J_a"))].value, 1.72 / 1.2);
  EXPECT_DOUBLE_EQ(model->parameters()[static_cast<std::size_t>(model->indexOf("f_m"))].value, 0.0355 * 1.2);
  EXPECT_DOUBLE_EQ(model->parameters()[static_cast<std::size_t>(model->indexOf("J_g"))].value, 9.92);
}

TEST(RecursiveEstimator, NothingEstimatedIsTheFixedOutputErrorPredictor) {
  const Data d = firstOrderData(20.0, 2.0, 300, 1);
  RecursiveOptions o;
  o.estimate.clear();
  RecursiveEstimator est(testing::FirstOrderModel(20.0, 2.0), kTs, o);
  const Eigen::VectorXd sim = simulate(testing::FirstOrderModel(20.0, 2.0), d.u, kTs);
  for (Eigen::Index k = 0; k < d.u.size(); ++k) {
    EXPECT_NEAR(est.prediction(), sim[k], 1e-12);
    const RecursiveStep& s = est.update(d.u[k], d.y[k]);
    EXPECT_NEAR(s.epsilon, d.y[k] - sim[k], 1e-12);
  }
  EXPECT_TRUE(est.ok());
}

TEST(RecursiveEstimator, ACopyContinuesAloneAndResetReplays) {
  const Data d = firstOrderData(20.0, 2.0, 600, 2);
  RecursiveOptions o = thetaOnly();
  o.p0 = {100.0};  // about (1 - lambda) / E psi^2 (6.51): psi is u filtered and scaled by beta
  o.startScale = 1.5;
  RecursiveEstimator a(testing::FirstOrderModel(20.0, 2.0), kTs, o);
  for (Eigen::Index k = 0; k < 300; ++k) a.update(d.u[k], d.y[k]);
  RecursiveEstimator b = a;
  std::vector<double> first;
  for (Eigen::Index k = 300; k < 600; ++k) first.push_back(a.update(d.u[k], d.y[k]).theta[0]);
  for (Eigen::Index k = 300; k < 600; ++k)
    EXPECT_DOUBLE_EQ(b.update(d.u[k], d.y[k]).theta[0], first[static_cast<std::size_t>(k - 300)]);
  const double end = a.theta()[0];
  a.reset();
  EXPECT_EQ(a.samples(), 0u);
  EXPECT_DOUBLE_EQ(a.theta()[0], 3.0);
  for (Eigen::Index k = 0; k < 600; ++k) a.update(d.u[k], d.y[k]);
  EXPECT_DOUBLE_EQ(a.theta()[0], end);
  EXPECT_NEAR(end, 2.0, 0.02);  // and it found the gain
}

// Section 6.6.2: P(0) is the mean diagonal of the P update run at the nominal theta. With a
// stationary input that is the steady state (6.51) resp. (6.52).
TEST(RecursiveInitialCovariance, MatchesTheSteadyStatesOfTheSeed) {
  const auto m = testing::threeMassP6();
  std::mt19937 rng(3);
  const Eigen::VectorXd u = testing::gaussian(6000, 0.1, rng);
  const Eigen::VectorXd y = simulate(*m, u, kTs);
  RecursiveOptions o;
  const InitialCovariance f = steadyStateCovariance(*m, u, y, kTs, o);
  ASSERT_EQ(f.termination, Termination::Converged) << f.message;
  const Eigen::VectorXd expected = ((1.0 - o.lambda) * f.Q.inverse()).diagonal();  // (6.51)
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(f.p0[i] / expected[i], 1.0, 0.1) << i;
  o.algorithm = RecursiveAlgorithm::Kalman;
  const InitialCovariance k = steadyStateCovariance(*m, u, y, kTs, o);
  ASSERT_EQ(k.termination, Termination::Converged) << k.message;
  // (6.52): P Q P = R1 R2 with (6.54), checked on the diagonal P(0) through its magnitudes.
  const Eigen::MatrixXd P0 = k.p0.asDiagonal();
  const Eigen::MatrixXd PQP = P0 * k.Q * P0;
  const double r1[3] = {5e-8, 5e-7, 5e-6};
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::log10(PQP(i, i) / r1[i]), 0.0, 0.5) << i;
}

// Poor excitation (the input stops): with forgetting P grows by 1 / lambda every sample until
// it blows up; the regularisation (6.9) keeps it below 1 / mu.
TEST(RecursiveEstimator, RegularisationKeepsPBoundedWhenTheExcitationStops) {
  Data d = firstOrderData(20.0, 2.0, 6000, 4, 0.0);
  d.u.tail(5000).setZero();
  RecursiveOptions o = thetaOnly();
  o.lambda = 0.99;
  o.p0 = {0.01};
  o.covarianceLimit = 1e6;
  RecursiveResult plain = recursiveIdentification(testing::FirstOrderModel(20.0, 2.0), d.u, d.y, kTs, o);
  EXPECT_EQ(plain.termination, Termination::Diverged);
  EXPECT_NE(plain.message.find("P blew up"), std::string::npos) << plain.message;
  EXPECT_NE(plain.message.find("theta"), std::string::npos) << plain.message;
  EXPECT_LT(plain.samples, 6000u);
  o.mu = 10.0;
  RecursiveResult regularised =
      recursiveIdentification(testing::FirstOrderModel(20.0, 2.0), d.u, d.y, kTs, o);
  EXPECT_EQ(regularised.termination, Termination::Converged) << regularised.message;
  EXPECT_LT(regularised.P(0, 0), 1.0 / o.mu);
  EXPECT_GT(regularised.P(0, 0), 1e-3 / o.mu);  // it did grow towards the bound
  EXPECT_NEAR(regularised.estimates[0].final, 2.0, 0.01);
}

// The gain is negative in the data but theta's bounds keep it positive: the update is held
// back (projection) until it has pushed outside for maxHeldSeconds, then the run has diverged.
TEST(RecursiveEstimator, AnEstimateThatKeepsLeavingItsBoundsDiverges) {
  const Data d = firstOrderData(20.0, -1.0, 2000, 5);
  const testing::FirstOrderModel model(20.0, 1.0, 0.0);
  RecursiveOptions o = thetaOnly();
  o.p0 = {100.0};
  o.maxHeldSeconds = 0.5;
  const RecursiveResult r = recursiveIdentification(model, d.u, d.y, kTs, o);
  ASSERT_EQ(r.termination, Termination::Diverged) << r.message << " " << r.estimates[0].final;
  EXPECT_NE(r.message.find("left its bounds"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("theta"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("101 samples in a row"), std::string::npos) << r.message;  // 0.5 s
  for (double v : r.trajectory.theta[0]) EXPECT_GE(v, 0.0);
  EXPECT_LT(r.samples, 2000u);
}

TEST(RecursiveIdentification, DataFailuresAreSentences) {
  const auto m = testing::threeMassP6();
  Eigen::VectorXd u = Eigen::VectorXd::Ones(50), y = Eigen::VectorXd::Zero(50);
  RecursiveOptions o;
  RecursiveResult r = recursiveIdentification(*m, Eigen::VectorXd::Zero(400), Eigen::VectorXd::Zero(400), kTs, o);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("do not excite"), std::string::npos) << r.message;
  u[7] = std::numeric_limits<double>::quiet_NaN();
  r = recursiveIdentification(*m, u, y, kTs, o);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("sample 7"), std::string::npos) << r.message;
  r = recursiveIdentification(*m, Eigen::VectorXd::Ones(4), Eigen::VectorXd::Ones(4), kTs, o);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("at least"), std::string::npos) << r.message;
  EXPECT_THROW(recursiveIdentification(*m, Eigen::VectorXd::Ones(5), Eigen::VectorXd::Ones(6), kTs, o),
               std::invalid_argument);
}

TEST(RecursiveIdentification, ProgressCanCancel) {
  const Data d = firstOrderData(20.0, 2.0, 2000, 6);
  RecursiveOptions o = thetaOnly();
  o.p0 = {0.1};
  int calls = 0;
  const RecursiveResult r = recursiveIdentification(
      testing::FirstOrderModel(20.0, 2.0), d.u, d.y, kTs, o, [&](double fraction, const std::string&) {
        ++calls;
        return fraction > 0.5 ? ProgressAction::Abort : ProgressAction::Continue;
      });
  EXPECT_EQ(r.termination, Termination::Cancelled);
  EXPECT_GT(r.samples, 900u);
  EXPECT_LT(r.samples, 1100u);
  EXPECT_GT(calls, 10);
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

// With white output noise the assumptions of (7.8) hold: the +-3 sigma band holds the truth
// and no caveat is printed; with coloured noise it does not, and the result says so.
TEST(RecursiveSigma, HonestForWhiteErrorsAndFlaggedForColouredOnes) {
  const auto m = testing::threeMassP6();
  std::mt19937 rng(31);
  const Eigen::Index n = 8000;
  const Eigen::VectorXd u = testing::gaussian(n, 0.1, rng);
  const Eigen::VectorXd clean = simulate(*m, u, kTs);
  const double level = std::sqrt(clean.squaredNorm() / static_cast<double>(n));
  const Eigen::VectorXd white = testing::gaussian(n, 0.05 * level, rng);
  RecursiveOptions o;
  const RecursiveResult r = recursiveIdentification(*m, u, clean + white, kTs, o);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  EXPECT_TRUE(r.caveat.empty()) << r.caveat;
  const auto& t = r.trajectory;
  std::size_t misses = 0, count = 0;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t k = t.size() / 4; k < t.size(); ++k, ++count)
      if (std::abs(t.theta[i][k] - r.estimates[i].parameter.nominal) > 3.0 * t.sigma[i][k]) ++misses;
  EXPECT_LT(static_cast<double>(misses) / static_cast<double>(count), 0.01);
  for (const auto& e : r.estimates) EXPECT_LT(e.spread, e.meanSigma) << e.parameter.name;

  // The same noise through a slow filter: strongly coloured errors.
  Eigen::VectorXd coloured(n);
  double state = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) coloured[k] = state = 0.98 * state + white[k];
  const RecursiveResult c = recursiveIdentification(*m, u, clean + coloured, kTs, o);
  ASSERT_EQ(c.termination, Termination::Converged) << c.message;
  EXPECT_GT(c.epsilonLag1, 0.9);
  EXPECT_NE(c.caveat.find("coloured"), std::string::npos) << c.caveat;
}

}  // namespace
}  // namespace flexarm
