// Preprocessing against analytic cases: derivative of a sinusoid, decimation of a two-tone
// signal, trend removal, spectra, and the data object's ranges.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "core/signal/preprocess.h"
#include "tones.h"

using namespace flexarm;

namespace {

using flexarm::testing::amplitudeAt;
using flexarm::testing::kPi;
using flexarm::testing::tone;


double db(double ratio) { return 20.0 * std::log10(ratio); }

}  // namespace

TEST(Differentiate, SinusoidIsSecondOrderAccurate) {
  // d/dt sin(w t) = w cos(w t); the central difference error is w^3 h^2 / 6.
  const double w = 2 * kPi * 5.0;
  double previous = 0.0;
  for (double fs : {500.0, 1000.0, 2000.0}) {
    const double h = 1.0 / fs;
    std::vector<double> x(static_cast<std::size_t>(fs));
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(w * i * h);
    const auto d = differentiate(x, h);
    double err = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) err = std::max(err, std::abs(d[i] - w * std::cos(w * i * h)));
    EXPECT_LT(err, w * w * w * h * h / 6.0 * 2.5) << "fs " << fs;  // ends are one-sided
    if (previous > 0) {
      EXPECT_NEAR(previous / err, 4.0, 0.5) << "halving h quarters the error";
    }
    previous = err;
  }
}

TEST(Differentiate, AddsMotorVelocityAsOutput) {
  IdData d;
  d.sampleTime = 0.001;
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, std::vector<double>(100)});
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, std::vector<double>(100)});
  for (std::size_t i = 0; i < 100; ++i) d.channel(columns::kMotorAngle)->values[i] = 3.0 * i * 0.001;
  IdData v = addDerivative(d);
  ASSERT_NE(v.channel(columns::kMotorVelocity), nullptr);
  EXPECT_EQ(v.output()->name, columns::kMotorVelocity);
  EXPECT_EQ(v.channel(columns::kMotorAngle)->role, ChannelRole::None);
  EXPECT_EQ(v.channel(columns::kMotorVelocity)->unit, "rad/s");
  for (double x : v.channel(columns::kMotorVelocity)->values) EXPECT_NEAR(x, 3.0, 1e-9);
  EXPECT_THROW(addDerivative(d, "no_such_channel"), std::invalid_argument);
}

TEST(Decimate, FirSuppressesToneAboveNewNyquistBy60dB) {
  // 2 kHz decimated by 10: the new Nyquist frequency is 100 Hz. A 20 Hz tone must pass, a
  // 105 Hz and a 130 Hz tone (aliasing to 95 and 70 Hz) must be suppressed >= 60 dB.
  const double fs = 2000.0;
  const std::size_t n = 40000;
  for (double high : {105.0, 130.0, 400.0}) {
    SCOPED_TRACE(high);
    std::vector<double> x = tone(n, fs, 20.0, 1.0);
    const auto hi = tone(n, fs, high, 1.0, 1.1);
    for (std::size_t i = 0; i < n; ++i) x[i] += hi[i];
    DecimateOptions o;
    o.factor = 10;
    const auto y = decimate(x, o);
    ASSERT_EQ(y.size(), n / 10);
    const double alias = std::abs(200.0 * std::round(high / 200.0) - high);
    const double kept = amplitudeAt(y, 200.0, 20.0, 100);
    const double leaked = amplitudeAt(y, 200.0, alias, 100);
    EXPECT_NEAR(db(kept), 0.0, 0.05) << "passband tone keeps its amplitude";
    EXPECT_LT(db(leaked / kept), -60.0) << "alias at " << alias << " Hz";
  }
}

TEST(Decimate, ChebyshevAndNoFilterBehaveAsTheirNamesSay) {
  const double fs = 2000.0;
  const std::size_t n = 40000;
  std::vector<double> x = tone(n, fs, 20.0, 1.0);
  const auto hi = tone(n, fs, 130.0, 1.0, 1.1);
  for (std::size_t i = 0; i < n; ++i) x[i] += hi[i];
  DecimateOptions o;
  o.factor = 10;
  o.filter = AntiAliasFilter::Chebyshev;
  auto y = decimate(x, o);
  EXPECT_NEAR(db(amplitudeAt(y, 200.0, 20.0, 100)), 0.0, 0.1);
  EXPECT_LT(db(amplitudeAt(y, 200.0, 70.0, 100)), -60.0);
  o.filter = AntiAliasFilter::None;
  y = decimate(x, o);
  EXPECT_GT(db(amplitudeAt(y, 200.0, 70.0, 100)), -1.0) << "without a filter the tone aliases";
}

TEST(Decimate, ConstantPassesUntouchedAtTheEnds) {
  std::vector<double> x(997, 2.5);
  for (AntiAliasFilter f : {AntiAliasFilter::Fir, AntiAliasFilter::Chebyshev}) {
    DecimateOptions o;
    o.factor = 7;
    o.filter = f;
    for (double v : decimate(x, o)) EXPECT_NEAR(v, 2.5, 1e-9) << toString(f);
  }
}

TEST(Decimate, FirDesignMeetsItsStopband) {
  const auto h = designLowpassFir(0.04, 0.05, 80.0);
  ASSERT_EQ(h.size() % 2, 1u);
  double worst = 0.0, pass = 0.0;
  for (double f = 0.0; f <= 0.5; f += 0.0005) {
    std::complex<double> H = 0;
    for (std::size_t k = 0; k < h.size(); ++k) H += h[k] * std::exp(std::complex<double>(0, -2 * kPi * f * k));
    if (f >= 0.05) worst = std::max(worst, std::abs(H));
    if (f <= 0.04) pass = std::max(pass, std::abs(std::abs(H) - 1.0));
  }
  EXPECT_LT(db(worst), -79.0);
  EXPECT_LT(pass, 1e-3);
  EXPECT_THROW(designLowpassFir(0.2, 0.1, 60), std::invalid_argument);
}

TEST(Decimate, DataKeepsRangesAndRate) {
  IdData d;
  d.sampleTime = 0.0005;
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, tone(4000, 2000, 3, 1)});
  d.estimationRange = SampleRange{1000, 3001};
  DecimateOptions o;
  o.factor = 10;
  IdData y = decimate(d, o);
  EXPECT_DOUBLE_EQ(y.sampleTime, 0.005);
  EXPECT_EQ(y.samples(), 400u);
  ASSERT_TRUE(y.estimationRange);
  EXPECT_EQ(y.estimationRange->begin, 100u);
  EXPECT_EQ(y.estimationRange->end, 301u);
  EXPECT_EQ(y.meta("sample_rate_hz"), "200");
  o.factor = 0;
  EXPECT_THROW(decimate(d, o), std::invalid_argument);
}

TEST(Detrend, RemovesMeanAndLine) {
  std::vector<double> x(101);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 4.0 + 0.25 * i + std::sin(0.7 * i);
  const auto m = detrend(x, Detrend::Mean);
  double mean = 0;
  for (double v : m) mean += v;
  EXPECT_NEAR(mean / m.size(), 0.0, 1e-12);
  // Removing a line is linear: the line itself vanishes and x leaves what the sinusoid leaves.
  std::vector<double> line(x.size()), wave(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    line[i] = 4.0 + 0.25 * i;
    wave[i] = std::sin(0.7 * i);
  }
  for (double v : detrend(line, Detrend::Linear)) EXPECT_NEAR(v, 0.0, 1e-12);
  const auto l = detrend(x, Detrend::Linear), lw = detrend(wave, Detrend::Linear);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(l[i], lw[i], 1e-12);
  EXPECT_GT(std::abs(m[100] - m[0]), 20.0) << "mean removal keeps the slope";
}

TEST(Spectrum, SinusoidPeakHasItsAmplitude) {
  const auto x = tone(20000, 1000.0, 50.0, 0.7);
  const auto s = amplitudeSpectrum(x, 0.001, 4000);
  ASSERT_FALSE(s.frequencyHz.empty());
  std::size_t peak = 0;
  for (std::size_t i = 1; i < s.amplitude.size(); ++i)
    if (s.amplitude[i] > s.amplitude[peak]) peak = i;
  EXPECT_NEAR(s.frequencyHz[peak], 50.0, 0.25);
  EXPECT_NEAR(s.amplitude[peak], 0.7, 0.7 * 0.02);
  EXPECT_NEAR(s.frequencyHz.back(), 500.0, 1e-9);
}

TEST(Preprocess, AppliesStepsInTheSeedsOrder) {
  IdData d;
  d.sampleTime = 0.0005;
  std::vector<double> angle(20000), torque = tone(20000, 2000, 4, 0.2);
  for (std::size_t i = 0; i < angle.size(); ++i) angle[i] = 0.1 + 2.0 * i * 0.0005;  // 2 rad/s
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, angle});
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, torque});
  PreprocessOptions o;
  o.differentiateAngle = true;
  o.range = SampleRange{2000, 12000};
  o.decimation.factor = 10;
  o.detrend = Detrend::None;
  IdData p = preprocess(d, o);
  EXPECT_EQ(p.samples(), 1000u);
  EXPECT_NEAR(p.startTime, 1.0, 1e-12);
  for (double v : p.channel(columns::kMotorVelocity)->values) EXPECT_NEAR(v, 2.0, 1e-6);
  o.detrend = Detrend::Mean;
  p = preprocess(d, o);
  for (double v : p.channel(columns::kMotorVelocity)->values) EXPECT_NEAR(v, 0.0, 1e-6);
}

TEST(IdData, RangesFromTimesAndSelection) {
  IdData d;
  d.sampleTime = 0.5;
  d.startTime = 10.0;
  d.setChannel({"a_rad", "", ChannelRole::None, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}});
  EXPECT_EQ(d.rangeForTimes(11.0, 12.0), (SampleRange{2, 5}));
  EXPECT_EQ(d.rangeForTimes(12.0, 11.0), (SampleRange{2, 5}));
  EXPECT_EQ(d.rangeForTimes(0.0, 100.0), (SampleRange{0, 10}));
  EXPECT_EQ(d.rangeForTimes(11.1, 11.4).size(), 0u);
  d.validationRange = SampleRange{6, 10};
  IdData s = d.select({4, 8});
  EXPECT_EQ(s.samples(), 4u);
  EXPECT_DOUBLE_EQ(s.startTime, 12.0);
  ASSERT_TRUE(s.validationRange);
  EXPECT_EQ(*s.validationRange, (SampleRange{2, 4}));
  std::string why;
  EXPECT_TRUE(d.isValid(&why));
  d.channels[0].values[3] = std::nan("");
  EXPECT_FALSE(d.isValid(&why));
  EXPECT_NE(why.find("sample 3"), std::string::npos);
  EXPECT_THROW(d.setChannel({"short", "", ChannelRole::None, {1, 2}}), std::invalid_argument);
}
