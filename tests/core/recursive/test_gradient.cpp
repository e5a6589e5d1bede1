// psi(t) of the recursive estimator: the sampled sensitivity system (6.27) against central
// differences of the whole re-simulation, and the difference gradient (6.33) of Section 6.3.2
// with Example 6.1 (6.42)-(6.45), which shows why it fails for an output-error predictor.
#include <gtest/gtest.h>

#include <random>

#include "core/ident/pem.h"
#include "core/recursive/rpem.h"
#include "recursive_helpers.h"

namespace flexarm {
namespace {

constexpr double kTs = 0.005;

// psi over the whole input at the model's theta, one column per theta entry. held: theta is
// held (updateParameters = false: the model sampled once by sampleZoh); otherwise the
// estimator runs as it does on data, sampling the extended system every sample, on the
// model's own noise-free output, so that the prediction errors and theta's updates vanish.
Eigen::MatrixXd psiAtFixedTheta(const ParametricModel& model, const RecursiveOptions& base,
                                const Eigen::VectorXd& u, Eigen::VectorXd* yhat = nullptr,
                                bool held = true) {
  RecursiveOptions o = base;
  o.updateParameters = !held;
  o.p0.assign(o.estimate.size(), 1.0);
  RecursiveEstimator est(model, kTs, o);
  const Eigen::VectorXd y = held ? Eigen::VectorXd::Zero(u.size()) : simulate(model, u, kTs);
  Eigen::MatrixXd psi(u.size(), static_cast<Eigen::Index>(o.estimate.size()));
  if (yhat) yhat->resize(u.size());
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    const RecursiveStep& s = est.update(u[k], y[k]);
    psi.row(k) = s.psi.transpose();
    if (yhat) (*yhat)[k] = s.yhat;
  }
  return psi;
}

// d yhat / d theta_j by central differences of the output-error simulation from zero state, in
// theta's coordinates (theta = 1 / J_a for an inverted entry).
Eigen::VectorXd centralDifference(const ParametricModel& model, const std::string& name,
                                  bool inverted, const Eigen::VectorXd& u) {
  const double value = model.parameters()[static_cast<std::size_t>(model.indexOf(name))].value;
  const double theta = inverted ? 1.0 / value : value;
  const double h = 1e-5 * std::abs(theta);
  auto at = [&](double th) {
    auto m = model.clone();
    m->setParameter(name, inverted ? 1.0 / th : th);
    return simulate(*m, u, kTs);
  };
  return (at(theta + h) - at(theta - h)) / (2.0 * h);
}

TEST(RecursiveGradient, SensitivityPsiEqualsCentralDifferencesOfTheReSimulation) {
  const auto model = testing::threeMassP6();
  std::mt19937 rng(11);
  const Eigen::VectorXd u = testing::gaussian(1500, 0.1, rng);
  RecursiveOptions o;  // theta = (k_T, J_a^-1, f_m), the seed's
  const Eigen::VectorXd sim = simulate(*model, u, kTs);
  const std::vector<std::pair<std::string, bool>> entries = {{"k_T", false}, {"J_a", true}, {"f_m", false}};
  for (bool held : {true, false}) {
    Eigen::VectorXd yhat;
    const Eigen::MatrixXd psi = psiAtFixedTheta(*model, o, u, &yhat, held);
    // The predictor at the model's theta is the output-error simulation.
    EXPECT_LT((yhat - sim).lpNorm<Eigen::Infinity>(), 1e-10 * sim.lpNorm<Eigen::Infinity>()) << held;
    for (std::size_t j = 0; j < entries.size(); ++j) {
      const Eigen::VectorXd cd = centralDifference(*model, entries[j].first, entries[j].second, u);
      const double err = (psi.col(static_cast<Eigen::Index>(j)) - cd).lpNorm<Eigen::Infinity>() /
                         cd.lpNorm<Eigen::Infinity>();
      EXPECT_LT(err, 1e-6) << entries[j].first << (held ? " held" : " updated every sample");
    }
  }
}

TEST(RecursiveGradient, AnySubsetOfParametersAndAnotherStructure) {
  auto model = makeModel("two-mass");
  std::mt19937 rng(12);
  const Eigen::VectorXd u = testing::gaussian(1200, 0.1, rng);
  RecursiveOptions o;
  o.estimate = {"k_a", "d_a", "J_m^-1"};
  o.inverted.clear();
  const Eigen::MatrixXd psi = psiAtFixedTheta(*model, o, u);
  const std::vector<std::pair<std::string, bool>> entries = {{"k_a", false}, {"d_a", false}, {"J_m", true}};
  for (std::size_t j = 0; j < entries.size(); ++j) {
    const Eigen::VectorXd cd = centralDifference(*model, entries[j].first, entries[j].second, u);
    EXPECT_LT((psi.col(static_cast<Eigen::Index>(j)) - cd).lpNorm<Eigen::Infinity>() /
                  cd.lpNorm<Eigen::Infinity>(),
              1e-6)
        << entries[j].first;
  }
}

// Example 6.1: y(t) = theta / (1 - alpha q^-1) u(t) (here sampled from x' = -a x + theta u, so
// one sample later and with the gain beta). The true gradient (6.44) is u filtered by
// 1 / (1 - alpha q^-1); the difference (6.33) from the shared past prediction (6.41) only sees
// the new input, (6.45).
TEST(RecursiveGradient, Example61TheDifferenceGradientMissesTheOutputErrorRecursion) {
  const double a = 20.0, theta = 2.0;
  const double alpha = std::exp(-a * kTs), beta = (1.0 - alpha) / a;
  const testing::FirstOrderModel model(a, theta);
  std::mt19937 rng(13);
  const Eigen::VectorXd u = testing::gaussian(800, 1.0, rng);
  RecursiveOptions o;
  o.estimate = {"theta"};
  o.inverted.clear();
  o.gradient = RecursiveGradient::Sensitivity;
  const Eigen::VectorXd exact = psiAtFixedTheta(model, o, u).col(0);
  EXPECT_LT((psiAtFixedTheta(model, o, u, nullptr, false).col(0) - exact).lpNorm<Eigen::Infinity>(),
            1e-12 * exact.lpNorm<Eigen::Infinity>());
  o.gradient = RecursiveGradient::Difference;
  const Eigen::VectorXd difference = psiAtFixedTheta(model, o, u).col(0);
  EXPECT_LT((psiAtFixedTheta(model, o, u, nullptr, false).col(0) - difference).lpNorm<Eigen::Infinity>(),
            1e-9 * difference.lpNorm<Eigen::Infinity>());

  double psi = 0.0;  // (6.44): psi(t) = alpha psi(t-1) + beta u(t-1)
  for (Eigen::Index t = 1; t < u.size(); ++t) {
    psi = alpha * psi + beta * u[t - 1];
    EXPECT_NEAR(exact[t], psi, 1e-12);
    EXPECT_NEAR(difference[t], beta * u[t - 1], 1e-9);  // (6.45)
  }
  const Eigen::VectorXd cd = centralDifference(model, "theta", false, u);
  EXPECT_LT((exact - cd).lpNorm<Eigen::Infinity>() / cd.lpNorm<Eigen::Infinity>(), 1e-8);
  // The difference gradient lacks the filter: its error is of the order of psi itself.
  EXPECT_GT((difference - cd).norm() / cd.norm(), 0.5);
}

}  // namespace
}  // namespace flexarm
