// Two-stage closed-loop identification (Van den Hof and Schrama; Forssell and Ljung) on the
// simulator's closed-loop logs: the three-mass truth of Table 5.7 under the cascaded
// controller of Figure 5.1 with torque noise, load disturbance and a quantized encoder (the
// same generator and realistic noise as test_three_mass_fit.cpp). The output-error fit on
// (u, y) is biased there (the seed's (4.43)); on (u_r, y), with u_r the part of u explained by
// the reference, it is consistent, and the sandwich covariance makes its 99 % intervals
// honest although the prediction errors are coloured.
// The fit runs at the log's own rate, 2 kHz, where the zero-order hold the estimator assumes
// (5.3) is what the plant sees: the controller holds the torque for one 0.5 ms tick.
#include <gtest/gtest.h>

#include "tests/test_scale.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/ident/closed_loop_pem.h"
#include "core/ident/levenberg_marquardt.h"
#include "core/ident/pem.h"
#include "core/models/physical_models.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

// Seeds 11-16; two of them under the sanitizers (tests/test_scale.h).
std::vector<std::uint64_t> seeds() {
  if (flexarm::test::reducedSizes()) return {11u, 12u};
  return {11u, 12u, 13u, 14u, 15u, 16u};
}

Eigen::VectorXd centred(const std::vector<double>& v) {
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  x.array() -= x.mean();
  return x;
}

Eigen::VectorXd raw(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

struct LoopLog {
  Eigen::VectorXd u, y, r;  // means removed
  double sampleTime = 0.0;
  Eigen::VectorXd angle, reference;  // as logged: measured motor angle and phi_ref
  ControllerOptions controller;
};

// Closed-loop log of the three-mass truth with the sample logs' controller, disturbances and
// chirp; y is the motor velocity from central differences of the measured angle.
LoopLog simulateLog(std::uint64_t seed) {
  SimulationOptions o;
  o.durationS = 18.0;
  o.seed = seed;
  const SimulationResult sim = simulateClosedLoop(*makeModel("three-mass"), {}, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  const IdData d = addDerivative(sim.data);
  LoopLog l;
  l.u = centred(d.input()->values);
  l.y = centred(d.output()->values);
  l.r = centred(d.withRole(ChannelRole::Reference)->values);
  l.sampleTime = d.sampleTime;
  l.angle = raw(sim.data.channel(columns::kMotorAngle)->values);
  l.reference = raw(sim.data.withRole(ChannelRole::Reference)->values);
  l.controller = o.controller;
  return l;
}

// The simulator's loop around the three-mass truth (default controller) without torque
// noise, load disturbance or encoder quantization.
SimulationResult simulateNoiseFree(double durationS) {
  SimulationOptions o;
  o.durationS = durationS;
  o.disturbance.torqueNoiseStd = 0.0;
  o.disturbance.loadTorqueStd = 0.0;
  o.disturbance.encoderCountsPerRev = 0;
  SimulationResult sim = simulateClosedLoop(*makeModel("three-mass"), {}, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  return sim;
}

// Starting point away from the truth: every free parameter off by 10-30 %.
void perturb(PhysicalModel& m) {
  const std::pair<const char*, double> f[] = {{"J_m", 1.2},  {"J_g", 0.8}, {"J_a", 1.15},
                                              {"f_m", 1.3},  {"k_g", 0.85}, {"k_a", 1.1},
                                              {"d_g", 0.8},  {"d_a", 1.25}};
  for (const auto& [name, factor] : f) m.setParameter(name, m.value(name) * factor);
}

// The three-mass fit of a log from the perturbed start: the indirect method on the angle and
// reference as logged, the others on the centred (u, y, r).
ClosedLoopPemResult fitPerturbed(const LoopLog& d, const ClosedLoopPemOptions& o) {
  auto start = makeModel("three-mass");
  perturb(*start);
  return o.method == ClosedLoopMethod::Indirect
             ? pemClosedLoop(*start, {}, d.angle, d.reference, d.sampleTime, o)
             : pemClosedLoop(*start, d.u, d.y, d.r, d.sampleTime, o);
}

// Counts the free parameters whose truth lies inside the 99 % interval, adds one line per
// parameter to report, and checks that the main parameters' intervals stay narrow.
void tally(const PemResult& est, const PhysicalModel& truth, int& inside, int& total,
           std::string& report) {
  for (const auto& p : est.parameters) {
    if (!p.free) continue;
    const double t = truth.value(p.name);
    const bool in = t >= p.lower && t <= p.upper;
    inside += in;
    ++total;
    char line[200];
    std::snprintf(line, sizeof line, "  %-4s %12.6g +- %10.4g (%5.1f %%)  truth %12.6g  %+.2f std%s\n",
                  p.name.c_str(), p.value, p.std, 100.0 * p.std / std::abs(p.value), t,
                  (p.value - t) / p.std, in ? "" : "  OUTSIDE");
    report += line;
    if (p.name == "J_m" || p.name == "J_a" || p.name == "k_g" || p.name == "k_a") {
      EXPECT_LT(p.std / t, 0.2) << p.name << " interval too wide\n" << report;
    }
  }
}

// Six logs of the same generator (seeds 11-16; 11-13 are those of the closed-loop test in
// test_three_mass_fit.cpp): every free parameter of the three-mass model, 48 intervals. The
// direct output-error fit with the white-noise covariance leaves about half of the truths
// outside their 99 % intervals on these logs; the two-stage fit with the sandwich covariance
// that carries the stage-1 error leaves at most four outside (on 24 seeds, 1-24, it leaves 7
// of 192 outside: 3.6 % where 1 % is promised; the misses are the arm's J_a, k_a, d_a and the
// friction f_m, whose estimates keep a bias of about one standard deviation from the load
// disturbance), and the intervals stay narrow.
TEST(ClosedLoopPem, TwoStageRecoversTheThreeMassTruthInsideHonestIntervalsAcrossSeeds) {
  const auto truth = makeModel("three-mass");
  int inside = 0, total = 0;
  std::string report;
  for (std::uint64_t seed : seeds()) {
    const ClosedLoopPemResult r = fitPerturbed(simulateLog(seed), {});
    ASSERT_TRUE(r.pem.summary.ok()) << r.pem.summary.message;
    ASSERT_EQ(r.method, ClosedLoopMethod::TwoStage);
    ASSERT_TRUE(r.projection.ok) << r.projection.message;
    EXPECT_EQ(r.pem.covarianceKind, CovarianceKind::Sandwich);
    // The reference explains most, but not all, of the torque: the rest is the controller's
    // answer to the noise.
    EXPECT_GT(r.projection.fitPercent, 90.0);
    EXPECT_LT(r.projection.fitPercent, 99.5);
    char head[120];
    std::snprintf(head, sizeof head, "seed %d: stage 1 explains %.2f %% of u, %d lags\n",
                  static_cast<int>(seed), r.projection.fitPercent, r.pem.covarianceLags);
    report += head;
    tally(r.pem, *truth, inside, total, report);
  }
  ::testing::Test::RecordProperty("inside99", inside);
  ::testing::Test::RecordProperty("total", total);
  std::printf("%s%d of %d truths inside the 99 %% intervals\n", report.c_str(), inside, total);
  EXPECT_EQ(total, 8 * static_cast<int>(seeds().size()));
  EXPECT_GE(inside, total - 4) << report;
}

// The indirect method on the same six logs (seeds 11-16, 48 intervals): the known controller
// closed around the three-mass model, fitted from the reference to the measured angle.
// Nothing of the noise reaches the model's input, so the estimate is consistent, and the
// sandwich covariance makes the intervals honest: at 99 %, a binomial count over 48
// independent intervals exceeds 2 with probability 1.4 %. On seeds 1-24 it leaves 3 of 192
// outside (1.6 %; the estimates' errors over standard deviation have an rms of 0.91-1.07 per
// parameter), where the two-stage fit leaves 7 (rms 0.93-1.48, J_a, k_a, d_a and f_m biased
// by about 0.8 standard deviations).
TEST(ClosedLoopPem, IndirectRecoversTheThreeMassTruthInsideHonestIntervalsAcrossSeeds) {
  const auto truth = makeModel("three-mass");
  int inside = 0, total = 0;
  std::string report;
  for (std::uint64_t seed : seeds()) {
    const LoopLog d = simulateLog(seed);
    ClosedLoopPemOptions o;
    o.method = ClosedLoopMethod::Indirect;
    o.controller = d.controller;
    const ClosedLoopPemResult r = fitPerturbed(d, o);
    ASSERT_TRUE(r.pem.summary.ok()) << r.pem.summary.message;
    ASSERT_EQ(r.method, ClosedLoopMethod::Indirect);
    EXPECT_EQ(r.pem.covarianceKind, CovarianceKind::Sandwich);
    // The estimate keeps the caller's output: the motor velocity.
    const auto* est = dynamic_cast<const PhysicalModel*>(r.pem.model.get());
    ASSERT_NE(est, nullptr);
    EXPECT_EQ(est->options().output, ModelOutput::MotorVelocity);
    report += "seed " + std::to_string(seed) + "\n";
    tally(r.pem, *truth, inside, total, report);
  }
  std::printf("%s%d of %d truths inside the 99 %% intervals\n", report.c_str(), inside, total);
  EXPECT_EQ(total, 8 * static_cast<int>(seeds().size()));
  EXPECT_GE(inside, total - 2) << report;
}

// The loop the indirect method simulates is the simulator's: without noise and with an ideal
// encoder, the ZOH-sampled model under the controller reproduces the logged angle (the
// simulator integrates the plant by Runge-Kutta between ticks), and the logged torque, held
// over each tick, drives the plant to the logged angle.
TEST(ClosedLoopPem, LoopSimulationReproducesTheNoiseFreeSimulator) {
  const ControllerOptions controller;
  const auto truth = makeModel("three-mass");
  const SimulationResult sim = simulateNoiseFree(4.0);
  const Eigen::VectorXd angle = raw(sim.data.channel(columns::kMotorAngle)->values);
  const Eigen::VectorXd ref = raw(sim.data.withRole(ChannelRole::Reference)->values);
  auto angleModel = makeModel("three-mass", {ModelOutput::MotorAngle, false});
  const Eigen::VectorXd a = simulateLoop(*angleModel, controller, ref, sim.data.sampleTime,
                                         LoopOutput::MotorAngle);
  EXPECT_LT((a - angle).norm(), 1e-6 * angle.norm()) << (a - angle).cwiseAbs().maxCoeff();
  const Eigen::VectorXd open = simulate(*angleModel, raw(sim.data.input()->values), sim.data.sampleTime);
  EXPECT_LT((open - angle).norm(), 1e-6 * angle.norm());
  // A controller one tick late (the angle before) would not reproduce it.
  Eigen::VectorXd late = Eigen::VectorXd::Zero(a.size());
  late.tail(a.size() - 1) = a.head(a.size() - 1);
  EXPECT_GT((late - angle).norm(), 1e-3 * angle.norm());
  // Other gains give another loop.
  ControllerOptions other = controller;
  other.kv *= 1.1;
  EXPECT_GT((simulateLoop(*angleModel, other, ref, sim.data.sampleTime, LoopOutput::MotorAngle) -
             angle).norm(), 1e-3 * angle.norm());
  // The velocity output is the angle's backward difference.
  const Eigen::VectorXd v = simulateLoop(*angleModel, controller, ref, sim.data.sampleTime,
                                         LoopOutput::MotorVelocity);
  EXPECT_NEAR(v[100], (a[100] - a[99]) / sim.data.sampleTime, 1e-9 * std::abs(v[100]) + 1e-12);
  // Misuse: a velocity-output model has no angle for the controller; a decimated rate.
  EXPECT_THROW(simulateLoop(*truth, controller, ref, sim.data.sampleTime), std::invalid_argument);
  EXPECT_THROW(simulateLoop(*angleModel, controller, ref, 2.0 * sim.data.sampleTime),
               std::invalid_argument);
}

// The loop's gradient psi = d yhat / d theta (from the sensitivity system of the closed
// loop, with the plant's exact ZOH derivatives) agrees with central differences of the
// simulated loop for every three-mass parameter, for both outputs.
TEST(ClosedLoopPem, LoopGradientMatchesCentralDifferences) {
  const ControllerOptions controller;
  const SimulationResult sim = simulateNoiseFree(1.0);
  const Eigen::VectorXd ref = raw(sim.data.withRole(ChannelRole::Reference)->values);
  const double T = sim.data.sampleTime;
  auto model = makeModel("three-mass", {ModelOutput::MotorAngle, false});
  std::vector<int> free;
  for (const char* name : {"J_m", "J_g", "J_a", "f_m", "k_g", "k_a", "d_g", "d_a"})
    free.push_back(model->indexOf(name));
  for (LoopOutput output : {LoopOutput::MotorAngle, LoopOutput::MotorVelocity}) {
    const PemEvaluation ev = evaluateLoop(*model, controller, ref, Eigen::VectorXd::Zero(ref.size()),
                                          T, free, true, output);
    ASSERT_EQ(ev.psi.cols(), 8);
    EXPECT_TRUE(ev.stable);
    for (int j = 0; j < 8; ++j) {
      const auto& info = model->parameters()[static_cast<std::size_t>(free[static_cast<std::size_t>(j)])];
      const double v = info.value, h = 1e-5 * std::abs(v);
      auto at = [&](double value) {
        auto m = model->clone();
        m->setParameter(info.name, value);
        return simulateLoop(*m, controller, ref, T, output);
      };
      const Eigen::VectorXd numeric = (at(v + h) - at(v - h)) / (2.0 * h);
      EXPECT_LT((ev.psi.col(j) - numeric).norm(), 1e-5 * numeric.norm())
          << info.name << " (" << toString(output) << ")";
    }
  }
}

// The indirect method on data at another rate than the controller's fails with a sentence.
TEST(ClosedLoopPem, IndirectOnDecimatedDataFailsWithASentence) {
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(400, 0.0, 1.0);
  ClosedLoopPemOptions o;
  o.method = ClosedLoopMethod::Indirect;
  const ClosedLoopPemResult res = pemClosedLoop(*makeModel("two-mass"), {}, r, r, 0.001, o);
  EXPECT_FALSE(res.pem.summary.ok());
  EXPECT_NE(res.pem.summary.message.find("controller's rate"), std::string::npos)
      << res.pem.summary.message;
  o.pem.noiseModel = NoiseModel::Innovations;
  EXPECT_THROW(pemClosedLoop(*makeModel("two-mass"), {}, r, r, 0.0005, o), std::invalid_argument);
}

// The direct fit of the same kind of log, for contrast: the noise fed back through the
// controller biases output error (4.43), and its white-noise intervals miss the truth.
TEST(ClosedLoopPem, DirectOutputErrorMissesTheTruthOnTheSameLogs) {
  const auto truth = makeModel("three-mass");
  const LoopLog d = simulateLog(11);
  auto start = makeModel("three-mass");
  perturb(*start);
  ClosedLoopPemOptions o;
  o.method = ClosedLoopMethod::Direct;
  const ClosedLoopPemResult r = pemClosedLoop(*start, d.u, d.y, {}, d.sampleTime, o);
  ASSERT_TRUE(r.pem.summary.ok()) << r.pem.summary.message;
  EXPECT_EQ(r.pem.covarianceKind, CovarianceKind::White);
  int outside = 0;
  for (const auto& p : r.pem.parameters)
    if (p.free) outside += truth->value(p.name) < p.lower || truth->value(p.name) > p.upper;
  EXPECT_GE(outside, 3);
}

// Stage 1 alone: on a noise-free loop, u is an exact linear function of r and the FIR with
// its spline tail reproduces it.
TEST(ClosedLoopPem, StageOneReproducesANoiseFreeInput) {
  const SimulationResult sim = simulateNoiseFree(6.0);
  const Eigen::VectorXd u = centred(sim.data.input()->values);
  const Eigen::VectorXd r = centred(sim.data.withRole(ChannelRole::Reference)->values);
  const ReferenceProjection p = projectOnReference(u, r, sim.data.sampleTime);
  ASSERT_TRUE(p.ok) << p.message;
  EXPECT_GT(p.fitPercent, 99.9);
  EXPECT_LT(p.freeParameters, p.pastTaps + p.futureTaps + 1);  // the tail is a spline
  // A too short FIR cannot hold the loop's memory.
  ReferenceProjectionOptions shortFir;
  shortFir.pastS = 0.05;
  EXPECT_LT(projectOnReference(u, r, sim.data.sampleTime, shortFir).fitPercent, 99.0);
}

TEST(ClosedLoopPem, MisuseThrowsAndBadDataFailWithASentence) {
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(100, 0.0, 1.0);
  EXPECT_THROW(projectOnReference(u, Eigen::VectorXd::Zero(50), 0.01), std::invalid_argument);
  ReferenceProjectionOptions bad;
  bad.pastS = -1.0;
  EXPECT_THROW(projectOnReference(u, u, 0.01, bad), std::invalid_argument);
  EXPECT_THROW(projectOnReference(u, u, 0.0), std::invalid_argument);
  // Too few samples for the FIR.
  const ReferenceProjection shortLog = projectOnReference(u, u, 0.0005);
  EXPECT_FALSE(shortLog.ok);
  EXPECT_NE(shortLog.message.find("too few samples"), std::string::npos) << shortLog.message;
  // A constant reference explains nothing.
  const ReferenceProjection flat = projectOnReference(u, Eigen::VectorXd::Zero(100), 0.1);
  EXPECT_FALSE(flat.ok);
  EXPECT_NE(flat.message.find("constant"), std::string::npos) << flat.message;
  // The two-stage fit needs a reference as long as the input.
  EXPECT_THROW(pemClosedLoop(*makeModel("two-mass"), u, u, {}, 0.01), std::invalid_argument);
  EXPECT_EQ(toString(ClosedLoopMethod::TwoStage), std::string("two-stage"));
  EXPECT_EQ(closedLoopMethodFromString("direct"), ClosedLoopMethod::Direct);
  EXPECT_EQ(closedLoopMethodFromString("indirect"), ClosedLoopMethod::Indirect);
  EXPECT_EQ(toString(ClosedLoopMethod::Indirect), std::string("indirect"));
  EXPECT_FALSE(closedLoopMethodFromString("joint").has_value());
  EXPECT_EQ(loopOutputFromString("motor-angle"), LoopOutput::MotorAngle);
  EXPECT_EQ(covarianceKindFromString("sandwich"), CovarianceKind::Sandwich);
}

// The long-run covariance by FFT equals its defining double sum; with white errors and no
// lags the sandwich is the usual lambda R^{-1} (4.37); with coloured errors it follows the
// long-run variance, which the white form misses.
TEST(ClosedLoopPem, SandwichMatchesItsDefinitionAndTheWhiteFormAndWidensForColouredErrors) {
  std::mt19937 rng(5);
  std::normal_distribution<double> nd(0.0, 1.0);
  {
    const Eigen::Index n = 300;
    const int lags = 25;
    Eigen::MatrixXd psi(n, 2), chi(n, 2);
    Eigen::VectorXd e(n), f(n);
    for (Eigen::Index t = 0; t < n; ++t) {
      psi(t, 0) = nd(rng), psi(t, 1) = std::sin(0.1 * t);
      chi(t, 0) = nd(rng), chi(t, 1) = std::cos(0.05 * t);
      e[t] = nd(rng) + (t ? 0.5 * e[t - 1] : 0.0);
      f[t] = nd(rng) + 0.3 * e[t];
    }
    const Eigen::MatrixXd* ps[] = {&psi, &chi};
    const Eigen::VectorXd* es[] = {&e, &f};
    Eigen::MatrixXd direct = Eigen::MatrixXd::Zero(2, 2);
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int tau = -lags; tau <= lags; ++tau) {
          double rij = 0.0;
          Eigen::Matrix2d c = Eigen::Matrix2d::Zero();
          for (Eigen::Index t = 0; t < n; ++t) {
            if (t - tau < 0 || t - tau >= n) continue;
            rij += (*es[i])[t] * (*es[j])[t - tau];
            c += ps[i]->row(t).transpose() * ps[j]->row(t - tau);
          }
          direct += (1.0 - std::abs(tau) / (lags + 1.0)) * rij / static_cast<double>(n) * c;
        }
    direct = 0.5 * (direct + direct.transpose()).eval();
    const Eigen::MatrixXd fast = longRunCovariance({{&psi, &e}, {&chi, &f}}, lags);
    EXPECT_TRUE(fast.isApprox(direct, 1e-9)) << fast << "\n" << direct;
  }
  const Eigen::Index n = 40000;
  Eigen::MatrixXd psi(n, 2);
  Eigen::VectorXd e(n), c(n);
  double ar = 0.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    psi(t, 0) = nd(rng);
    psi(t, 1) = 1.0;
    e[t] = nd(rng);
    ar = 0.9 * ar + nd(rng);
    c[t] = ar;
  }
  const Eigen::MatrixXd white = gaussNewtonCovariance(psi, e.squaredNorm());
  const Eigen::MatrixXd sw0 = sandwichCovariance(psi, e, 0);
  EXPECT_TRUE(sw0.isApprox(white, 0.05)) << sw0 << "\n" << white;
  // AR(1) with pole 0.9: the long-run variance of a mean is (1 + 0.9) / (1 - 0.9) = 19 times
  // the white one (Bartlett's window over 400 lags takes off about 0.5); the estimate's own
  // relative spread is about sqrt(4 M / 3 N) = 12 %.
  const Eigen::MatrixXd sw = sandwichCovariance(psi, c, 400);
  const Eigen::MatrixXd wc = gaussNewtonCovariance(psi, c.squaredNorm());
  EXPECT_GT(sw(1, 1) / wc(1, 1), 12.0);
  EXPECT_LT(sw(1, 1) / wc(1, 1), 26.0);
  EXPECT_THROW(sandwichCovariance(psi, e.head(10), 3), std::invalid_argument);
}

}  // namespace
}  // namespace flexarm
