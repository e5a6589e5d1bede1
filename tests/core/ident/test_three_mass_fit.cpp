// Physical fits end to end on closed-loop simulator data (the seed's Sections 5.1-5.3): the
// three-mass truth of Table 5.7 (p6) under the cascaded controller of Figure 5.1 with torque
// noise, load disturbance and a quantized encoder, excited by the chirp of Section 5.1.
// The output is the motor velocity formed from the measured angle by central differences
// (Section 5.2); the fit runs at the log's own rate, 2 kHz, where the zero-order hold the
// estimator assumes (5.3) is exactly what the plant sees: the controller holds the torque
// reference for one 0.5 ms tick. (After decimation the input is no longer held between the
// new samples, so a ZOH model is only an approximation there.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "core/ident/blackbox.h"
#include "core/ident/evaluation.h"
#include "core/ident/nonparametric.h"
#include "core/ident/pem.h"
#include "core/models/physical_models.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"

namespace flexarm {
namespace {

struct LoopData {
  Eigen::VectorXd u, y;  // means removed
  double sampleTime = 0.0;
};

LoopData toVectors(const IdData& withVelocity) {
  LoopData d;
  inputOutput(withVelocity, d.u, d.y);
  d.u.array() -= d.u.mean();
  d.y.array() -= d.y.mean();
  d.sampleTime = withVelocity.sampleTime;
  return d;
}

// Closed-loop log of the three-mass truth, as the sample log three_mass_estimation_chirp is
// made (same controller, disturbances and chirp), with the given seed.
LoopData simulateLog(std::uint64_t seed, double durationS = 18.0,
                     ExcitationKind kind = ExcitationKind::Chirp) {
  SimulationOptions o;
  o.durationS = durationS;
  o.seed = seed;
  o.excitation.kind = kind;
  const auto truth = makeModel("three-mass");
  const SimulationResult sim = simulateClosedLoop(*truth, {}, o);
  EXPECT_EQ(sim.termination, Termination::Converged) << sim.message;
  return toVectors(addDerivative(sim.data));
}

// Starting point away from the truth: every free parameter off by 10-30 %.
void perturb(PhysicalModel& m) {
  const std::pair<const char*, double> f[] = {{"J_m", 1.2},  {"J_g", 0.8}, {"J_a", 1.15},
                                              {"f_m", 1.3},  {"k_g", 0.85}, {"k_a", 1.1},
                                              {"d_g", 0.8},  {"d_a", 1.25}};
  for (const auto& [name, factor] : f) m.setParameter(name, m.value(name) * factor);
}

std::vector<double> grid() { return logGrid(10.0, 2000.0, 2000); }

// Where the output-error assumptions hold (the input independent of the noise, white output
// noise, input held between samples), the three-mass OE fit recovers every free parameter
// inside its 99 % interval (Section 4.4.3): open-loop white-noise torque at 400 Hz.
TEST(ThreeMassFit, OutputErrorRecoversTheTruthInsideItsIntervalsAcrossSeeds) {
  const auto truth = makeModel("three-mass");
  const double ts = 0.0025;
  int inside = 0, total = 0;
  double worst = 0.0;
  std::string report;
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> nd(0.0, 1.0);
    Eigen::VectorXd u(6000), e(6000);
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = 0.5 * nd(rng);
    for (Eigen::Index i = 0; i < e.size(); ++i) e[i] = nd(rng);
    const Eigen::VectorXd clean = simulate(*truth, u, ts);
    const double sd = std::sqrt((clean.array() - clean.mean()).square().mean());
    const Eigen::VectorXd y = clean + 0.05 * sd * e;
    auto start = makeModel("three-mass");
    perturb(*start);
    const PemResult r = pem(*start, u, y, ts);
    ASSERT_TRUE(r.summary.ok()) << r.summary.message;
    for (const auto& p : r.parameters) {
      if (!p.free) continue;
      const double t = truth->value(p.name);
      worst = std::max(worst, std::abs(p.value - t) / p.std);
      const bool in = t >= p.lower && t <= p.upper;
      inside += in;
      ++total;
      report += "seed " + std::to_string(seed) + " " + p.name + " " + std::to_string(p.value) +
                " +- " + std::to_string(p.std) + " (truth " + std::to_string(t) + ")" +
                (in ? "\n" : " OUTSIDE\n");
    }
  }
  ::testing::Test::RecordProperty("inside99", inside);
  ::testing::Test::RecordProperty("total", total);
  EXPECT_GE(inside, total - 1) << report;  // 24 intervals at 99 %: about 0.24 misses expected
  EXPECT_LT(worst, 4.0) << report;
}

// Closed-loop logs with the realistic disturbances of the sample logs: the noise reaches the
// input through the controller, so the output-error estimate is biased (the seed's (4.43):
// only an independently parameterized, correct noise model removes the bias). What the
// engineer reads from the fit still holds: inertias and stiffnesses within 30 %, the notch
// and peak frequencies within 8 %, and a validation fit as good as the truth's own. (The
// two-stage fit of test_closed_loop_pem.cpp removes the bias and gives honest intervals.)
TEST(ThreeMassFit, ClosedLoopOutputErrorKeepsResonancesAndValidationFit) {
  const auto truth = makeModel("three-mass");
  const auto truthNp = notchesAndPeaks(frequencyResponse(*truth, grid()));
  ASSERT_EQ(truthNp.peaks.size(), 2u);
  ASSERT_EQ(truthNp.notches.size(), 2u);
  const LoopData val = simulateLog(22, 12.0, ExcitationKind::Multisine);
  const double fitTruth = fitPercent(val.y, simulate(*truth, val.u, val.sampleTime));
  int inside = 0, total = 0;
  std::string report;
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    const LoopData d = simulateLog(seed);
    auto start = makeModel("three-mass");
    perturb(*start);
    const PemResult r = pem(*start, d.u, d.y, d.sampleTime);
    ASSERT_TRUE(r.summary.ok()) << r.summary.message;
    for (const auto& p : r.parameters) {
      if (!p.free) continue;
      const double t = truth->value(p.name);
      inside += t >= p.lower && t <= p.upper;
      ++total;
      report += "seed " + std::to_string(seed) + " " + p.name + " " + std::to_string(p.value) +
                " +- " + std::to_string(p.std) + " (truth " + std::to_string(t) + ")\n";
      if (p.name[0] == 'J' || p.name[0] == 'k') {
        EXPECT_NEAR(p.value / t, 1.0, 0.3) << report;
      }
    }
    const auto np = notchesAndPeaks(frequencyResponse(*r.model, grid()));
    ASSERT_EQ(np.peaks.size(), 2u) << report;
    ASSERT_EQ(np.notches.size(), 2u) << report;
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(np.peaks[i] / truthNp.peaks[i], 1.0, 0.08) << "peak " << i;
      EXPECT_NEAR(np.notches[i] / truthNp.notches[i], 1.0, 0.08) << "notch " << i;
    }
    const double fitVal = fitPercent(val.y, simulate(*r.model, val.u, val.sampleTime));
    ::testing::Test::RecordProperty("validationFit" + std::to_string(seed), std::to_string(fitVal));
    EXPECT_GT(fitVal, fitTruth - 1.0) << "truth " << fitTruth;
  }
  ::testing::Test::RecordProperty("validationFitTruth", std::to_string(fitTruth));
  ::testing::Test::RecordProperty("inside99ClosedLoop", inside);
  ::testing::Test::RecordProperty("totalClosedLoop", total);
  std::printf("%s%d of %d truths inside the 99 %% intervals\n", report.c_str(), inside, total);
}

// Figure 5.3: on the same data, the two-mass model shows one resonance (one notch, one peak)
// where the three-mass model and a fifth-order Box-Jenkins model show two.
TEST(ThreeMassFit, TwoMassShowsOneResonanceWhereThreeMassAndBj5ShowTwo) {
  const LoopData d = simulateLog(31);
  const auto truthNp = notchesAndPeaks(frequencyResponse(*makeModel("three-mass"), grid()));
  ASSERT_EQ(truthNp.peaks.size(), 2u);
  ASSERT_EQ(truthNp.notches.size(), 2u);

  auto three = makeModel("three-mass");
  perturb(*three);
  const PemResult r3 = pem(*three, d.u, d.y, d.sampleTime);
  ASSERT_TRUE(r3.summary.ok()) << r3.summary.message;
  const auto np3 = notchesAndPeaks(frequencyResponse(*r3.model, grid()));
  ASSERT_EQ(np3.peaks.size(), 2u);
  ASSERT_EQ(np3.notches.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(np3.peaks[i], truthNp.peaks[i], 0.05 * truthNp.peaks[i]);
    EXPECT_NEAR(np3.notches[i], truthNp.notches[i], 0.05 * truthNp.notches[i]);
  }

  PemOptions two;
  two.randomStarts = 4;
  const PemResult r2 = pem(*makeModel("two-mass"), d.u, d.y, d.sampleTime, two);
  ASSERT_TRUE(r2.summary.ok()) << r2.summary.message;
  const auto np2 = notchesAndPeaks(frequencyResponse(*r2.model, grid()));
  EXPECT_EQ(np2.peaks.size(), 1u);
  EXPECT_EQ(np2.notches.size(), 1u);
  EXPECT_GT(r2.summary.loss, r3.summary.loss);

  // bj5 at 400 Hz (decimated by five behind the anti-alias FIR). At the seed's 200 Hz the two
  // resonances of this truth (about 157 and 209 rad/s) merge into one in bj5; bj8 separates
  // them there.
  SimulationOptions o;
  o.seed = 31;
  const auto sim = simulateClosedLoop(*makeModel("three-mass"), {}, o);
  DecimateOptions dec;
  dec.factor = 5;
  const LoopData dd = toVectors(decimate(addDerivative(sim.data), dec));
  const PolyEstimate bj5 = bj(dd.u, dd.y, 5, 5, 5, 5, 1, dd.sampleTime);
  ASSERT_TRUE(bj5.summary.ok()) << bj5.summary.message;
  const auto npb = notchesAndPeaks(
      frequencyResponse(bj5.model, logGrid(10.0, 0.95 * M_PI / dd.sampleTime, 2000)), 3.0);
  EXPECT_EQ(npb.peaks.size(), 2u);
  EXPECT_EQ(npb.notches.size(), 2u);
  for (std::size_t i = 0; i < std::min<std::size_t>(2, npb.peaks.size()); ++i)
    EXPECT_NEAR(npb.peaks[i], truthNp.peaks[i], 0.05 * truthNp.peaks[i]);
}

}  // namespace
}  // namespace flexarm
