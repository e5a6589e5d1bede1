// Consistency of the recursive estimator: on long, nearly noise-free logs of the seed's arm the
// estimates of k_T and J_a settle within 0.5 % of the truth that made the data.
#include <gtest/gtest.h>

#include <cmath>

#include "core/recursive/rpem.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"
#include "recursive_helpers.h"

namespace flexarm {
namespace {

// Mean of a trajectory column over its second half.
double secondHalfMean(const std::vector<double>& v) {
  double s = 0.0;
  for (std::size_t k = v.size() / 2; k < v.size(); ++k) s += v[k];
  return s / static_cast<double>(v.size() - v.size() / 2);
}

// The FlexArm simulator's closed loop (Figure 5.1) at the controller's 2 kHz with little noise
// and an ideal encoder; the estimator runs at the log's rate, where the zero-order hold of the
// torque reference is exact, on the velocity differentiated from the angle.
TEST(RecursiveBias, KtAndJaWithinHalfAPercentOnALongLowNoiseClosedLoopLog) {
  const auto truth = testing::threeMassP6();
  SimulationOptions so;
  so.durationS = 20.0;
  so.logRateHz = 2000.0;
  so.seed = 21;
  so.excitation.kind = ExcitationKind::Multisine;
  so.excitation.amplitude = 0.2;
  so.disturbance.torqueNoiseStd = 0.002;
  so.disturbance.loadTorqueStd = 0.02;
  so.disturbance.encoderCountsPerRev = 0;
  const SimulationResult sim = simulateClosedLoop(*truth, {}, so);
  ASSERT_EQ(sim.termination, Termination::Converged) << sim.message;
  const IdData d = detrend(addDerivative(sim.data), Detrend::Mean);
  const auto n = static_cast<Eigen::Index>(d.samples());
  const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(d.input()->values.data(), n);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(d.output()->values.data(), n);
  for (auto algorithm : {RecursiveAlgorithm::ForgettingFactor, RecursiveAlgorithm::Kalman}) {
    RecursiveOptions o;
    o.algorithm = algorithm;
    o.startScale = 1.2;
    // The seed's design variables are per sample at 200 Hz: at ten times the rate the same
    // memory (1 s) and the same random walk per second are lambda^(1/10) and R1 / 10.
    const RecursiveResult r = recursiveIdentification(*truth, u, y, d.sampleTime, o);
    ASSERT_EQ(r.termination, Termination::Converged) << r.message;
    if (algorithm == RecursiveAlgorithm::Kalman) {
      ASSERT_EQ(r.asRun.r1.size(), 3u);
      EXPECT_NEAR(r.asRun.r1[0], 5e-9, 1e-20);
      EXPECT_NEAR(r.asRun.r1[2], 5e-7, 1e-18);
    } else {
      EXPECT_NEAR(r.asRun.lambda, std::pow(0.995, 0.1), 1e-15);
    }
    const double kT = secondHalfMean(r.trajectory.theta[0]);
    const double Ja = 1.0 / secondHalfMean(r.trajectory.theta[1]);
    EXPECT_NEAR(kT / 1.0, 1.0, 0.005) << toString(algorithm);
    EXPECT_NEAR(Ja / 1.72, 1.0, 0.005) << toString(algorithm);
    // The model's names carry J_a itself.
    EXPECT_EQ(r.estimates[1].parameter.modelName, "J_a");
    EXPECT_NEAR(r.estimates[1].modelFinal, 1.0 / r.estimates[1].final, 1e-12);
  }
}

}  // namespace
}  // namespace flexarm
