// The rational polyphase resampler against facts: the decimation it replaced (stored outputs),
// scipy.signal.resample_poly on the same factors (stored reference numbers), the stated
// stopband, a band-limited round trip, and parallel runs equal to serial ones.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "core/signal/preprocess.h"
#include "core/signal/resample.h"
#include "tones.h"

using namespace flexarm;

namespace {

using flexarm::testing::amplitudeAt;
using flexarm::testing::kPi;
using flexarm::testing::tone;

// Rows of a reference CSV (comment line, header, then numbers), split on commas.
std::vector<std::vector<std::string>> readCsv(const std::string& name) {
  std::ifstream in(std::string(FLEXARM_TEST_DATA_DIR) + "/signal/" + name);
  EXPECT_TRUE(in.good()) << name;
  std::vector<std::vector<std::string>> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

// The input of scipy_resample_poly.csv (make_scipy_reference.py), at any position.
double scipyInput(double i) {
  return 0.8 * std::sin(2 * kPi * 0.004 * i + 0.3) + 0.3 * std::sin(2 * kPi * 0.011 * i + 1.1) +
         0.1 * std::sin(2 * kPi * 0.023 * i + 0.5);
}


ResampleOptions factors(int up, int down) {
  ResampleOptions o;
  o.up = up;
  o.down = down;
  return o;
}

}  // namespace

TEST(Resample, DecimationIsTheDirectConvolutionItReplacesUpToRounding) {
  // decimate_before_polyphase.csv holds the outputs of the direct convolution (and of the
  // Chebyshev and plain paths) before decimation became the up = 1 case of the resampler.
  std::vector<double> x(601);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = i / 2000.0;
    x[i] = 0.7 * std::sin(2 * kPi * 13 * t + 0.2) + 0.2 * std::sin(2 * kPi * 170 * t) +
           0.05 * std::sin(2 * kPi * 830 * t + 1.0) + 0.3 * t;
  }
  std::map<std::pair<std::string, int>, std::vector<double>> expected;
  for (const auto& row : readCsv("decimate_before_polyphase.csv"))
    expected[{row[0], std::stoi(row[1])}].push_back(std::stod(row[3]));
  ASSERT_EQ(expected.size(), 9u);
  for (const auto& [key, values] : expected) {
    DecimateOptions o;
    o.filter = *antiAliasFilterFromString(key.first);
    o.factor = key.second;
    const auto y = decimate(x, o);
    ASSERT_EQ(y.size(), values.size()) << key.first << " " << key.second;
    double worst = 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) worst = std::max(worst, std::abs(y[k] - values[k]));
    EXPECT_LT(worst, 1e-13) << key.first << " by " << key.second;
  }
}

TEST(Resample, AgreesWithScipyResamplePolyToFilterDesignTolerance) {
  // SciPy's default filter (Kaiser, beta 5, cutoff at the new Nyquist frequency) is off the
  // ideal by up to 1.2e-3 here, ours (80 dB, passband to 0.8 of it) by 1e-4 of the 1.2 peak:
  // away from the ends, where SciPy pads with zeros, the two agree within 2e-3.
  std::map<std::pair<int, int>, std::vector<double>> scipy;
  for (const auto& row : readCsv("scipy_resample_poly.csv"))
    scipy[{std::stoi(row[0]), std::stoi(row[1])}].push_back(std::stod(row[3]));
  ASSERT_EQ(scipy.size(), 4u);
  std::vector<double> x(800);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = scipyInput(static_cast<double>(i));
  for (const auto& [key, ref] : scipy) {
    const auto [up, down] = key;
    const auto y = resample(x, factors(up, down));
    ASSERT_EQ(y.size(), ref.size()) << up << "/" << down << ": ceil(n up / down) outputs";
    // Away from the ends by the longer of the two filters' half lengths.
    const std::size_t half = static_cast<std::size_t>(resampleFilterTaps(factors(up, down)) / 2 / down) + 1;
    const std::size_t skip = std::max(ref.size() * 15 / 100, half);
    double offScipy = 0.0, offIdeal = 0.0;
    for (std::size_t k = skip; k + skip < ref.size(); ++k) {
      offScipy = std::max(offScipy, std::abs(y[k] - ref[k]));
      offIdeal = std::max(offIdeal, std::abs(y[k] - scipyInput(static_cast<double>(k) * down / up)));
    }
    EXPECT_LT(offScipy, 2e-3) << up << "/" << down;
    EXPECT_LT(offIdeal, 1.2e-4) << up << "/" << down;
  }
}

TEST(Resample, TonesAboveTheNewNyquistAreSuppressedByTheStatedStopband) {
  // 2000 -> 1500 Hz: the FIR passes up to 600 Hz and stops >= 80 dB from 750 Hz.
  const std::size_t n = 8000;
  for (double f : {760.0, 800.0, 900.0}) {
    const auto y = resample(tone(n, 2000.0, f, 1.0), factors(3, 4));
    double worst = 0.0;
    for (std::size_t k = 200; k + 200 < y.size(); ++k) worst = std::max(worst, std::abs(y[k]));
    EXPECT_LT(20 * std::log10(worst), -80.0) << f << " Hz";
  }
  const auto kept = resample(tone(n, 2000.0, 580.0, 1.0), factors(3, 4));
  EXPECT_NEAR(amplitudeAt(kept, 1500.0, 580.0, 200), 1.0, 2e-4) << "passband tone keeps its amplitude";
  // 1000 -> 2000 Hz: a 300 Hz tone must not leave its image at 700 Hz.
  const auto up = resample(tone(4000, 1000.0, 300.0, 1.0), factors(2, 1));
  EXPECT_NEAR(amplitudeAt(up, 2000.0, 300.0, 200), 1.0, 2e-4);
  EXPECT_LT(20 * std::log10(amplitudeAt(up, 2000.0, 700.0, 200)), -80.0);
  // 2000 -> 250 Hz (up 1, down 8): 140 Hz aliases to 110 Hz unless stopped.
  const auto down = resample(tone(16000, 2000.0, 140.0, 1.0), factors(1, 8));
  EXPECT_LT(20 * std::log10(amplitudeAt(down, 250.0, 110.0, 100)), -80.0);
}

TEST(Resample, BandLimitedSignalThereAndBackMatchesWithinTheStatedError) {
  // Content below 0.8 of the lower Nyquist frequency (600 Hz) survives 2000 -> 1500 -> 2000 Hz
  // within 2.5e-4 of its 1.5 peak (twice the passband ripple of 1e-4).
  const std::size_t n = 6000;
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i / 2000.0;
    x[i] = std::sin(2 * kPi * 37 * t) + 0.3 * std::sin(2 * kPi * 210 * t + 1) + 0.2 * std::cos(2 * kPi * 480 * t);
  }
  const auto mid = resample(x, factors(3, 4));
  const auto back = resample(mid, factors(4, 3));
  ASSERT_EQ(back.size(), n);
  double worst = 0.0;
  for (std::size_t i = 300; i + 300 < n; ++i) worst = std::max(worst, std::abs(back[i] - x[i]));
  EXPECT_LT(worst, 2.5e-4);
}

TEST(Resample, FractionalOffsetShiftsTheTimeBase) {
  // Output k at input position 0.37 + k: the band-limited value between the samples.
  std::vector<double> x(3000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = scipyInput(static_cast<double>(i));
  ResampleOptions o;
  o.offset = 10.37;
  const auto y = resample(x, o);
  ASSERT_EQ(y.size(), 2990u);
  double worst = 0.0;
  for (std::size_t k = 0; k + 100 < y.size(); ++k) worst = std::max(worst, std::abs(y[k] - scipyInput(10.37 + k)));
  EXPECT_LT(worst, 1.2e-4);
  o.filter = AntiAliasFilter::Chebyshev;
  std::string why;
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_NE(why.find("FIR"), std::string::npos) << why;
}

TEST(Resample, ChannelsInParallelEqualOneAtATime) {
  std::vector<std::vector<double>> x(3, std::vector<double>(50000));
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < x[c].size(); ++i) x[c][i] = std::sin(0.001 * (c + 1) * i) + 0.01 * std::cos(0.9 * i);
  for (auto [up, down] : {std::pair{1, 10}, std::pair{3, 4}, std::pair{2, 1}}) {
    ResampleOptions o = factors(up, down);
    o.threads = 4;
    const auto together = resample({&x[0], &x[1], &x[2]}, o);
    o.threads = 1;
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(together[c], resample(x[c], o)) << up << "/" << down;
  }
}

TEST(Resample, RationalFactorOfTwoRates) {
  auto f = rationalFactor(2000, 1500);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->up, 3);
  EXPECT_EQ(f->down, 4);
  f = rationalFactor(1000, 2000);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->up, 2);
  EXPECT_EQ(f->down, 1);
  f = rationalFactor(2000, 250);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->up, 1);
  EXPECT_EQ(f->down, 8);
  f = rationalFactor(2000, 1234.5);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->up, 2469);
  EXPECT_EQ(f->down, 4000);
  f = rationalFactor(1.0 / 0.00050000000000000001, 200);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->down, 10);
  EXPECT_FALSE(rationalFactor(2000.04, 1500)) << "1500/2000.04 = 37500/50001";
  EXPECT_THROW(rationalFactor(0, 100), std::invalid_argument);
}

TEST(Resample, RejectsWhatTheFiltersCannotDo) {
  std::string why;
  ResampleOptions o = factors(3, 4);
  o.filter = AntiAliasFilter::None;
  EXPECT_FALSE(o.isValid(&why));
  o = factors(0, 4);
  EXPECT_FALSE(o.isValid(&why));
  EXPECT_THROW(resample(std::vector<double>(10), o), std::invalid_argument);
  const std::vector<double> a(10), b(11);
  EXPECT_THROW(resample(std::vector<const std::vector<double>*>{&a, &b}, factors(1, 2)), std::invalid_argument);
  EXPECT_EQ(resampleFilterTaps(factors(1, 10)), 503) << "the seed's decimation by ten";
}
