// Discretization with zero- and first-order hold against a fine-step simulation with the same
// input, and zeros of a system with relative degree two.
#include <gtest/gtest.h>

#include <cmath>

#include "core/models/analysis.h"
#include "core/models/physical_models.h"

namespace flexarm {
namespace {

// Integrates x' = Ax + b u(t) with classical Runge-Kutta (steps per sample) and returns the
// output at every sample; u(t) is held (zoh) or interpolated (foh) between samples.
std::vector<double> fineSimulation(const StateSpace& s, const std::vector<double>& u, double T,
                                   bool linear, int steps) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.states());
  std::vector<double> y;
  const double h = T / steps;
  for (std::size_t k = 0; k < u.size(); ++k) {
    y.push_back((s.C * x)(0) + s.D(0, 0) * u[k]);
    if (k + 1 == u.size()) break;
    auto input = [&](double tau) { return linear ? u[k] + (u[k + 1] - u[k]) * tau / T : u[k]; };
    for (int i = 0; i < steps; ++i) {
      const double t = i * h;
      auto f = [&](const Eigen::VectorXd& z, double tt) {
        return Eigen::VectorXd(s.A * z + s.B.col(0) * input(tt));
      };
      const Eigen::VectorXd k1 = f(x, t), k2 = f(x + h / 2 * k1, t + h / 2),
                            k3 = f(x + h / 2 * k2, t + h / 2), k4 = f(x + h * k3, t + h);
      x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
  }
  return y;
}

std::vector<double> discreteSimulation(const StateSpace& d, const std::vector<double>& u) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.states());
  std::vector<double> y;
  for (double uk : u) {
    y.push_back((d.C * x)(0) + d.D(0, 0) * uk);
    x = d.A * x + d.B.col(0) * uk;
  }
  return y;
}

void checkHold(Discretization method) {
  auto m = makeModel("three-mass");
  const StateSpace c = m->stateSpace();
  const double T = 1e-3;
  std::vector<double> u;
  for (int k = 0; k < 400; ++k) u.push_back(std::sin(0.05 * k) + 0.5 * std::cos(0.37 * k));
  const bool linear = method == Discretization::FirstOrderHold;
  // The discrete model's state for FOH is shifted by G2 u: start from rest with u(0) = 0.
  u[0] = 0.0;
  const auto fine = fineSimulation(c, u, T, linear, 200);
  const auto disc = discreteSimulation(discretize(c, T, method), u);
  double maxAbs = 0.0, maxErr = 0.0;
  for (std::size_t k = 0; k < u.size(); ++k) {
    maxAbs = std::max(maxAbs, std::abs(fine[k]));
    maxErr = std::max(maxErr, std::abs(fine[k] - disc[k]));
  }
  EXPECT_GT(maxAbs, 1.0);
  EXPECT_LT(maxErr, 1e-8 * maxAbs) << toString(method);
  // The other hold is measurably different: the check can fail.
  const auto other = discreteSimulation(
      discretize(c, T, linear ? Discretization::ZeroOrderHold : Discretization::FirstOrderHold),
      u);
  double diff = 0.0;
  for (std::size_t k = 0; k < u.size(); ++k) diff = std::max(diff, std::abs(fine[k] - other[k]));
  EXPECT_GT(diff, 1e-3 * maxAbs);
}

TEST(Analysis, ZeroOrderHoldMatchesFineSimulation) { checkHold(Discretization::ZeroOrderHold); }
TEST(Analysis, FirstOrderHoldMatchesFineSimulation) { checkHold(Discretization::FirstOrderHold); }

TEST(Analysis, ZerosOfRelativeDegreeTwo) {
  // Motor angle output: the zeros are those of the velocity model, the pole at 0 is added.
  ModelOptions o;
  o.output = ModelOutput::MotorAngle;
  auto pos = makeModel("three-mass", o);
  auto vel = makeModel("three-mass");
  auto zp = zeros(pos->stateSpace());
  auto zv = zeros(vel->stateSpace());
  ASSERT_EQ(zp.size(), 4u);
  ASSERT_EQ(zv.size(), 4u);
  auto key = [](std::complex<double> a, std::complex<double> b) {
    return a.imag() < b.imag() || (a.imag() == b.imag() && a.real() < b.real());
  };
  std::sort(zp.begin(), zp.end(), key);
  std::sort(zv.begin(), zv.end(), key);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(std::abs(zp[i] - zv[i]), 0.0, 1e-6);
  const auto ps = poles(pos->stateSpace());
  double smallest = 1e300;
  for (const auto& p : ps) smallest = std::min(smallest, std::abs(p));
  EXPECT_LT(smallest, 1e-9);
}

TEST(Analysis, DiscretizeRejectsMisuse) {
  auto m = makeModel("two-mass");
  EXPECT_THROW(discretize(m->stateSpace(), 0.0), std::invalid_argument);
  auto d = discretize(m->stateSpace(), 1e-3);
  EXPECT_THROW(discretize(d, 1e-3), std::invalid_argument);
  EXPECT_EQ(discretizationFromString("foh"), Discretization::FirstOrderHold);
  EXPECT_FALSE(discretizationFromString("tustin").has_value());
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

// FlexArm's one definition of notches and peaks: the extrema of |G(i w)|, refined on the
// exact response, so that any grid gives the same frequency. For Table 5.2 the notch lies
// at (5.4)'s sqrt(k/J_a) = 111.8 rad/s; the peak of the well damped resonance (zeta = 0.2)
// lies at 160.8 rad/s, above the pole's imaginary part 143.4 rad/s that a root list gives.
TEST(Analysis, NotchesAndPeaksAreExtremaOfTheMagnitude) {
  const StateSpace sys = makeModel("two-mass")->stateSpace();
  const NotchesPeaks np = notchesAndPeaks(sys);
  ASSERT_EQ(np.notches.size(), 1u);
  ASSERT_EQ(np.peaks.size(), 1u);
  EXPECT_NEAR(np.notches[0], std::sqrt(1.5e5 / 12.0), 0.2);
  EXPECT_NEAR(np.peaks[0], 160.78, 0.01);
  EXPECT_NEAR(peakFrequencies(sys).at(0).frequency, 143.35, 0.01);
  auto mag = [&](double w) { return std::abs(frequencyResponse(sys, std::vector<double>{w}).front()); };
  for (double f : {1.0 - 1e-4, 1.0 + 1e-4}) {
    EXPECT_GT(mag(np.notches[0] * f), mag(np.notches[0]));
    EXPECT_LT(mag(np.peaks[0] * f), mag(np.peaks[0]));
  }
  // Two different grids, the same frequencies.
  for (int points : {37, 501}) {
    std::vector<double> w(points), m(points);
    for (int i = 0; i < points; ++i) {
      w[i] = 20.0 * std::pow(50.0, static_cast<double>(i) / (points - 1));
      m[i] = mag(w[i]);
    }
    const NotchesPeaks g = magnitudeExtrema(w, m, 1.0, mag);
    ASSERT_EQ(g.notches.size(), 1u) << points;
    ASSERT_EQ(g.peaks.size(), 1u) << points;
    EXPECT_NEAR(g.notches[0] / np.notches[0], 1.0, 1e-6) << points;
    EXPECT_NEAR(g.peaks[0] / np.peaks[0], 1.0, 1e-6) << points;  // a flat maximum: sqrt(eps)
  }
}

}  // namespace
}  // namespace flexarm
