// flexarm preprocess --resample end to end: the irregular sample log reported exactly and
// filled, the gap limit, a rate change of a regular log, two logs on one time base and
// channels at different rates in one file.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "core/io/log_io.h"

using flexarm::test::runFlexarm;
using nlohmann::json;

namespace {
const std::string kChirp = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const std::string kMultisine = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_validation_multisine.csv";
// Data rows 3000 and 7000-7002 dropped, row 5000 stamped 15 us late, row 9000 written twice,
// rows 10000 and 10001 swapped (sample_logs/README.md); the data start on line 15.
const std::string kIrregular = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_irregular_timing.csv";
}  // namespace

TEST(CliResample, ReadingStaysStrictAndNamesEveryIrregularity) {
  const auto r = runFlexarm({"info", kIrregular});
  EXPECT_EQ(r.code, 3);
  for (const char* part : {"three_mass_irregular_timing.csv:9012: column 1 (time_s): time 4.5 does not increase",
                           "2 gaps (4 samples missing, the longest 2 ms at 3.5015 s, line 7014)",
                           "1 jittered sample (up to 3 % of the interval)", "1 duplicate time stamp and 1 reversal",
                           "flexarm preprocess --resample"})
    EXPECT_NE(r.err.find(part), std::string::npos) << part << " in " << r.err;
}

TEST(CliResample, IrregularLogIsReportedExactlyAndFilled) {
  const std::string out = (flexarm::test::scratchDir() / "regular.csv").string();
  const auto r = runFlexarm({"preprocess", kIrregular, "--resample", "2000", "--json", "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["samples_in"].get<int>(), 11997);
  EXPECT_EQ(j["samples_out"].get<int>(), 12000);
  const json& s = j["resample"];
  EXPECT_EQ(s["method"], "bandlimited");
  EXPECT_EQ(s["filled"].get<int>(), 4);
  EXPECT_EQ(s["retimed"].get<int>(), 1);
  EXPECT_NEAR(s["longest_gap_bridged_s"].get<double>(), 0.002, 1e-12);
  EXPECT_NEAR(s["longest_gap_at_s"].get<double>(), 3.5015, 1e-12);
  ASSERT_EQ(s["groups"].size(), 1u);
  const json& events = s["groups"][0]["events"];
  ASSERT_EQ(events.size(), 5u);
  const char* kinds[] = {"gap", "jitter", "gap", "duplicate", "reversal"};
  const int lines[] = {3015, 5014, 7014, 9012, 10013};
  const double times[] = {1.5005, 2.500015, 3.5015, 4.5, 5.0};
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(events[i]["kind"], kinds[i]) << i;
    EXPECT_EQ(events[i]["line"].get<int>(), lines[i]) << i;
    EXPECT_NEAR(events[i]["time_s"].get<double>(), times[i], 1e-9) << i;
  }
  EXPECT_EQ(events[2]["missing"].get<int>(), 3);
  EXPECT_NEAR(events[1]["deviation"].get<double>(), 0.03, 1e-6);
  // The result is a regular log at 2000 Hz the strict reader accepts.
  const auto back = flexarm::readLog(out);
  ASSERT_TRUE(back.ok) << back.error.toString();
  EXPECT_EQ(back.data.samples(), 12000u);
  EXPECT_NEAR(back.data.sampleRateHz(), 2000.0, 1e-6);
}

TEST(CliResample, GapAboveTheLimitIsRefusedWithItsPlace) {
  const std::string out = (flexarm::test::scratchDir() / "refused.csv").string();
  const auto r = runFlexarm({"preprocess", kIrregular, "--resample", "2000", "--max-gap", "0.0015", "--out", out});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("the gap of 2 ms before the sample at 3.5015 s, line 7014 is longer than the limit of 1.5 ms"),
            std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(out).good()) << "no file is written";
}

TEST(CliResample, RegularLogChangesRateByARationalFactor) {
  const std::string out = (flexarm::test::scratchDir() / "1500.csv").string();
  const auto r = runFlexarm({"preprocess", kChirp, "--resample", "1500", "--json", "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["samples_out"].get<int>(), 27000) << "floor(35999 * 3 / 4) + 1";
  EXPECT_NEAR(j["sample_rate_hz"].get<double>(), 1500.0, 1e-9);
  EXPECT_EQ(j["resample"]["groups"][0]["up"].get<int>(), 3);
  EXPECT_EQ(j["resample"]["groups"][0]["down"].get<int>(), 4);
  EXPECT_EQ(j["resample"]["stopband"], "80 dB from 750 Hz");
  const auto back = flexarm::readLog(out);
  ASSERT_TRUE(back.ok) << back.error.toString();
  EXPECT_NEAR(back.data.sampleRateHz(), 1500.0, 1e-6);
}

TEST(CliResample, TwoLogsOnTheFirstLogsTimeBase) {
  const std::string out = (flexarm::test::scratchDir() / "joined.csv").string();
  const auto r = runFlexarm({"preprocess", kChirp, "--resample", "1000", "--with", kMultisine, "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto back = flexarm::readLog(out);
  ASSERT_TRUE(back.ok) << back.error.toString();
  EXPECT_EQ(back.data.samples(), 12000u) << "0 to 11.999 s, the time both cover";
  for (const char* c : {"motor_angle_rad", "torque_ref_nm", "log2_motor_angle_rad", "log2_torque_ref_nm"})
    EXPECT_NE(back.data.channel(c), nullptr) << c;
}

TEST(CliResample, ChannelsAtDifferentRatesInOneFile) {
  // Rows at 2 kHz; the torque is logged at 1 kHz (empty on every other row).
  const std::string in = (flexarm::test::scratchDir() / "two_rates.csv").string();
  {
    std::ofstream f(in);
    f << "# flexarm-log: 1\ntime_s,motor_angle_rad,torque_ref_nm\n";
    for (int k = 0; k < 4000; ++k) {
      f << k * 0.0005 << "," << std::sin(0.01 * k) << ",";
      if (k % 2 == 0) f << std::cos(0.02 * k);
      f << "\n";
    }
  }
  const std::string out = (flexarm::test::scratchDir() / "two_rates_1k.csv").string();
  auto r = runFlexarm({"preprocess", in, "--out", out});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("the field is empty"), std::string::npos) << r.err;
  r = runFlexarm({"preprocess", in, "--resample", "1000", "--json", "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["resample"]["groups"].size(), 2u);
  EXPECT_NEAR(j["resample"]["groups"][1]["rate_hz"].get<double>(), 1000.0, 1e-9);
  EXPECT_EQ(j["samples_out"].get<int>(), 2000);
}

TEST(CliResample, UsageErrors) {
  const std::string out = (flexarm::test::scratchDir() / "x.csv").string();
  EXPECT_EQ(runFlexarm({"preprocess", kChirp, "--method", "pchip", "--out", out}).code, 2);
  EXPECT_EQ(runFlexarm({"preprocess", kChirp, "--resample", "1500", "--method", "cubic", "--out", out}).code, 2);
  EXPECT_EQ(runFlexarm({"preprocess", kChirp, "--resample", "-5", "--out", out}).code, 2);
  const auto r = runFlexarm({"preprocess", kChirp, "--resample", "1234.5678", "--out", out});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("is not a ratio of whole numbers up to 10000"), std::string::npos) << r.err;
}
