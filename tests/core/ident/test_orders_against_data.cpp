// Orders, delays and FIR lengths are checked against the data before anything is allocated:
// what the sanitizers found (a negative QR row count for nk >= samples, bad_alloc for OE/BJ
// with the same gap, signed overflow of the parameter count, an int overflow of the FIR
// length) now ends as a sentence in the result.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>

#include "core/ident/blackbox.h"
#include "core/ident/closed_loop_pem.h"

namespace flexarm {
namespace {

Eigen::VectorXd signal(Eigen::Index n, double f) {
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = std::sin(f * static_cast<double>(i)) + 0.3 * std::cos(2.7 * f * i);
  return x;
}

TEST(OrdersAgainstData, ParameterCountNeverOverflows) {
  PolyOrders o;
  o.na = INT_MAX;
  o.nb = 1;
  EXPECT_EQ(o.parameters(), INT_MAX);
  std::string why;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("more than 2000 parameters"), std::string::npos) << why;
  o.na = 2;
  o.nk = INT_MAX;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("delay nk is more than"), std::string::npos) << why;
}

TEST(OrdersAgainstData, DelayBeyondTheSamplesEndsAsASentenceForEveryStructure) {
  const Eigen::VectorXd u = signal(500, 0.3), y = signal(500, 0.7);
  for (PolyStructure s : {PolyStructure::Arx, PolyStructure::Armax, PolyStructure::Oe, PolyStructure::Bj}) {
    SCOPED_TRACE(toString(s));
    PolyOrders o;
    o.na = s == PolyStructure::Arx || s == PolyStructure::Armax ? 2 : 0;
    o.nb = 2;
    o.nc = s == PolyStructure::Armax || s == PolyStructure::Bj ? 2 : 0;
    o.nd = s == PolyStructure::Bj ? 2 : 0;
    o.nf = s == PolyStructure::Oe || s == PolyStructure::Bj ? 2 : 0;
    o.nk = 500;
    const PolyEstimate r = estimatePolynomial(u, y, s, o);
    EXPECT_EQ(r.summary.termination, Termination::Failed);
    EXPECT_NE(r.summary.message.find("too few samples (500)"), std::string::npos) << r.summary.message;
    EXPECT_NE(r.summary.message.find("delay nk = 500"), std::string::npos) << r.summary.message;
  }
}

TEST(OrdersAgainstData, WorkBeyondTheLimitIsRefusedInWords) {
  PolyOrders o;
  o.nb = 1000;
  o.nf = 1000;
  std::string why;
  EXPECT_FALSE(o.fitsData(PolyStructure::Oe, 35000, &why));
  EXPECT_NE(why.find("oe with 2000 parameters on 35000 samples"), std::string::npos) << why;
  PolyOrders small;
  small.nb = 2;
  small.nf = 2;
  EXPECT_TRUE(small.fitsData(PolyStructure::Oe, 35000, &why)) << why;
  // The limit depends on the data: the same orders fit a shorter record.
  PolyOrders arx;
  arx.na = 100;
  arx.nb = 100;
  EXPECT_TRUE(arx.fitsData(PolyStructure::Arx, 100000, &why)) << why;
  EXPECT_FALSE(arx.fitsData(PolyStructure::Arx, 1000000, &why));
}

TEST(OrdersAgainstData, LongDelayGivesTheSameEstimateAsTheShiftedData) {
  // A pure delay of nk samples only shifts B: the leading zeros cost nothing and change nothing.
  const Eigen::Index n = 3000, k = 400;
  const Eigen::VectorXd u = signal(n, 0.21);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  for (Eigen::Index t = k + 1; t < n; ++t) y[t] = 0.6 * y[t - 1] + u[t - k] + 0.01 * std::sin(3.1 * t);
  const PolyEstimate r = oe(u, y, 1, 1, static_cast<int>(k));
  ASSERT_TRUE(r.summary.ok()) << r.summary.message;
  EXPECT_NEAR(r.model.b[static_cast<std::size_t>(k)], 1.0, 0.05);
  EXPECT_NEAR(r.model.f[1], -0.6, 0.05);
}

TEST(OrdersAgainstData, FirLengthFromATinySampleTimeDoesNotOverflow) {
  const Eigen::VectorXd u = signal(1000, 0.2), r = signal(1000, 0.05);
  const ReferenceProjection p = projectOnReference(u, r, 1e-12);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("too few samples (1000) for an FIR of 505000000001 taps"),
            std::string::npos) << p.message;
}

}  // namespace
}  // namespace flexarm
