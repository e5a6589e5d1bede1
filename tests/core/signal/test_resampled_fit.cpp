// A log whose time stamps jitter, skip, repeat and run backwards, put on a uniform grid, gives
// the same fitted physical model as the clean log of the same experiment: every estimate
// lies inside the clean fit's 99 % interval. Two-mass model (3.13), output-error fit (5.3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "../ident/two_mass_test_model.h"
#include "core/ident/pem.h"
#include "core/signal/uniform_grid.h"

using namespace flexarm;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTs = 0.005;  // 200 Hz log
constexpr int kFine = 20;      // the experiment runs at 4 kHz
constexpr int kSamples = 3000;

// Torque of the experiment: 20 sines 2..40 Hz (below 0.8 of the log's Nyquist frequency).
double torque(double t) {
  double u = 0.0;
  for (int i = 1; i <= 20; ++i) u += std::sin(2 * kPi * 2.0 * i * t + kPi * i * i / 20.0);
  return u / std::sqrt(10.0);
}

struct Experiment {
  std::vector<double> u, y;  // at every 4 kHz instant
};

Experiment run(const ParametricModel& model) {
  const StateSpace d = discretizeZoh(model.stateSpace(), kTs / kFine);
  Experiment e;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.A.rows());
  for (int j = 0; j <= kSamples * kFine + 1; ++j) {
    const double u = torque(j * kTs / kFine);
    e.u.push_back(u);
    e.y.push_back((d.C * x)(0, 0));
    x = d.A * x + d.B * u;
  }
  return e;
}

IdData logOf(const std::vector<double>& time, const std::vector<double>& u, const std::vector<double>& y) {
  IdData d;
  d.sampleTime = kTs;
  d.channels = {{"torque_ref_nm", "N m", ChannelRole::Input, u},
                {"motor_velocity_rad_s", "rad/s", ChannelRole::Output, y}};
  d.timeStamps = time;
  d.startTime = time.front();
  return d;
}

PemResult fit(const IdData& d) {
  flexarm::testing::TwoMassTestModel start;
  start.setParameter("J_m", 9e-4 * 1.2);
  start.setParameter("J_a", 12.0 * 0.85);
  start.setParameter("f_m", 0.1 * 1.3);
  start.setParameter("k", 1.5e5 * 1.1);
  start.setParameter("d", 70.0 * 1.5);
  const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(d.input()->values.data(), static_cast<Eigen::Index>(d.samples()));
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(d.output()->values.data(), static_cast<Eigen::Index>(d.samples()));
  return pem(start, u, y, d.sampleTime);
}

}  // namespace

TEST(ResampledFit, IrregularLogGivesTheCleanLogsModelWithinItsIntervals) {
  const flexarm::testing::TwoMassTestModel truth;
  const Experiment e = run(truth);
  std::mt19937 rng(7);
  double sd = 0.0;
  for (int k = 0; k < kSamples; ++k) sd += e.y[static_cast<std::size_t>(k * kFine)] * e.y[static_cast<std::size_t>(k * kFine)];
  std::normal_distribution<double> noise(0.0, 0.05 * std::sqrt(sd / kSamples));
  std::vector<double> noiseOf(kSamples);
  for (double& v : noiseOf) v = noise(rng);

  // The clean log: every 200 Hz instant. The irregular one: seven samples dropped (four
  // gaps), every 53rd sample taken one 4 kHz step early or late (5 % jitter), one written
  // twice and two swapped; each holds the experiment's values at its stamped time.
  std::vector<double> tc, uc, yc, ti, ui, yi;
  const int drops[] = {500, 1200, 1201, 2000, 2600, 2601, 2602};
  for (int k = 0; k < kSamples; ++k) {
    const std::size_t j = static_cast<std::size_t>(k * kFine);
    tc.push_back(k * kTs);
    uc.push_back(e.u[j]);
    yc.push_back(e.y[j] + noiseOf[static_cast<std::size_t>(k)]);
    if (std::find(std::begin(drops), std::end(drops), k) != std::end(drops)) continue;
    const std::size_t jj = k % 53 == 7 && k > 0 ? (k % 2 ? j + 1 : j - 1) : j;
    for (int copies = k == 1500 ? 2 : 1; copies > 0; --copies) {
      ti.push_back(static_cast<double>(jj) * kTs / kFine);
      ui.push_back(e.u[jj]);
      yi.push_back(e.y[jj] + noiseOf[static_cast<std::size_t>(k)]);
    }
  }
  std::swap(ti[2200], ti[2201]);
  std::swap(ui[2200], ui[2201]);
  std::swap(yi[2200], yi[2201]);

  IdData clean = logOf(tc, uc, yc);
  clean.timeStamps.clear();
  UniformGridOptions o;
  o.rateHz = 200;
  const auto r = resampleToUniform(logOf(ti, ui, yi), o);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  ASSERT_EQ(r.data.samples(), static_cast<std::size_t>(kSamples));
  EXPECT_EQ(r.filled, 7u);
  EXPECT_EQ(r.retimed, 57u) << "every 53rd sample from the 7th";
  EXPECT_EQ(r.groups[0].timing.duplicates, 1u);
  EXPECT_EQ(r.groups[0].timing.reversals, 1u);

  const PemResult a = fit(clean), b = fit(r.data);
  ASSERT_TRUE(a.summary.ok()) << a.summary.message;
  ASSERT_TRUE(b.summary.ok()) << b.summary.message;
  int compared = 0;
  for (std::size_t i = 0; i < a.parameters.size(); ++i) {
    const PemParameter& pa = a.parameters[i];
    const PemParameter& pb = b.parameters[i];
    if (!pa.free) continue;
    ++compared;
    EXPECT_GE(pb.value, pa.lower) << pa.name;
    EXPECT_LE(pb.value, pa.upper) << pa.name;
    // Band-limited resampling keeps every estimate within a quarter of a standard deviation
    // (at most 0.15 here); linear interpolation would move f_m and d by a third.
    EXPECT_LT(std::abs(pb.value - pa.value), 0.25 * pa.std) << pa.name;
  }
  EXPECT_EQ(compared, 5);
}
