// Logs put on a uniform time base: a uniform log at another rate (the same numbers as the
// resampler and as decimation), an irregular log regularised by each method against the
// signal that made it, the gap limit, two logs of one experiment and channels at different
// rates in one log.
#include <gtest/gtest.h>

#include <cmath>

#include "core/signal/preprocess.h"
#include "core/signal/uniform_grid.h"

using namespace flexarm;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Band-limited test signals (content up to 430 Hz, below 0.8 of a 2 kHz log's Nyquist).
double angle(double t) { return 0.5 * std::sin(2 * kPi * 13 * t + 0.2) + 0.2 * std::sin(2 * kPi * 170 * t) + 0.05 * std::cos(2 * kPi * 430 * t); }
double torque(double t) { return std::cos(2 * kPi * 7 * t) + 0.3 * std::sin(2 * kPi * 260 * t + 1.0); }
double accel(double t) { return std::sin(2 * kPi * 31 * t + 0.7) + 0.1 * std::sin(2 * kPi * 390 * t); }

IdData uniformLog(double rate, double start, std::size_t n) {
  IdData d;
  d.sampleTime = 1.0 / rate;
  d.startTime = start;
  std::vector<double> a(n), u(n);
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = angle(d.timeAt(i));
    u[i] = torque(d.timeAt(i));
  }
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, u});
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, a});
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.12g", rate);
  d.setMeta("sample_rate_hz", buf);
  return d;
}

// A 2 kHz log of 4 s whose stamps jitter (every 37th sample, by 2-4 %), with dropped samples
// (five places, seven samples), one sample written twice and two swapped; the values are the
// signals at the stamped times, the lines count from 5.
struct Irregular {
  IdData data;
  std::size_t jittered = 0, dropped = 0;
};

Irregular irregularLog() {
  Irregular r;
  IdData& d = r.data;
  d.sampleTime = 0.0005;
  d.setMeta("sample_rate_hz", "2000");
  std::vector<double> t;
  const std::size_t drops[] = {1001, 2500, 2501, 4000, 5000, 5001, 5002};
  for (std::size_t k = 0; k < 8000; ++k) {
    if (std::find(std::begin(drops), std::end(drops), k) != std::end(drops)) {
      ++r.dropped;
      continue;
    }
    double tk = k * 0.0005;
    if (k % 37 == 3) {
      tk += (k % 2 ? 0.02 : -0.04) * 0.0005 * (1.0 + 0.5 * std::sin(static_cast<double>(k)));
      ++r.jittered;
    }
    t.push_back(tk);
    if (k == 6000) t.push_back(tk);
  }
  std::swap(t[7000], t[7001]);
  std::vector<double> a, u;
  for (std::size_t i = 0; i < t.size(); ++i) {
    a.push_back(angle(t[i]));
    u.push_back(torque(t[i]));
    d.sourceLines.push_back(static_cast<int>(5 + i));
  }
  d.timeStamps = t;
  d.startTime = t.front();
  d.channels = {{columns::kTorqueRef, "N m", ChannelRole::Input, u},
                {columns::kMotorAngle, "rad", ChannelRole::Output, a}};
  return r;
}

double worstError(const IdData& d, const char* channel, double (*truth)(double), std::size_t skip) {
  double worst = 0.0;
  const auto& v = d.channel(channel)->values;
  for (std::size_t i = skip; i + skip < v.size(); ++i) worst = std::max(worst, std::abs(v[i] - truth(d.timeAt(i))));
  return worst;
}

UniformGridOptions at(double rate, InterpolationMethod m = InterpolationMethod::BandLimited) {
  UniformGridOptions o;
  o.rateHz = rate;
  o.method = m;
  return o;
}

}  // namespace

TEST(UniformGrid, UniformLogAtAnotherRateIsTheResamplerAndDecimationIsItsUpOneCase) {
  IdData d = uniformLog(2000, 0.0, 9001);
  d.estimationRange = SampleRange{1000, 5001};
  auto r = resampleToUniform(d, at(1500));
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  EXPECT_EQ(r.data.samples(), 6751u) << "floor(9000 * 3 / 4) + 1";
  EXPECT_NEAR(r.data.sampleTime, 1.0 / 1500, 1e-18);
  EXPECT_EQ(r.data.meta("sample_rate_hz"), "1500");
  ASSERT_TRUE(r.data.estimationRange);
  EXPECT_EQ(r.data.estimationRange->begin, 750u) << "0.5 s";
  EXPECT_EQ(r.data.estimationRange->end, 3751u) << "2.5 s inclusive";
  ResampleOptions ro;
  ro.up = 3;
  ro.down = 4;
  ro.outputs = 6751;
  EXPECT_EQ(r.data.channel(columns::kMotorAngle)->values, resample(d.channel(columns::kMotorAngle)->values, ro));
  EXPECT_LT(worstError(r.data, columns::kMotorAngle, angle, 100), 1.2e-4);
  EXPECT_NE(r.message.find("2000 Hz -> 1500 Hz (up 3, down 4; anti-alias FIR, 80 dB from 750 Hz)"), std::string::npos) << r.message;
  EXPECT_EQ(r.data.input()->name, columns::kTorqueRef);

  r = resampleToUniform(d, at(200));
  DecimateOptions dec;
  const IdData y = decimate(d, dec);
  ASSERT_EQ(r.data.samples(), y.samples());
  for (const char* c : {columns::kTorqueRef, columns::kMotorAngle})
    EXPECT_EQ(r.data.channel(c)->values, y.channel(c)->values) << c;
  EXPECT_EQ(r.data.estimationRange->begin, y.estimationRange->begin);
  EXPECT_EQ(r.data.estimationRange->end, y.estimationRange->end);

  r = resampleToUniform(d, at(0));  // keeps the rate: nothing changes
  EXPECT_EQ(r.data.channel(columns::kMotorAngle)->values, d.channel(columns::kMotorAngle)->values);
  EXPECT_NE(r.message.find("kept at 2000 Hz"), std::string::npos) << r.message;
}

TEST(UniformGrid, IrregularLogOntoItsGridByEachMethod) {
  const Irregular in = irregularLog();
  double errors[3] = {};
  for (auto m : {InterpolationMethod::Linear, InterpolationMethod::Pchip, InterpolationMethod::BandLimited}) {
    const auto r = resampleToUniform(in.data, at(2000, m));
    ASSERT_EQ(r.termination, Termination::Converged) << r.message;
    EXPECT_TRUE(r.data.isUniform());
    EXPECT_EQ(r.data.samples(), 8000u);
    EXPECT_NEAR(r.data.startTime, 0.0, 1e-12);
    EXPECT_EQ(r.filled, in.dropped) << toString(m);
    EXPECT_EQ(r.retimed, in.jittered) << toString(m);
    EXPECT_NEAR(r.longestGapBridged, 0.002, 1e-12);
    EXPECT_NEAR(r.longestGapTime, 5003 * 0.0005, 1e-12);
    ASSERT_EQ(r.groups.size(), 1u);
    EXPECT_EQ(r.groups[0].timing.gaps, 4u);
    EXPECT_EQ(r.groups[0].timing.duplicates, 1u);
    EXPECT_EQ(r.groups[0].timing.reversals, 1u);
    EXPECT_NE(r.message.find("7 grid points filled and " + std::to_string(in.jittered) + " samples retimed (" +
                             toString(m) + ")"), std::string::npos) << r.message;
    EXPECT_NE(r.message.find("longest gap bridged 2 ms at 2.5015 s"), std::string::npos) << r.message;
    errors[static_cast<int>(m)] = std::max(worstError(r.data, columns::kMotorAngle, angle, 40),
                                           worstError(r.data, columns::kTorqueRef, torque, 40));
  }
  // The band-limited method recovers the signal, PCHIP and linear only roughly.
  EXPECT_LT(errors[2], 2e-4);
  EXPECT_GT(errors[1], 50 * errors[2]);
  EXPECT_GT(errors[0], errors[1]);
}

TEST(UniformGrid, IrregularLogAtAnotherRate) {
  const auto r = resampleToUniform(irregularLog().data, at(1500));
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  EXPECT_EQ(r.data.samples(), 6000u);
  EXPECT_LT(worstError(r.data, columns::kMotorAngle, angle, 100), 3e-4);
  EXPECT_LT(worstError(r.data, columns::kTorqueRef, torque, 100), 3e-4);
}

TEST(UniformGrid, GapAboveTheLimitIsRefusedWithItsPlace) {
  auto o = at(2000);
  o.maxGapSeconds = 0.0015;
  const auto r = resampleToUniform(irregularLog().data, o);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("the gap of 2 ms before the sample at 2.5015 s, line 5001 is longer than the limit of 1.5 ms"),
            std::string::npos) << r.message;
  o.maxGapSeconds = 0.0;  // ten intervals: 5 ms
  EXPECT_EQ(resampleToUniform(irregularLog().data, o).termination, Termination::Converged);
}

TEST(UniformGrid, TwoLogsOfOneExperimentOnTheFirstLogsTimeBase) {
  const IdData a = uniformLog(2000, 0.0, 8001);  // 0 .. 4 s
  IdData b;  // a 4 kHz accelerometer log starting 0.13 ms after the drive log's 0.1 s
  b.sampleTime = 0.00025;
  b.startTime = 0.10013;
  std::vector<double> acc(14000), ang(14000);
  for (std::size_t i = 0; i < acc.size(); ++i) {
    acc[i] = accel(b.timeAt(i));
    ang[i] = angle(b.timeAt(i));
  }
  b.setChannel({columns::kMotorAngle, "", ChannelRole::Output, ang});
  b.setChannel({columns::kArmAccel, "", ChannelRole::None, acc});
  const auto r = resampleToUniform({&a, &b}, at(0));
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const IdData& d = r.data;
  EXPECT_NEAR(d.startTime, 0.1005, 1e-12) << "the first grid point of the drive log in both";
  EXPECT_EQ(d.samples(), static_cast<std::size_t>(std::floor((0.10013 + 13999 * 0.00025 - 0.1005) * 2000 + 1e-9)) + 1);
  ASSERT_EQ(d.channels.size(), 4u);
  EXPECT_EQ(d.channels[0].name, columns::kTorqueRef);
  EXPECT_EQ(d.channels[2].name, "log2_motor_angle_rad");
  EXPECT_EQ(d.channels[2].role, ChannelRole::None) << "the first log keeps the output";
  EXPECT_EQ(d.channels[3].name, columns::kArmAccel);
  EXPECT_EQ(d.output()->name, columns::kMotorAngle);
  // The drive log's samples are copied; the accelerometer's are filtered and shifted.
  EXPECT_EQ(d.channel(columns::kMotorAngle)->values.front(), a.channel(columns::kMotorAngle)->values[201]);
  EXPECT_LT(worstError(d, columns::kArmAccel, accel, 60), 2e-4);
  EXPECT_LT(worstError(d, "log2_motor_angle_rad", angle, 60), 2e-4);
  EXPECT_NEAR(r.groups[1].offsetSamples, (0.1005 - 0.10013) / 0.00025, 1e-9);
  EXPECT_EQ(r.groups[1].factor.down, 2);

  IdData late = b;
  late.startTime = 10.0;
  const auto none = resampleToUniform({&a, &late}, at(0));
  EXPECT_EQ(none.termination, Termination::Failed);
  EXPECT_NE(none.message.find("do not overlap"), std::string::npos) << none.message;
}

TEST(UniformGrid, ChannelsAtDifferentRatesInOneLog) {
  // Rows at 4 kHz; the angle is logged at every row, the torque at every second row from the
  // second one (2 kHz, starting 0.25 ms late): empty (NaN) elsewhere.
  IdData d;
  d.sampleTime = 0.00025;
  const std::size_t n = 12000;
  std::vector<double> a(n), u(n, std::nan(""));
  for (std::size_t i = 0; i < n; ++i) {
    d.timeStamps.push_back(i * 0.00025);
    a[i] = angle(i * 0.00025);
    if (i % 2 == 1) u[i] = torque(i * 0.00025);
  }
  d.channels = {{columns::kMotorAngle, "rad", ChannelRole::Output, a},
                {columns::kTorqueRef, "N m", ChannelRole::Input, u}};
  ASSERT_TRUE(d.isValid());
  const auto r = resampleToUniform(d, at(2000));
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  ASSERT_EQ(r.groups.size(), 2u);
  EXPECT_FALSE(r.groups[0].irregular);
  EXPECT_NEAR(r.groups[0].sourceRateHz, 4000, 1e-9);
  EXPECT_NEAR(r.groups[1].sourceRateHz, 2000, 1e-9);
  EXPECT_NEAR(r.data.startTime, 0.0005, 1e-12) << "where both channels have samples";
  EXPECT_EQ(r.data.channels[0].name, columns::kMotorAngle);
  EXPECT_LT(worstError(r.data, columns::kMotorAngle, angle, 60), 2e-4);
  EXPECT_LT(worstError(r.data, columns::kTorqueRef, torque, 60), 2e-4);
}

TEST(UniformGrid, PreprocessingRefusesIrregularStampsWithoutTheStepAndCancels) {
  const Irregular in = irregularLog();
  PreprocessOptions p;
  auto r = runPreprocess(in.data, p);
  EXPECT_EQ(r.termination, Termination::Failed);
  EXPECT_NE(r.message.find("resample the log onto a uniform grid first"), std::string::npos) << r.message;
  EXPECT_THROW(preprocess(in.data, p), std::invalid_argument);
  p.resample = at(2000);
  p.differentiateAngle = true;
  p.decimation.factor = 10;
  r = runPreprocess(in.data, p);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  EXPECT_EQ(r.data.samples(), 800u);
  ASSERT_TRUE(r.resampling);
  EXPECT_EQ(r.resampling->filled, 7u);
  EXPECT_EQ(r.message, r.resampling->message);
  const auto cancelled = resampleToUniform(in.data, at(2000), [](double, const std::string&) { return ProgressAction::Abort; });
  EXPECT_EQ(cancelled.termination, Termination::Cancelled);
}
