// The order scan (core/ident/order_scan.h) as arxstruc and selstruc define it: the true ARX
// structure picked on simulated data, every structure's loss equal to a fit of its own, and the
// state-space order from the subspace step.
#include <gtest/gtest.h>

#include <memory>

#include "core/ident/blackbox.h"
#include "core/ident/fit_data.h"
#include "core/ident/model_output.h"
#include "core/ident/order_scan.h"
#include "tests/core/ident/sim_helpers.h"
#include "tests/core/ident/subspace_logs.h"

namespace flexarm {
namespace {

FitOptions halves(const std::shared_ptr<const IdData>& d) {
  const double T = d->sampleTime, n = static_cast<double>(d->samples());
  FitOptions o;
  o.estimation = {{d, SecondsRange{0.0, T * (n / 2 - 1)}}};
  o.validation = {{d, SecondsRange{T * n / 2, T * (n - 1)}}};
  return o;
}

TEST(OrderScan, PicksTheTrueArxStructure) {
  // A y = B u + e with na = 2, nb = 2, nk = 2.
  const Poly a{1.0, -1.5, 0.7}, b{0.0, 0.0, 1.0, 0.5}, one{1.0};
  int mdlRight = 0, aicRight = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const testing::SimData s = testing::simulateSystem(a, b, one, one, one, 4000, 0.3, seed);
    const FitOptions o = halves(testing::torqueVelocityLog(s.u, s.y, 1e-3));
    OrderScanOptions scan;
    scan.maxNa = 5;
    scan.maxNb = 5;
    scan.maxNk = 3;
    scan.maxStateOrder = 0;
    const OrderScan r = scanOrders(o, scan);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_TRUE(r.onValidation);
    EXPECT_EQ(r.rows.size(), 6u * 5u * 3u);
    mdlRight += r.pickName(r.bestMdl) == "arx[2 2 2]";
    aicRight += r.pickName(r.bestAic) == "arx[2 2 2]";
    // The least validation loss (selstruc(V, 0)) often takes a larger structure, which gains
    // next to nothing over the truth on data it was not fitted to.
    double truth = 0.0;
    for (const auto& row : r.rows)
      if (row.na == 2 && row.nb == 2 && row.nk == 2) truth = row.loss;
    ASSERT_GE(r.best, 0);
    EXPECT_GT(r.rows[static_cast<std::size_t>(r.best)].loss / truth, 0.99);
    EXPECT_NEAR(truth / (0.3 * 0.3), 1.0, 0.1);  // the noise variance
  }
  // MDL is consistent; AIC may take a larger structure now and then.
  EXPECT_EQ(mdlRight, 5);
  EXPECT_GE(aicRight, 3);
}

TEST(OrderScan, EachLossIsThatOfItsOwnFit) {
  const Poly a{1.0, -1.2, 0.5}, b{0.0, 0.8, 0.3}, one{1.0};
  const testing::SimData s = testing::simulateSystem(a, b, one, one, one, 3000, 0.2, 9);
  const FitOptions o = halves(testing::torqueVelocityLog(s.u, s.y, 1e-3));
  OrderScanOptions scan;
  scan.maxNa = 4;
  scan.maxNb = 4;
  scan.maxNk = 2;
  scan.maxStateOrder = 0;
  const OrderScan r = scanOrders(o, scan);
  ASSERT_TRUE(r.ok) << r.message;
  // The estimation half with its mean removed, as the scan prepared it; every structure on the
  // same rows (from the largest lag on), so a fit of arx[3 2 1] on those rows gives the loss.
  const Eigen::Index half = 1500;
  Eigen::VectorXd ue = s.u.head(half), ye = s.y.head(half);
  const double um = ue.mean(), ym = ye.mean();
  ue.array() -= um;
  ye.array() -= ym;
  const int first = 5;  // max(maxNa, maxNk + maxNb - 1)
  for (const auto& row : r.rows) {
    if (row.na != 3 || row.nb != 2 || row.nk != 1) continue;
    // Least squares on rows first.. of the estimation half.
    Eigen::MatrixXd phi(half - first, 5);
    for (Eigen::Index t = first; t < half; ++t) {
      phi.row(t - first) << -ye[t - 1], -ye[t - 2], -ye[t - 3], ue[t - 1], ue[t - 2];
    }
    const Eigen::VectorXd theta = phi.colPivHouseholderQr().solve(ye.tail(half - first));
    // Its loss on the validation half (the estimation means removed).
    Eigen::VectorXd uv = s.u.tail(1500), yv = s.y.tail(1500);
    uv.array() -= um;
    yv.array() -= ym;
    double sum = 0.0;
    Eigen::Index count = 0;
    for (Eigen::Index t = first; t < uv.size(); ++t, ++count) {
      const double pred = -theta[0] * yv[t - 1] - theta[1] * yv[t - 2] - theta[2] * yv[t - 3] + theta[3] * uv[t - 1] +
                          theta[4] * uv[t - 2];
      sum += (yv[t] - pred) * (yv[t] - pred);
    }
    EXPECT_NEAR(row.loss / (sum / static_cast<double>(count)), 1.0, 1e-9);
    return;
  }
  FAIL() << "arx[3 2 1] was not scanned";
}

TEST(OrderScan, StateSpaceOrderOfAFlexibleArm) {
  const testing::ArmLog log = testing::armLog(3, false, 21u, 6000);
  const FitOptions o = halves(testing::torqueVelocityLog(log.u, log.y, 0.005));
  std::string why;
  FitModelSpec spec;
  spec.kind = FitModelKind::BlackBox;
  spec.structure = PolyStructure::Ss;
  spec.orders = PolyOrders::stateSpace(8);
  const auto scan = OrderScanOptions::fromSpec(spec, &why);
  ASSERT_TRUE(scan) << why;
  EXPECT_EQ(scan->maxStateOrder, 8);
  const OrderScan r = scanOrders(o, *scan);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.rows.empty());
  ASSERT_TRUE(r.stateSpace);
  EXPECT_EQ(r.stateSpace->chosenOrder, 5) << r.stateSpace->orderReason;
  EXPECT_EQ(r.stateSpace->orders.size(), 8u);
  spec.structure = PolyStructure::Oe;
  spec.orders = PolyOrders{0, 2, 0, 0, 2, 1};
  EXPECT_FALSE(OrderScanOptions::fromSpec(spec, &why));
  EXPECT_NE(why.find("arx:NA,NB,NK"), std::string::npos) << why;
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

// An estimate whose G is unstable simulates to a finite but absurd size on a long log (a
// pole at 1.02 grows by 1e17 over 2000 samples): Compare and the fit call that diverged
// instead of printing a fit % of -1e30.
TEST(ModelOutput, AnOutputFarBeyondTheDataDiverges) {
  const Poly one{1.0}, b{0.0, 1.0, 0.5}, f{1.0, -1.5, 0.7};
  const testing::SimData s = testing::simulateSystem(one, b, one, one, f, 2000, 0.3, 4);
  auto log = testing::torqueVelocityLog(s.u, s.y, 1e-3);
  FitDataOptions fo;
  const PreparedData d = prepareFitData(*log, fo);
  ASSERT_TRUE(d.ok()) << d.message;
  auto unstable = std::make_shared<PolynomialModel>(PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 1, 1}, 1e-3));
  unstable->b = {0.0, 1.0, 0.5};
  unstable->f = {1.0, -1.02};
  EvaluatedModel m;
  m.name = "unstable";
  m.polynomial = unstable;
  const SampleRange whole{0, static_cast<std::size_t>(d.u.size())};
  const ModelSignal out = modelOutput(m, d, whole, FitBasis{});
  EXPECT_FALSE(out.ok());
  EXPECT_EQ(out.failure, SignalFailure::Diverged);
  EXPECT_NE(out.message.find("diverges"), std::string::npos) << out.message;
  // A stable one of the same size is compared as before.
  unstable->f = {1.0, -0.98};
  EXPECT_TRUE(modelOutput(m, d, whole, FitBasis{}).ok());
}

}  // namespace
}  // namespace flexarm
