// The plant closed by the cascade controller (loop_model.h): its derivatives against finite
// differences, and its output against the simulator's digital loop.
#include <gtest/gtest.h>

#include <cmath>

#include "core/diagnosis/diagnosis_data.h"
#include "core/diagnosis/loop_model.h"
#include "core/ident/closed_loop_pem.h"
#include "core/ident/pem.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

TEST(LoopModel, DerivativesMatchFiniteDifferences) {
  const auto plant = makeModel("three-mass");
  const LoopModel loop(*plant, ControllerOptions{});
  for (const char* name : {"k_T", "J_a", "f_m", "k_g"}) {
    const int i = loop.indexOf(name);
    ASSERT_GE(i, 0) << name;
    const double v = loop.parameters()[static_cast<std::size_t>(i)].value, h = 1e-6 * v;
    auto plus = loop.clone(), minus = loop.clone();
    plus->setParameter(name, v + h);
    minus->setParameter(name, v - h);
    const Eigen::MatrixXd dA = (plus->stateSpace().A - minus->stateSpace().A) / (2.0 * h);
    const Eigen::MatrixXd dB = (plus->stateSpace().B - minus->stateSpace().B) / (2.0 * h);
    const auto d = loop.derivative(i);
    EXPECT_LT((d.dA - dA).norm(), 1e-6 * (dA.norm() + 1.0)) << name;
    EXPECT_LT((d.dB - dB).norm(), 1e-6 * (dB.norm() + 1.0)) << name;
  }
  EXPECT_EQ(loop.structureName(), "three-mass in the loop");
  EXPECT_EQ(loop.plant()->options().output, ModelOutput::MotorVelocity);
}

// The continuous loop against the digital controller of the simulator (2 kHz, backward
// difference, hold), both from the same smooth reference: the quarter millisecond of hold the
// model leaves out costs less than 2 % of the motor angle's swing.
TEST(LoopModel, FollowsTheDigitalLoop) {
  const auto plant = makeModel("three-mass");
  const ControllerOptions controller;
  const double T = 1.0 / controller.rateHz;
  const Eigen::Index n = 4000;
  Eigen::VectorXd r(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * T;
    r(k) = 0.05 * (std::sin(2.0 * M_PI * 3.0 * t) + 0.5 * std::sin(2.0 * M_PI * 11.0 * t));
  }
  auto anglePlant = makeModel("three-mass", ModelOptions{ModelOutput::MotorAngle, false});
  const Eigen::VectorXd digital = simulateLoop(*anglePlant, controller, r, T);
  const LoopModel loop(*plant, controller);
  const Eigen::VectorXd continuous = simulate(loop, LoopModel::referenceSlopes(r, T), T);
  const double swing = digital.cwiseAbs().maxCoeff();
  EXPECT_GT(swing, 0.04);
  EXPECT_LT((continuous - digital).cwiseAbs().maxCoeff(), 0.02 * swing);
}

// A noise-free closed-loop log at 200 Hz: the loop through the first-order hold predicts its
// motor angle closely, where holding the reference over each sample does not.
TEST(LoopModel, FirstOrderHoldPredictsASlowLog) {
  const auto plant = makeModel("three-mass");
  SimulationOptions o;
  o.durationS = 6.0;
  o.logRateHz = 200.0;
  o.excitation.kind = ExcitationKind::Multisine;
  o.disturbance.torqueNoiseStd = o.disturbance.loadTorqueStd = 0.0;
  o.disturbance.encoderCountsPerRev = 0;
  const auto run = simulateClosedLoop(*plant, {}, o);
  ASSERT_EQ(run.termination, Termination::Converged);
  std::string why;
  const auto s = diagnosisSignals(run.data, DiagnosisPredictor::Loop, &why);
  ASSERT_TRUE(s) << why;
  ASSERT_EQ(s->predictor, DiagnosisPredictor::Loop);
  const auto model = predictorModel(*plant, *s);
  const Eigen::VectorXd foh = simulate(*model, s->input, s->sampleTime);
  const double fitFoh = 100.0 * (1.0 - (s->output - foh).norm() / s->output.norm());
  EXPECT_GT(fitFoh, 97.0);
  // The same loop driven by the reference held over each sample (the slopes' integral).
  const LoopModel zoh(*plant, *s->controller);
  const StateSpace ss = zoh.stateSpace();
  StateSpace held;  // remove the first-order hold: the reference as the input again
  const Eigen::Index m = ss.A.rows() - 1;
  held.A = ss.A.topLeftCorner(m, m);
  held.B = ss.A.block(0, m, m, 1);
  held.C = ss.C.leftCols(m);
  held.D = Eigen::MatrixXd::Zero(1, 1);
  const auto d = discretizeZoh(held, s->sampleTime);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m), yz(s->size());
  const auto& ref = run.data.channel(columns::kAngleRef)->values;
  for (Eigen::Index k = 0; k < s->size(); ++k) {
    yz(k) = (d.C * x)(0);
    x = d.A * x + d.B * ref[static_cast<std::size_t>(k)];
  }
  const double fitZoh = 100.0 * (1.0 - (s->output - yz).norm() / s->output.norm());
  EXPECT_LT(fitZoh, fitFoh - 5.0) << fitZoh << " " << fitFoh;
}

}  // namespace
}  // namespace flexarm
