// The one-pass predictor of (4.8) against the plain definitions: eps (4.5) by filtering the
// data polynomial by polynomial, and psi (4.20) formed column by column as minus the
// derivative of eps, checked by finite differences; R and g against psi^T psi and psi^T eps.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/ident/poly_predictor.h"
#include "sim_helpers.h"

namespace flexarm {
namespace {

// eps = D/C (A y - B/F u) with zero initial conditions, straight from the definition.
Eigen::VectorXd referenceErrors(const PolynomialModel& m, const Eigen::VectorXd& u,
                                const Eigen::VectorXd& y) {
  const Eigen::VectorXd v = filter(m.a, {1.0}, y) - filter(m.b, m.f, u);
  return filter(m.d, m.c, v);
}

// psi = -d eps / d theta by central differences of the reference errors.
Eigen::MatrixXd numericPsi(const PolynomialModel& m, const Eigen::VectorXd& u,
                           const Eigen::VectorXd& y) {
  const Eigen::VectorXd th = m.parameterVector();
  Eigen::MatrixXd psi(y.size(), th.size());
  for (Eigen::Index j = 0; j < th.size(); ++j) {
    const double h = 1e-6;
    PolynomialModel up = m, down = m;
    Eigen::VectorXd t1 = th, t2 = th;
    t1[j] += h;
    t2[j] -= h;
    up.setParameterVector(t1);
    down.setParameterVector(t2);
    psi.col(j) = -(referenceErrors(up, u, y) - referenceErrors(down, u, y)) / (2.0 * h);
  }
  return psi;
}

struct Case {
  const char* name;
  PolyStructure structure;
  PolyOrders orders;
};

// A stable model of the given orders with every coefficient non-zero.
PolynomialModel someModel(const Case& c, unsigned seed) {
  PolynomialModel m = PolynomialModel::zero(c.structure, c.orders, 1.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coefficient(-0.6, 0.6);
  Eigen::VectorXd th(c.orders.parameters());
  for (Eigen::Index i = 0; i < th.size(); ++i) th[i] = coefficient(rng);
  m.setParameterVector(th);
  // Roots well inside the unit circle (products of stable first-order factors).
  const auto stable = [&](Poly& p) {
    Poly q{1.0};
    for (std::size_t k = 1; k < p.size(); ++k) q = polyMultiply(q, {1.0, coefficient(rng)});
    p = q;
  };
  stable(m.a);
  stable(m.c);
  stable(m.d);
  stable(m.f);
  return m;
}

const Case kCases[] = {
    {"oe221", PolyStructure::Oe, {0, 2, 0, 0, 2, 1}},
    {"oe330", PolyStructure::Oe, {0, 3, 0, 0, 3, 0}},
    {"oe446", PolyStructure::Oe, {0, 4, 0, 0, 4, 6}},  // delay longer than the orders
    {"oe761", PolyStructure::Oe, {0, 7, 0, 0, 6, 1}},  // orders above the fixed-order passes
    {"arx221", PolyStructure::Arx, {2, 2, 0, 0, 0, 1}},
    {"armax2221", PolyStructure::Armax, {2, 2, 2, 0, 0, 1}},
    {"armax3302", PolyStructure::Armax, {3, 3, 0, 0, 0, 2}},
    {"armax5516", PolyStructure::Armax, {5, 5, 1, 0, 0, 6}},
    {"bj22221", PolyStructure::Bj, {0, 2, 2, 2, 2, 1}},
    {"bj21121", PolyStructure::Bj, {0, 2, 1, 1, 2, 1}},
    {"bj20221", PolyStructure::Bj, {0, 2, 0, 2, 2, 1}},
    {"bj33330", PolyStructure::Bj, {0, 3, 3, 3, 3, 0}},
    {"bj65561", PolyStructure::Bj, {0, 6, 5, 5, 6, 1}},
    {"general", PolyStructure::Bj, {2, 2, 1, 2, 2, 1}},  // A, B, C, D and F at once
};

TEST(PolyPredictor, ErrorsAndNormalEquationsMatchTheDefinitions) {
  const Poly one{1.0};
  // Records long enough for several blocks, and one shorter than a block, odd in length.
  for (const Eigen::Index n : {Eigen::Index{2049}, Eigen::Index{301}}) {
    const auto data = testing::simulateSystem({1.0, -1.2, 0.5}, {0.0, 1.0, 0.4}, {1.0, 0.3}, one,
                                              one, n, 0.3, 17);
    for (const Case& c : kCases) {
      SCOPED_TRACE(std::string(c.name) + " over " + std::to_string(n) + " samples");
      const PolynomialModel m = someModel(c, 5);
      PolyPredictor predictor(data.u, data.y, c.orders);
      const Eigen::VectorXd eps = referenceErrors(m, data.u, data.y);
      const Eigen::VectorXd got = predictor.errors(m);
      ASSERT_EQ(got.size(), n);
      EXPECT_LT((got - eps).cwiseAbs().maxCoeff(), 1e-12 * eps.cwiseAbs().maxCoeff());

      const Eigen::Index n0 = PolyPredictor::criterionStart(c.orders, n);
      EXPECT_EQ(predictor.criterionStart(), n0);
      const Eigen::VectorXd used = eps.tail(n - n0);
      Eigen::MatrixXd R;
      Eigen::VectorXd g;
      const double ss = predictor.run(m, &R, &g);
      EXPECT_NEAR(ss, used.squaredNorm(), 1e-12 * used.squaredNorm());
      EXPECT_EQ(predictor.run(m), ss);  // the same sum without the normal equations

      const Eigen::MatrixXd psi = numericPsi(m, data.u, data.y).bottomRows(n - n0);
      const Eigen::MatrixXd Rref = psi.transpose() * psi;
      const Eigen::VectorXd gref = psi.transpose() * used;
      ASSERT_EQ(R.rows(), c.orders.parameters());
      EXPECT_LT((R - Rref).cwiseAbs().maxCoeff(), 1e-6 * Rref.cwiseAbs().maxCoeff());
      EXPECT_LT((g - gref).cwiseAbs().maxCoeff(), 1e-6 * Rref.diagonal().cwiseSqrt().maxCoeff() *
                                                        std::sqrt(used.squaredNorm()));
    }
  }
}

TEST(PolyPredictor, StopsOnceTheSumExceedsTheBound) {
  const auto data = testing::simulateSystem({1.0}, {0.0, 1.0, 0.5}, {1.0}, {1.0},
                                            {1.0, -1.5, 0.7}, 5000, 0.5, 3);
  PolynomialModel m = PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 2, 1}, 1.0);
  m.b = {0.0, 1.0, 0.5};
  m.f = {1.0, -1.5, 0.7};
  PolyPredictor predictor(data.u, data.y, m.orders);
  const double full = predictor.run(m);
  Eigen::MatrixXd R;
  Eigen::VectorXd g;
  // A bound above the sum changes nothing; below it, the run stops early with a partial sum
  // that already exceeds the bound (and is less than the whole).
  EXPECT_EQ(predictor.run(m, &R, &g, 2.0 * full), full);
  EXPECT_EQ(R.rows(), 2 + 2);
  const double partial = predictor.run(m, nullptr, nullptr, 0.01 * full);
  EXPECT_GT(partial, 0.01 * full);
  EXPECT_LT(partial, full);
}

TEST(PolyPredictor, RejectsModelsOutsideTheStructure) {
  const Eigen::VectorXd u = Eigen::VectorXd::Ones(50), y = Eigen::VectorXd::Ones(50);
  PolynomialModel m = PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 2, 1}, 1.0);
  PolyPredictor predictor(u, y, m.orders);
  m.f[0] = 2.0;  // (4.8) has a monic F
  EXPECT_THROW(predictor.run(m), std::invalid_argument);
  PolynomialModel other = PolynomialModel::zero(PolyStructure::Oe, {0, 3, 0, 0, 2, 1}, 1.0);
  EXPECT_THROW(predictor.run(other), std::invalid_argument);
  EXPECT_THROW(PolyPredictor(Eigen::VectorXd::Ones(3), y, m.orders), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
