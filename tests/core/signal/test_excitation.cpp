// The one check of dead data (core/signal/excitation.h): what it refuses, in which words, and
// that ordinary signals pass.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/ident/fit_data.h"
#include "core/signal/excitation.h"

namespace flexarm {
namespace {

std::vector<double> wave(std::size_t n, double scale, double offset = 0.0) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = offset + scale * std::sin(0.05 * static_cast<double>(i));
  return v;
}

IdData log(std::vector<double> u, std::vector<double> y) {
  IdData d;
  d.sampleTime = 0.0005;
  d.setChannel({"torque_ref_nm", "N m", ChannelRole::Input, std::move(u)});
  d.setChannel({"motor_angle_rad", "rad", ChannelRole::Output, std::move(y)});
  return d;
}

TEST(Excitation, OrdinarySignalsPassAtAnyReasonableScale) {
  for (double scale : {1e-9, 1e-3, 1.0, 1e6, 1e12}) {
    SCOPED_TRACE(scale);
    EXPECT_EQ(deadSignalProblem(wave(500, scale)), "");
  }
  EXPECT_EQ(deadSignalProblem(wave(500, 1e-3, 1000.0)), "");  // a small motion at a large reading
  EXPECT_EQ(deadDataProblem(log(wave(500, 1.0), wave(500, 2.0))), "");
}

TEST(Excitation, DeadSignalsAreNamedWithWhatIsWrong) {
  EXPECT_EQ(deadSignalProblem(std::vector<double>(300, 1.25)), "is constant (every sample is 1.25)");
  EXPECT_EQ(deadSignalProblem({}), "holds no samples");
  std::vector<double> huge(100);
  for (std::size_t i = 0; i < huge.size(); ++i) huge[i] = i % 2 ? 1e308 : -1e308;
  EXPECT_NE(deadSignalProblem(huge).find("reaches 1e+308 in magnitude, too large for its squares"), std::string::npos);
  EXPECT_NE(deadSignalProblem(wave(100, 1e-315)).find("too small for its squares to be told from zero"),
            std::string::npos);
  std::vector<double> stuck(100, 1000.0);
  stuck[7] = std::nextafter(1000.0, 2000.0);
  EXPECT_NE(deadSignalProblem(stuck).find("(constant to 12 digits: a stuck sensor)"), std::string::npos);
  std::vector<double> nan = wave(50, 1.0);
  nan[9] = NAN;
  EXPECT_EQ(deadSignalProblem(nan), "has a value that is not a finite number at sample 10");
}

TEST(Excitation, TheFirstDeadChannelIsNamedAndTheDataPreparationRefusesIt) {
  const IdData stuck = log(wave(500, 1.0), std::vector<double>(500, 0.5));
  EXPECT_EQ(deadDataProblem(stuck), "the channel motor_angle_rad carries no signal: it is constant (every sample is 0.5)");
  const IdData silent = log(std::vector<double>(500, 0.0), wave(500, 1.0));
  EXPECT_EQ(deadDataProblem(silent), "the channel torque_ref_nm carries no signal: it is constant (every sample is 0)");
  EXPECT_EQ(deadDataProblem(silent, {"motor_angle_rad"}), "");  // only the channels named
  // The preparation every fit, recursive estimate, discovery and diagnosis goes through.
  FitDataOptions o;
  const PreparedData p = prepareFitData(stuck, o);
  EXPECT_FALSE(p.ok());
  EXPECT_EQ(p.message, deadDataProblem(stuck));
}

TEST(Excitation, AStuckArmEncoderIsDeadDataToo) {
  IdData d = log(wave(500, 1.0), wave(500, 2.0));
  d.setChannel({"arm_angle_rad", "rad", ChannelRole::None, std::vector<double>(500, 0.25)});
  EXPECT_EQ(deadDataProblem(d), "the channel arm_angle_rad carries no signal: it is constant (every sample is 0.25)");
  FitDataOptions o;
  EXPECT_EQ(prepareFitData(d, o).message, deadDataProblem(d));
  d.setChannel({"arm_angle_rad", "rad", ChannelRole::None, wave(500, 0.5)});
  EXPECT_EQ(deadDataProblem(d), "");
}

}  // namespace
}  // namespace flexarm
