// The masses' angles along a log: under a constant torque each spring carries exactly the
// torque that accelerates the masses beyond it (the static deflections of (3.18) and (3.22)),
// the motor angle agrees with the model's own ZOH simulation, the measured motor angle is
// kept, and cancel / no torque / divergence end with a sentence.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ident/pem.h"
#include "core/sim/body_angles.h"

namespace flexarm {
namespace {

IdData torqueLog(std::vector<double> torque, double Ts) {
  IdData d;
  d.sampleTime = Ts;
  d.setChannel({columns::kTorqueRef, "N m", ChannelRole::Input, std::move(torque)});
  return d;
}

// A model with no motor friction: a constant torque accelerates it uniformly, so in steady
// state every spring carries the inertia beyond it times its acceleration.
std::unique_ptr<PhysicalModel> frictionless(const char* structure) {
  auto m = makeModel(structure);
  m->setParameter("f_m", 0.0);
  if (m->indexOf("d_g") >= 0) m->setParameter("d_g", 62.0);  // a damped transient
  return m;
}

TEST(BodyAngles, TwoMassSpringCarriesTheArmUnderConstantTorque) {
  auto m = frictionless("two-mass");
  const double tau = 2.0, Ts = 1e-3;
  const BodyAngles b = simulateBodyAngles(*m, {}, torqueLog(std::vector<double>(8000, tau), Ts));
  ASSERT_EQ(b.termination, Termination::Converged) << b.message;
  EXPECT_EQ(b.springs, 1);
  EXPECT_EQ(b.motorAngleSource, MotorAngleSource::Simulated);  // the log has no angle
  const double r = m->value("r"), Jm = m->value("J_m"), Ja = m->value("J_a");
  // Arm acceleration r tau / (J_m + r^2 J_a); the spring carries J_a times it: (3.12).
  const double alpha = r * tau / (Jm + r * r * Ja);
  const double expected = Ja * alpha / m->value("k_a");
  const BodyPose end = b.at(b.samples() - 1);
  EXPECT_NEAR(end.gearDeflection, expected, 1e-3 * expected);
  EXPECT_TRUE(b.armDeflection.empty());
  EXPECT_EQ(end.arm, end.gear);  // two-mass: one spring, phi_g is phi_a
  EXPECT_NEAR(end.gearInput - end.arm, end.gearDeflection, 1e-12 * end.gearInput);
  // The motor angle grows as alpha / r t^2 / 2 (plus the start-up transient's small offset).
  const double t = (b.samples() - 1) * Ts;
  EXPECT_NEAR(end.motor, 0.5 * alpha / r * t * t, 1e-3 * end.motor);
}

TEST(BodyAngles, ThreeAndFourMassSpringsCarryWhatLiesBeyondThem) {
  for (const char* s : {"three-mass", "four-mass"}) {
    SCOPED_TRACE(s);
    auto m = frictionless(s);
    const bool four = std::string(s) == "four-mass";
    const double tau = 1.5, Ts = 1e-3;
    const BodyAngles b = simulateBodyAngles(*m, {}, torqueLog(std::vector<double>(10000, tau), Ts));
    ASSERT_EQ(b.termination, Termination::Converged) << b.message;
    EXPECT_EQ(b.springs, four ? 3 : 2);
    const double r = m->value("r"), Jg = m->value("J_g"), Ja = m->value("J_a");
    const double Jp = four ? m->value("J_p") : 0.0;
    const double alpha = r * tau / (m->value("J_m") + r * r * (Jg + Ja + Jp));
    const BodyPose p = b.at(b.samples() - 1);
    // (3.18): k_g x1 accelerates J_g, J_a (and J_p); k_a x2 accelerates J_a; (3.22) k_p x3 J_p.
    const double x1 = (Jg + Ja + Jp) * alpha / m->value("k_g");
    const double x2 = Ja * alpha / m->value("k_a");
    EXPECT_NEAR(p.gearDeflection, x1, 2e-3 * x1);
    EXPECT_NEAR(p.armDeflection, x2, 2e-3 * x2);
    EXPECT_NEAR(p.gear, p.gearInput - x1, 2e-3 * x1);
    EXPECT_NEAR(p.arm, p.gearInput - x1 - x2, 2e-3 * (x1 + x2));
    if (four) {
      const double x3 = Jp * alpha / m->value("k_p");
      EXPECT_NEAR(p.parallelDeflection, x3, 2e-3 * x3);
      // The step rings the lightly damped parallel mass (zeta 0.02): it swings past x3.
      EXPECT_GT(b.maxParallelDeflection, 1.2 * x3);
    } else {
      EXPECT_TRUE(b.parallelDeflection.empty());
      EXPECT_EQ(p.parallel, p.gear);
    }
  }
}

TEST(BodyAngles, MotorAngleAgreesWithTheModelsOwnSimulation) {
  // A chirp through the resonances: the motor angle depends on every state through (3.19).
  auto m = makeModel("three-mass");
  const double Ts = 5e-4;
  const int N = 6000;
  std::vector<double> u(N);
  for (int k = 0; k < N; ++k) {
    const double t = k * Ts;
    u[static_cast<std::size_t>(k)] = 0.5 * std::sin(2 * M_PI * (5.0 * t + 20.0 * t * t));
  }
  const BodyAngles b = simulateBodyAngles(*m, {}, torqueLog(u, Ts));
  ASSERT_EQ(b.termination, Termination::Converged) << b.message;
  ModelOptions angle;
  angle.output = ModelOutput::MotorAngle;
  auto ma = makeModel("three-mass", angle);
  const Eigen::VectorXd ref = simulate(*ma, Eigen::Map<const Eigen::VectorXd>(u.data(), N), Ts);
  double worst = 0.0, scale = 0.0;
  for (int k = 0; k < N; ++k) {
    worst = std::max(worst, std::abs(ref[k] - b.motor[static_cast<std::size_t>(k)]));
    scale = std::max(scale, std::abs(ref[k]));
  }
  EXPECT_GT(scale, 1e-3);
  EXPECT_LT(worst, 1e-6 * scale);
  // The chirp rings the springs: the largest deflections are well above their mean.
  EXPECT_GT(b.maxGearDeflection, 0.0);
  EXPECT_GT(b.maxArmDeflection, 0.0);
}

TEST(BodyAngles, KeepsTheMeasuredMotorAngleAndTheSimulatedDeflections) {
  auto m = makeModel("three-mass");
  IdData d = torqueLog(std::vector<double>(2000, 1.0), 5e-4);
  std::vector<double> angle(2000);
  for (std::size_t k = 0; k < angle.size(); ++k) angle[k] = 0.01 * std::sin(0.003 * k);
  d.setChannel({columns::kMotorAngle, "rad", ChannelRole::Output, angle});
  d.startTime = 3.0;
  const BodyAngles measured = simulateBodyAngles(*m, {}, d);
  BodyAnglesOptions o;
  o.motorAngle = MotorAngleSource::Simulated;
  const BodyAngles simulated = simulateBodyAngles(*m, {}, d, o);
  ASSERT_EQ(measured.termination, Termination::Converged);
  EXPECT_EQ(measured.motorAngleSource, MotorAngleSource::Measured);
  EXPECT_EQ(measured.motor, angle);
  EXPECT_EQ(measured.gearDeflection, simulated.gearDeflection);
  EXPECT_EQ(measured.armDeflection, simulated.armDeflection);
  EXPECT_NE(simulated.motor, angle);
  // Times are the log's: sample 1000 is at 3 s + 1000 Ts.
  EXPECT_EQ(measured.sampleAt(3.0 + 1000 * 5e-4), 1000u);
  EXPECT_EQ(measured.sampleAt(-100.0), 0u);
  EXPECT_EQ(measured.sampleAt(1e9), 1999u);
  EXPECT_EQ(measured.atTime(3.5).armDeflection, measured.armDeflection[1000]);
}

TEST(BodyAngles, EndsWithASentence) {
  auto m = makeModel("two-mass");
  IdData none;
  none.sampleTime = 1e-3;
  none.setChannel({columns::kMotorAngle, "rad", ChannelRole::Output, std::vector<double>(10, 0.0)});
  const BodyAngles a = simulateBodyAngles(*m, {}, none);
  EXPECT_EQ(a.termination, Termination::Failed);
  EXPECT_NE(a.message.find("torque"), std::string::npos);

  const BodyAngles c = simulateBodyAngles(*m, {}, torqueLog(std::vector<double>(5000, 1.0), 1e-3),
                                          {}, [](double f, const std::string&) {
                                            return f > 0.3 ? ProgressAction::Abort
                                                           : ProgressAction::Continue;
                                          });
  EXPECT_EQ(c.termination, Termination::Cancelled);
  EXPECT_TRUE(c.motor.empty());

  auto unstable = makeModel("two-mass");
  unstable->setParameter("d_a", -5000.0);  // negative damping beyond the friction: it grows
  const BodyAngles u = simulateBodyAngles(*unstable, {}, torqueLog(std::vector<double>(200000, 1.0), 1e-3));
  EXPECT_EQ(u.termination, Termination::Diverged);
  EXPECT_NE(u.message.find("diverged"), std::string::npos) << u.message;

  BodyAnglesOptions bad;
  bad.substeps = -1;
  EXPECT_THROW(simulateBodyAngles(*m, {}, torqueLog({1.0}, 1e-3), bad), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
