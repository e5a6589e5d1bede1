// The cascade controller of Figure 5.1 identified from a closed-loop log of the simulator,
// which logs exactly what its controller computed: the gains come back to rounding, a torque
// the cascade does not explain is refused with the fit % it reached.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/ident/controller_ident.h"
#include "core/models/physical_models.h"
#include "core/sim/closed_loop.h"
#include "tests/core/ident/closed_loop_logs.h"

namespace flexarm {
namespace {

using testing::column;
using testing::twoMassLog;

TEST(ControllerIdent, RecoversTheSimulatorsCascadeAndExplainsTheTorque) {
  const auto log = twoMassLog(4.0, 3);
  const Eigen::VectorXd r = column(*log, columns::kAngleRef), a = column(*log, columns::kMotorAngle),
                        u = column(*log, columns::kTorqueRef);
  const ControllerIdentResult c = identifyController(r, a, u, log->sampleTime);
  ASSERT_TRUE(c.ok()) << c.message;
  // The log holds exactly what the controller computed (the torque before its noise, the
  // angle it read): the gains come back to rounding.
  EXPECT_NEAR(c.controller.kp, 40.0, 40.0 * 1e-6);
  EXPECT_NEAR(c.controller.kv, 0.3, 0.3 * 1e-6);
  EXPECT_NEAR(c.controller.ti, 0.05, 0.05 * 1e-6);
  EXPECT_NEAR(c.controller.rateHz, 2000.0, 1e-9);
  EXPECT_NEAR(c.offset, 0.0, 1e-9);
  EXPECT_GT(c.fitPercent, 99.999);
  EXPECT_NE(c.message.find("explains 100.000 % of the torque"), std::string::npos) << c.message;
  EXPECT_NEAR(controllerFitPercent(c.controller, r, a, u, log->sampleTime), c.fitPercent, 1e-6);

  // Cut from the middle of the log, the integral starts at a value of its own: the constant c.
  const Eigen::Index from = 3000, n = 4000;
  const ControllerIdentResult cut = identifyController(r.segment(from, n), a.segment(from, n), u.segment(from, n),
                                                       log->sampleTime);
  ASSERT_TRUE(cut.ok()) << cut.message;
  EXPECT_NEAR(cut.controller.kv, 0.3, 0.3 * 1e-6);
  EXPECT_NEAR(cut.controller.ti, 0.05, 0.05 * 1e-6);
  EXPECT_GT(std::abs(cut.offset), 1e-4);

  // A P velocity loop without integral action: T_i = 0 is found as such.
  ControllerOptions p;
  p.ti = 0.0;
  p.kv = 0.5;
  const auto plain = twoMassLog(3.0, 4, false, p);
  const ControllerIdentResult cp =
      identifyController(column(*plain, columns::kAngleRef), column(*plain, columns::kMotorAngle),
                         column(*plain, columns::kTorqueRef), plain->sampleTime);
  ASSERT_TRUE(cp.ok()) << cp.message;
  EXPECT_EQ(cp.controller.ti, 0.0);
  EXPECT_NEAR(cp.controller.kv, 0.5, 0.5 * 1e-6);
  EXPECT_NE(cp.message.find("no integral action"), std::string::npos) << cp.message;
}

TEST(ControllerIdent, RefusesATorqueItDoesNotExplainAndMisuse) {
  const auto log = twoMassLog(4.0, 3);
  const Eigen::VectorXd r = column(*log, columns::kAngleRef), a = column(*log, columns::kMotorAngle);
  Eigen::VectorXd u = column(*log, columns::kTorqueRef);
  // A feedforward torque the cascade knows nothing of, as large as the controller's own.
  const double rms = std::sqrt(u.squaredNorm() / static_cast<double>(u.size()));
  for (Eigen::Index k = 0; k < u.size(); ++k) u[k] += rms * std::sin(2.0 * M_PI * 3.0 * static_cast<double>(k) * log->sampleTime);
  const ControllerIdentResult c = identifyController(r, a, u, log->sampleTime);
  EXPECT_EQ(c.termination, Termination::Failed);
  EXPECT_LT(c.fitPercent, 99.0);
  EXPECT_NE(c.message.find("explains only"), std::string::npos) << c.message;
  EXPECT_NE(c.message.find("99 % needed"), std::string::npos) << c.message;

  const ControllerIdentResult flat = identifyController(Eigen::VectorXd::Zero(500), Eigen::VectorXd::Zero(500),
                                                        Eigen::VectorXd::Zero(500), 0.0005);
  EXPECT_EQ(flat.termination, Termination::Failed);
  EXPECT_NE(flat.message.find("does not move"), std::string::npos) << flat.message;
  ControllerIdentOptions bad;
  bad.minimumFitPercent = 120.0;
  EXPECT_THROW(identifyController(r, a, u, log->sampleTime, bad), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
