// Confidence regions of poles and zeros (core/ident/pole_zero_regions.h): on a Monte-Carlo of
// simulated OE estimates the 99 % regions hold the true pole and zero at their level; a
// physical estimate's regions sit on its poles and grow with its covariance.
#include <gtest/gtest.h>

#include "core/ident/blackbox.h"
#include "core/ident/pole_zero_regions.h"
#include "core/models/analysis.h"
#include "tests/core/ident/sim_helpers.h"

namespace flexarm {
namespace {

TEST(PoleZeroRegions, HoldTheTruthOfOeEstimatesAtTheirLevel) {
  const Poly one{1.0}, b{0.0, 1.0, 0.5}, f{1.0, -1.5, 0.7};
  const std::complex<double> pole(0.75, std::sqrt(0.7 - 0.75 * 0.75)), zero(-0.5, 0.0);
  int poleMisses = 0, zeroMisses = 0;
  const int runs = 150;
  for (int seed = 1; seed <= runs; ++seed) {
    const testing::SimData s = testing::simulateSystem(one, b, one, one, f, 800, 0.5, static_cast<unsigned>(seed));
    const PolyEstimate e = oe(s.u, s.y, 2, 2, 1);
    ASSERT_TRUE(e.summary.ok());
    const auto regions = poleZeroRegions(nullptr, {}, {}, &e.model, 0.99);
    ASSERT_EQ(regions.size(), 3u);  // two poles, one zero
    const RootRegion* upper = nullptr;
    const RootRegion* z = nullptr;
    for (const auto& r : regions) {
      if (!r.zero && r.value.imag() > 0.0) upper = &r;
      if (r.zero) z = &r;
    }
    ASSERT_TRUE(upper && z);
    EXPECT_GT(upper->covariance.determinant(), 0.0);  // a complex pole: a true ellipse
    EXPECT_NEAR(z->covariance(1, 1), 0.0, 1e-12);      // a real zero stays on the axis
    poleMisses += !upper->contains(pole);
    zeroMisses += !z->contains(zero);
  }
  ::testing::Test::RecordProperty("pole_misses", poleMisses);
  ::testing::Test::RecordProperty("zero_misses", zeroMisses);
  // 1 % of 150 is 1.5: a region too small misses far more often.
  EXPECT_LE(poleMisses, 6);
  EXPECT_LE(zeroMisses, 6);
}

TEST(PoleZeroRegions, APhysicalEstimatesRegionsSitOnItsPoles) {
  const auto model = makeModel("two-mass");
  const int ka = model->indexOf("k_a");
  ASSERT_GE(ka, 0);
  const double v = model->parameters()[static_cast<std::size_t>(ka)].value;
  Eigen::MatrixXd P(1, 1);
  P(0, 0) = (0.02 * v) * (0.02 * v);
  const auto regions = poleZeroRegions(model.get(), P, {ka}, nullptr, 0.99);
  const auto p = poles(model->stateSpace());
  std::size_t nPoles = 0;
  for (const auto& r : regions) nPoles += !r.zero;
  ASSERT_EQ(nPoles, p.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_LT(std::abs(regions[i].value - p[i]), 1e-9 * std::abs(p[i]) + 1e-12);
  // The resonance moves with the stiffness: its region is not a point, and a wider covariance
  // gives a wider one; the boundary is closed around the pole.
  const RootRegion* res = nullptr;
  for (const auto& r : regions)
    if (!r.zero && r.value.imag() > 1.0) res = &r;
  ASSERT_TRUE(res);
  EXPECT_GT(res->covariance.trace(), 0.0);
  const auto edge = res->boundary(16);
  ASSERT_EQ(edge.size(), 17u);
  EXPECT_LT(std::abs(edge.front() - edge.back()), 1e-9 * std::abs(res->value));
  EXPECT_TRUE(res->contains(res->value));
  std::complex<double> far = edge.front();  // the boundary point farthest out
  for (const auto& z : edge)
    if (std::abs(z - res->value) > std::abs(far - res->value)) far = z;
  EXPECT_GT(std::abs(far - res->value), 0.0);
  EXPECT_TRUE(res->contains(res->value + 0.9 * (far - res->value)));
  EXPECT_FALSE(res->contains(res->value + 1.1 * (far - res->value)));
  // Off the line the one parameter moves it along: outside however close.
  const std::complex<double> across = (far - res->value) * std::complex<double>(0.0, 1.0);
  EXPECT_FALSE(res->contains(res->value + 0.01 * across));
  EXPECT_TRUE(poleZeroRegions(model.get(), {}, {}, nullptr).empty());
}

}  // namespace
}  // namespace flexarm
