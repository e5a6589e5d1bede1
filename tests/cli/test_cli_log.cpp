// The headless verbs info and preprocess, end to end through the executable.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "core/io/log_io.h"

using flexarm::test::runFlexarm;
using nlohmann::json;

namespace {
const std::string kSample = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const std::string kDaisy = std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat";
std::string bad(const char* f) { return std::string(FLEXARM_TEST_DATA_DIR) + "/bad/" + f; }
}  // namespace

TEST(CliLog, HelpListsVerbsAndEveryVerbExplainsItself) {
  auto r = runFlexarm({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("info"), std::string::npos);
  EXPECT_NE(r.out.find("preprocess"), std::string::npos);
  for (const char* verb : {"info", "preprocess"}) {
    auto h = runFlexarm({verb, "--help"});
    EXPECT_EQ(h.code, 0) << verb;
    EXPECT_NE(h.out.find(std::string("Usage: flexarm ") + verb), std::string::npos) << verb;
  }
  EXPECT_NE(runFlexarm({"preprocess", "--help"}).out.find("--decimate N"), std::string::npos);
}

TEST(CliLog, UsageErrorsExitWithTwo) {
  EXPECT_EQ(runFlexarm({"frobnicate"}).code, 2);
  EXPECT_EQ(runFlexarm({"info"}).code, 2);
  EXPECT_EQ(runFlexarm({"info", kSample, "--no-such-option"}).code, 2);
  auto r = runFlexarm({"preprocess", kSample, "--decimate", "0", "--out", "/tmp/x.csv"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--decimate expects a whole number from 1 to"), std::string::npos) << r.err;
  r = runFlexarm({"preprocess", kSample, "--decimate", "ten", "--out", "/tmp/x.csv"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--decimate expects a whole number"), std::string::npos) << r.err;
  EXPECT_EQ(runFlexarm({"preprocess", kSample, "--decimate", "10"}).code, 2) << "--out missing";
}

TEST(CliLog, InfoPrintsChannelsRateAndLength) {
  auto r = runFlexarm({"info", kSample, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  json j = json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["sample_rate_hz"].get<double>(), 2000.0);
  EXPECT_EQ(j["samples"].get<int>(), 36000);
  EXPECT_TRUE(j["closed_loop"].get<bool>());
  std::vector<std::string> names;
  for (const auto& c : j["channels"]) names.push_back(c["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"motor_angle_rad", "torque_ref_nm", "angle_ref_rad"}));
  EXPECT_EQ(j["channels"][1]["role"], "input");
  EXPECT_EQ(j["channels"][0]["unit"], "rad");
  EXPECT_FALSE(j["metadata"]["gear_ratio"].get<std::string>().empty());
  EXPECT_TRUE(j["ranges"]["estimation"].is_null());
}

TEST(CliLog, InfoReadsHeaderlessTableWithMapping) {
  auto r = runFlexarm({"info", kDaisy, "--input-column", "1", "--output-column", "2",
                       "--sample-time", "0.1", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  json j = json::parse(r.out);
  EXPECT_EQ(j["samples"].get<int>(), 1024);
  EXPECT_DOUBLE_EQ(j["sample_rate_hz"].get<double>(), 10.0);
  EXPECT_FALSE(j["closed_loop"].get<bool>());
}

TEST(CliLog, BadInputExitsWithThreeNamingFileLineAndColumn) {
  auto r = runFlexarm({"info", bad("non_numeric.csv"), "--json"});
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(r.out.empty()) << "nothing on stdout for bad input";
  EXPECT_NE(r.err.find("non_numeric.csv:5: column 3 (torque_ref_nm): 'abc' is not a number"),
            std::string::npos)
      << r.err;
  r = runFlexarm({"preprocess", bad("irregular_sampling.csv"), "--decimate", "2", "--out", "/tmp/y.csv"});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("irregular_sampling.csv:6"), std::string::npos) << r.err;
}

TEST(CliLog, PreprocessDecimatesDetrendsAndWritesALog) {
  const std::string out = (flexarm::test::scratchDir() / "pre.csv").string();
  auto r = runFlexarm({"preprocess", kSample, "--differentiate", "--decimate", "10", "--detrend",
                       "--range", "1:15", "--out", out, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  json j = json::parse(r.out);
  EXPECT_EQ(j["samples_out"].get<int>(), 2801);
  flexarm::LogReadResult back = flexarm::readLog(out);
  ASSERT_TRUE(back.ok) << back.error.toString();
  EXPECT_NEAR(back.data.sampleRateHz(), 200.0, 1e-9);
  EXPECT_EQ(back.data.samples(), 2801u);
  EXPECT_NEAR(back.data.startTime, 1.0, 1e-9);
  ASSERT_NE(back.data.output(), nullptr);
  EXPECT_EQ(back.data.output()->name, "motor_velocity_rad_s");
  double mean = 0;
  for (double v : back.data.input()->values) mean += v;
  EXPECT_NEAR(mean / back.data.samples(), 0.0, 1e-12);
  EXPECT_EQ(back.data.meta("preprocessed_from"), kSample);
}
