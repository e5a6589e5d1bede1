// The physical models against the seed's printed matrices (3.10), (3.13), (3.21), (3.22),
// the transfer function (3.14), the parameterization (5.5), and finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/models/analysis.h"
#include "core/models/physical_models.h"

namespace flexarm {
namespace {

// Sets every parameter except r and k_T to a random value within +-50 % of its default.
void randomize(PhysicalModel& m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.5, 1.5);
  for (const auto& p : m.parameters())
    if (p.free) m.setParameter(p.name, p.value * u(rng));
}

void expectMatrixNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double rel) {
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), b.cols());
  for (int i = 0; i < a.rows(); ++i)
    for (int j = 0; j < a.cols(); ++j)
      EXPECT_NEAR(a(i, j), b(i, j), rel * std::max(1.0, std::abs(b(i, j))))
          << "entry (" << i << "," << j << ")";
}

TEST(PhysicalModels, RigidMatchesEquation310) {
  std::mt19937_64 rng(1);
  auto m = makeModel("rigid");
  randomize(*m, rng);
  const double J = m->value("J_m") + std::pow(m->value("r"), 2) * m->value("J_a");
  const auto ss = m->stateSpace();
  EXPECT_DOUBLE_EQ(ss.A(0, 0), -m->value("f_m") / J);
  EXPECT_DOUBLE_EQ(ss.B(0, 0), m->value("k_T") / J);
  EXPECT_EQ(ss.C(0, 0), 1.0);
}

TEST(PhysicalModels, TwoMassMatchesEquation313) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    auto m = makeModel("two-mass");
    randomize(*m, rng);
    const double Jm = m->value("J_m"), Ja = m->value("J_a"), fm = m->value("f_m"),
                 k = m->value("k_a"), d = m->value("d_a"), r = m->value("r"),
                 kT = m->value("k_T");
    Eigen::MatrixXd A(3, 3);
    A << 0, r, -1, -r * k / Jm, -(fm + r * r * d) / Jm, r * d / Jm, k / Ja, r * d / Ja, -d / Ja;
    Eigen::MatrixXd B(3, 1), C(1, 3);
    B << 0, kT / Jm, 0;
    C << 0, 1, 0;
    const auto ss = m->stateSpace();
    expectMatrixNear(ss.A, A, 1e-14);
    expectMatrixNear(ss.B, B, 1e-14);
    expectMatrixNear(ss.C, C, 0.0);
    EXPECT_EQ(ss.D(0, 0), 0.0);
  }
}

TEST(PhysicalModels, ThreeMassMatchesEquation321) {
  std::mt19937_64 rng(3);
  auto m = makeModel("three-mass");
  randomize(*m, rng);
  const double Jm = m->value("J_m"), Jg = m->value("J_g"), Ja = m->value("J_a"),
               fm = m->value("f_m"), kg = m->value("k_g"), ka = m->value("k_a"),
               dg = m->value("d_g"), da = m->value("d_a"), r = m->value("r");
  Eigen::MatrixXd A(5, 5);
  A << 0, 0, r, -1, 0,                                                       //
      0, 0, 0, 1, -1,                                                        //
      -kg * r / Jm, 0, -(fm + dg * r * r) / Jm, dg * r / Jm, 0,              //
      kg / Jg, -ka / Jg, dg * r / Jg, -(dg + da) / Jg, da / Jg,              //
      0, ka / Ja, 0, da / Ja, -da / Ja;
  expectMatrixNear(m->stateSpace().A, A, 1e-14);
  EXPECT_DOUBLE_EQ(m->stateSpace().B(2, 0), 1.0 / Jm);
  EXPECT_EQ(m->stateSpace().C(0, 2), 1.0);
}

TEST(PhysicalModels, FourMassMatchesEquation322) {
  std::mt19937_64 rng(4);
  auto m = makeModel("four-mass");
  randomize(*m, rng);
  auto v = [&m](const char* n) { return m->value(n); };
  const double Jm = v("J_m"), Jg = v("J_g"), Ja = v("J_a"), Jp = v("J_p"), fm = v("f_m"),
               kg = v("k_g"), ka = v("k_a"), kp = v("k_p"), dg = v("d_g"), da = v("d_a"),
               dp = v("d_p"), r = v("r");
  Eigen::MatrixXd A(7, 7);
  A << 0, 0, 0, r, -1, 0, 0,                                                          //
      0, 0, 0, 0, 1, -1, 0,                                                           //
      0, 0, 0, 0, 1, 0, -1,                                                           //
      -kg * r / Jm, 0, 0, -(fm + dg * r * r) / Jm, dg * r / Jm, 0, 0,                 //
      kg / Jg, -ka / Jg, -kp / Jg, dg * r / Jg, -(dg + da + dp) / Jg, da / Jg, dp / Jg,  //
      0, ka / Ja, 0, 0, da / Ja, -da / Ja, 0,                                         //
      0, 0, kp / Jp, 0, dp / Jp, 0, -dp / Jp;
  expectMatrixNear(m->stateSpace().A, A, 1e-14);
  EXPECT_DOUBLE_EQ(m->stateSpace().B(3, 0), 1.0 / Jm);
  EXPECT_EQ(m->stateSpace().C(0, 3), 1.0);
}

TEST(PhysicalModels, TorqueGainScalesB) {
  auto m = makeModel("three-mass");
  const double b = m->stateSpace().B(2, 0);
  m->setParameter("k_T", 1.2);
  EXPECT_DOUBLE_EQ(m->stateSpace().B(2, 0), 1.2 * b);
  EXPECT_FALSE(m->parameters()[static_cast<std::size_t>(m->indexOf("k_T"))].free);
  EXPECT_FALSE(m->parameters()[static_cast<std::size_t>(m->indexOf("r"))].free);
  EXPECT_DOUBLE_EQ(m->value("r"), 1.0 / 118.0);
}

TEST(PhysicalModels, MotorAngleOutputAddsIntegrator) {
  ModelOptions o;
  o.output = ModelOutput::MotorAngle;
  o.armAcceleration = true;
  auto m = makeModel("two-mass", o);
  const auto ss = m->stateSpace();
  ASSERT_EQ(ss.states(), 4);
  ASSERT_EQ(ss.outputs(), 2);
  EXPECT_EQ(ss.A(3, 1), 1.0);  // phi_m' = x_2
  EXPECT_EQ(ss.C(0, 3), 1.0);
  // Arm acceleration: (3.12) solved for phi_a''.
  const double Ja = m->value("J_a"), k = m->value("k_a"), d = m->value("d_a"),
               r = m->value("r");
  EXPECT_DOUBLE_EQ(ss.C(1, 0), k / Ja);
  EXPECT_DOUBLE_EQ(ss.C(1, 1), r * d / Ja);
  EXPECT_DOUBLE_EQ(ss.C(1, 2), -d / Ja);
  // Position transfer function = velocity transfer function / s.
  auto vel = makeModel("two-mass");
  const std::complex<double> s(0.0, 37.0);
  const auto gv = transferFunction(vel->stateSpace())(s);
  const auto gp = transferFunction(ss)(s);
  EXPECT_NEAR(std::abs(gp * s - gv), 0.0, 1e-9 * std::abs(gv));
}

TEST(PhysicalModels, TransferFunctionIsEquation314) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    auto m = makeModel("two-mass");
    randomize(*m, rng);
    const double Jm = m->value("J_m"), Ja = m->value("J_a"), fm = m->value("f_m"),
                 k = m->value("k_a"), d = m->value("d_a"), r = m->value("r");
    const double lead = Ja * Jm;
    const std::vector<double> num = {Ja / lead, d / lead, k / lead};
    const std::vector<double> den = {1.0, (Ja * fm + d * (Jm + r * r * Ja)) / lead,
                                     (k * (Jm + r * r * Ja) + d * fm) / lead, k * fm / lead};
    const auto tf = transferFunction(m->stateSpace());
    ASSERT_EQ(tf.num.size(), 3u);
    ASSERT_EQ(tf.den.size(), 4u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(tf.num[i], num[i], 1e-9 * std::abs(num[i]));
    for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(tf.den[i], den[i], 1e-9 * std::abs(den[i]));
    // And the frequency response is C(i w I - A)^-1 B.
    const auto h = frequencyResponse(m->stateSpace(), {50.0, 150.0});
    EXPECT_NEAR(std::abs(h[1] - tf({0.0, 150.0})), 0.0, 1e-9 * std::abs(h[1]));
  }
}

TEST(PhysicalModels, Table52NotchIsEquation54) {
  auto m = makeModel("two-mass");  // Table 5.2 defaults
  const auto notches = notchFrequencies(m->stateSpace());
  ASSERT_EQ(notches.size(), 1u);
  const double k = 1.5e5, Ja = 12.0, d = 70.0;
  const double im = std::sqrt(k / Ja - std::pow(d / (2 * Ja), 2));  // (5.4), exact
  EXPECT_NEAR(notches[0].frequency, im, 1e-6 * im);
  EXPECT_NEAR(notches[0].frequency, 112.0, 0.5);  // the seed's printed value
  EXPECT_EQ(peakFrequencies(m->stateSpace()).size(), 1u);
}

TEST(PhysicalModels, ThreeMassP6MatchesTable55) {
  auto m = makeModel("three-mass");  // Table 5.7 p6
  const auto n = notchFrequencies(m->stateSpace());
  const auto p = peakFrequencies(m->stateSpace());
  ASSERT_EQ(n.size(), 2u);
  ASSERT_EQ(p.size(), 2u);
  // Table 5.5, p6: 107.3, 157, 183, 209 rad/s (read from Bode plots; the printed parameters
  // are rounded to three digits).
  EXPECT_NEAR(n[0].frequency, 107.3, 0.02 * 107.3);
  EXPECT_NEAR(p[0].frequency, 157.0, 0.02 * 157.0);
  EXPECT_NEAR(n[1].frequency, 183.0, 0.02 * 183.0);
  EXPECT_NEAR(p[1].frequency, 209.0, 0.02 * 209.0);
}

TEST(PhysicalModels, FourMassAddsAResonance) {
  const auto p3 = peakFrequencies(makeModel("three-mass")->stateSpace());
  const auto p4 = peakFrequencies(makeModel("four-mass")->stateSpace());
  EXPECT_EQ(p4.size(), p3.size() + 1);
}

TEST(PhysicalModels, EveryDerivativeMatchesCentralDifference) {
  ModelOptions o;
  o.output = ModelOutput::MotorAngle;
  o.armAcceleration = true;
  for (const auto& name : modelStructureNames()) {
    for (bool extended : {false, true}) {
      auto m = makeModel(name, extended ? o : ModelOptions{});
      for (int i = 0; i < static_cast<int>(m->parameters().size()); ++i) {
        const auto p = m->parameters()[static_cast<std::size_t>(i)];
        const double h = 1e-6 * std::abs(p.value);
        auto plus = makeModel(name, m->options());
        auto minus = makeModel(name, m->options());
        plus->setParameter(p.name, p.value + h);
        minus->setParameter(p.name, p.value - h);
        const auto sp = plus->stateSpace(), sm = minus->stateSpace();
        const auto d = m->derivative(i);
        auto check = [&](const Eigen::MatrixXd& an, const Eigen::MatrixXd& fp,
                         const Eigen::MatrixXd& fm, const char* which) {
          const Eigen::MatrixXd fd = (fp - fm) / (2 * h);
          ASSERT_EQ(an.rows(), fd.rows());
          // Truncation error relative to the derivative plus the rounding error of the
          // difference quotient, about eps |M| / h.
          const double scale = std::max(fd.cwiseAbs().maxCoeff(), an.cwiseAbs().maxCoeff());
          const double rounding = 1e-14 * fp.cwiseAbs().maxCoeff() / h;
          EXPECT_LE((an - fd).cwiseAbs().maxCoeff(), 1e-6 * scale + rounding)
              << name << " d" << which << "/d" << p.name;
        };
        check(d.dA, sp.A, sm.A, "A");
        check(d.dB, sp.B, sm.B, "B");
        check(d.dC, sp.C, sm.C, "C");
        check(d.dD, sp.D, sm.D, "D");
      }
    }
  }
}

TEST(PhysicalModels, ThetaParameterizationIsEquation55) {
  auto two = makeModel("two-mass");
  auto theta = makeModel("two-mass-theta");
  expectMatrixNear(theta->stateSpace().A, two->stateSpace().A, 1e-12);
  expectMatrixNear(theta->stateSpace().B, two->stateSpace().B, 1e-12);
  // (5.6): most theta appear by themselves in A (rows 2 and 3 with the sign (5.5) gives).
  const auto A = theta->stateSpace().A;
  auto t = [&theta](int i) { return theta->parameters()[static_cast<std::size_t>(i)].value; };
  const double r = theta->value("r");
  EXPECT_NEAR(A(1, 0), -r * t(0), 1e-9 * r * t(0));
  EXPECT_NEAR(A(1, 1), -t(4), 1e-12 * t(4));
  EXPECT_NEAR(A(1, 2), r * t(0) * t(3) / t(1), 1e-9 * r * t(0) * t(3) / t(1));
  EXPECT_NEAR(A(2, 0), t(1), 1e-12 * t(1));
  EXPECT_NEAR(A(2, 1), r * t(3), 1e-12 * r * t(3));
  EXPECT_NEAR(A(2, 2), -t(3), 1e-12 * t(3));
  double th[5];
  thetaFromTwoMass({1e-3, 10.0, 0.2, 2e5, 50.0}, r, th);
  const auto back = twoMassFromTheta(th, r);
  EXPECT_NEAR(back.J_m, 1e-3, 1e-15);
  EXPECT_NEAR(back.J_a, 10.0, 1e-10);
  EXPECT_NEAR(back.f_m, 0.2, 1e-12);
  EXPECT_NEAR(back.k, 2e5, 1e-6);
  EXPECT_NEAR(back.d, 50.0, 1e-10);
}

TEST(PhysicalModels, AddMassKeepsTotalInertia) {
  auto two = makeModel("two-mass");
  auto three = addMass(*two, 0.2, 300.0);
  ASSERT_TRUE(three);
  EXPECT_EQ(three->structureName(), "three-mass");
  EXPECT_NEAR(three->value("J_g") + three->value("J_a"), two->value("J_a"), 1e-12);
  EXPECT_NEAR(std::sqrt(three->value("k_a") / three->value("J_a")), 300.0, 1e-9);
  // Same low-frequency behaviour: the DC gain of motor velocity is k_T / f_m for both.
  const auto g2 = frequencyResponse(two->stateSpace(), {1e-4})[0];
  const auto g3 = frequencyResponse(three->stateSpace(), {1e-4})[0];
  EXPECT_NEAR(std::abs(g2 - g3), 0.0, 1e-6 * std::abs(g2));
  EXPECT_EQ(addMass(*makeModel("rigid"), 0.2, 100.0)->structureName(), "two-mass");
  EXPECT_EQ(addMass(*three, 0.2, 300.0)->structureName(), "four-mass");
  EXPECT_EQ(addMass(*makeModel("four-mass"), 0.2, 300.0), nullptr);
}

TEST(PhysicalModels, BadInputThrows) {
  auto m = makeModel("two-mass");
  EXPECT_THROW(m->setParameter("k_g", 1.0), std::invalid_argument);
  EXPECT_THROW(m->setParameter("J_m", 0.0), std::invalid_argument);
  EXPECT_THROW(m->setParameter("J_m", std::nan("")), std::invalid_argument);
  EXPECT_THROW(makeModel("five-mass"), std::invalid_argument);
  EXPECT_THROW(m->derivative(99), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
