// LQG design of chapter 8 against the seed's Section 8.3 and 8.7, and the transfer-function
// identities (8.19)-(8.22), (8.36).
#include "core/control/lqg.h"

#include <gtest/gtest.h>

#include "core/control/frequency_response.h"

namespace flexarm {
namespace {

TEST(Lqg, SeedCasesGiveStableAndUnstableRegulators) {
  const LqgDesign i = designLqg(LqgOptions::seedCaseI());
  const LqgDesign ii = designLqg(LqgOptions::seedCaseII());
  const LqgDesign acc = designLqg(LqgOptions::seedAccelerationFeedback());
  for (const LqgDesign* d : {&i, &ii, &acc}) {
    ASSERT_TRUE(d->ok()) << d->message;
    EXPECT_LT(d->lqrResidual, 1e-12);
    EXPECT_LT(d->kalmanResidual, 1e-12);
    EXPECT_EQ(d->rhpClosedLoopPoles, 0);
    EXPECT_EQ(d->closedLoopPoles.size(), 9);
  }
  // Section 8.3: case (i) stable, case (ii) F_y has two poles in the right half plane.
  EXPECT_EQ(i.rhpRegulatorPoles, 0);
  EXPECT_EQ(ii.rhpRegulatorPoles, 2);
  EXPECT_EQ(ii.regulatorStability(), "the regulator is unstable: 2 poles in the RHP");
  EXPECT_EQ(i.regulatorStability(), "the regulator is stable");
  // Section 8.7: with the arm acceleration the regulator is stable again.
  EXPECT_EQ(acc.rhpRegulatorPoles, 0);
  // Same L in all three (only the estimator changes in Section 8.3).
  EXPECT_LT((i.L - ii.L).norm(), 1e-9 * i.L.norm());
  EXPECT_LT((i.L - acc.L).norm(), 1e-9 * i.L.norm());
}

TEST(Lqg, IntegralActionRemovesSteadyMotorErrorForConstantLoads) {
  for (const auto& o : {LqgOptions::seedCaseI(), LqgOptions::seedAccelerationFeedback()}) {
    const LqgDesign d = designLqg(o);
    ASSERT_TRUE(d.ok());
    const StateSpace cl = disturbanceClosedLoop(d);
    // Static gain -C A^-1 B from (w, v) to (phi_a, phi_m, u).
    const Eigen::MatrixXd dc = -cl.C * cl.A.partialPivLu().solve(cl.B);
    EXPECT_NEAR(dc(1, 0), 0.0, 1e-9);   // phi_m after a constant w
    EXPECT_NEAR(dc(1, 1), 0.0, 1e-9);   // phi_m after a constant v
    EXPECT_NEAR(dc(2, 0), -1.0, 1e-9);  // the torque cancels w
    EXPECT_NEAR(dc(2, 1), -1.0, 1e-9);  // and v
  }
}

TEST(Lqg, TransferFunctionIdentities) {
  using C = std::complex<double>;
  const LqgDesign d = designLqg(LqgOptions::seedCaseII());
  ASSERT_TRUE(d.ok());
  const TransferEvaluator G(plantTransfer(d)), Fy(regulatorFy(d)), Fr(regulatorFr(d)),
      Gc(closedLoopGc(d));
  for (double w : {0.3, 7.0, 23.0, 65.0, 400.0}) {
    const C s(0.0, w);
    const C loop = Fy.scalar(s) * G.scalar(s);
    const C S = 1.0 / (1.0 + loop);  // (8.36)
    // Absolute tolerance: at low frequency |S| ~ 1e-14 and (8.22) is a difference near 1.
    EXPECT_LT(std::abs(sensitivity822(d, s)(0, 0) - S), 1e-9 * std::max(1.0, std::abs(S))) << w;
    // With l_0 = 1 the servo transfer F_r G S (8.8) equals the state-feedback G_C (8.21).
    EXPECT_LT(std::abs(Fr.scalar(s) * G.scalar(s) * S - Gc.scalar(s)),
              1e-9 * std::abs(Gc.scalar(s)))
        << w;
  }
}

TEST(Lqg, TransferEvaluatorAgreesWithDirectSolve) {
  const LqgDesign d = designLqg(LqgOptions::seedAccelerationFeedback());
  ASSERT_TRUE(d.ok());
  const StateSpace fy = regulatorFy(d);
  const TransferEvaluator ev(fy);
  for (double w : {0.1, 30.0, 1000.0}) {
    const std::complex<double> s(0.2, w);
    const Eigen::MatrixXcd direct =
        fy.C.cast<std::complex<double>>() *
        (s * Eigen::MatrixXcd::Identity(5, 5) - fy.A.cast<std::complex<double>>())
            .partialPivLu()
            .solve(fy.B.cast<std::complex<double>>());
    EXPECT_LT((ev(s) - direct).norm(), 1e-10 * direct.norm());
  }
}

TEST(Lqg, InvalidOptionsThrowWithReason) {
  LqgOptions o;
  o.q1 = Eigen::VectorXd::Ones(4);
  std::string why;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("Q1 needs 5"), std::string::npos) << why;
  EXPECT_THROW(designLqg(o), std::invalid_argument);
  o = LqgOptions::seedAccelerationFeedback();
  o.r2 = Eigen::VectorXd::Constant(1, 1e-8);
  EXPECT_FALSE(o.isValid(&why));
  o = LqgOptions();
  o.r2(0) = 0.0;
  EXPECT_FALSE(o.isValid(&why));
}

}  // namespace
}  // namespace flexarm
