// Real robots' logs on the command line: the KUKA KR300 .mat file read by MATLAB expressions
// with units, sides and the gear ratio; what was skipped or assumed printed as warnings; bad
// expressions and units refused with the file and the expression named.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"

using flexarm::test::runFlexarm;
using nlohmann::json;

namespace {

const std::string kKuka = std::string(FLEXARM_SAMPLE_DIR) + "/kuka_kr300/rec_B_data.mat";

std::vector<std::string> axisOne(std::vector<std::string> more) {
  std::vector<std::string> args = {"info",         kKuka,
                                   "--time-var",   "rec.time_cont",
                                   "--input-var",  "rec.act_torque_abs_nm(1,:)",
                                   "--output-var", "rec.act_pos_mot_deg(1,:)",
                                   "--arm-var",    "rec.act_pos_se_deg(1,:)"};
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

const json* channel(const json& j, const std::string& name) {
  for (const auto& c : j["channels"])
    if (c["name"] == name) return &c;
  return nullptr;
}

}  // namespace

TEST(CliImport, KukaAxisWithUnitsSidesAndGearRatio) {
  auto r = runFlexarm(axisOne({"--output-unit", "deg", "--output-side", "arm", "--arm-unit", "deg",
                               "--gear-ratio", "1/256.86", "--ref-var", "rec.ref_pos_deg(1,:)", "--json"}));
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["samples"].get<int>(), 2501);
  EXPECT_NEAR(j["sample_rate_hz"].get<double>(), 250.0, 1e-4);  // the file stores time in single precision
  const json* motor = channel(j, "motor_angle_rad");
  const json* arm = channel(j, "arm_angle_rad");
  const json* tau = channel(j, "torque_ref_nm");
  ASSERT_TRUE(motor && arm && tau) << r.out;
  EXPECT_EQ((*motor)["role"], "output");
  EXPECT_EQ((*tau)["role"], "input");
  const json* ref = channel(j, "angle_ref_rad");
  ASSERT_TRUE(ref) << r.out;
  EXPECT_EQ((*ref)["role"], "reference");
  EXPECT_TRUE(j["closed_loop"].get<bool>());
  // The motor shaft turns 256.86 times the arm: its range is that many times the arm's.
  const double motorSpan = (*motor)["max"].get<double>() - (*motor)["min"].get<double>();
  const double armSpan = (*arm)["max"].get<double>() - (*arm)["min"].get<double>();
  EXPECT_NEAR(motorSpan / armSpan, 256.86, 0.05 * 256.86);
  EXPECT_NEAR(std::stod(j["metadata"]["gear_ratio"].get<std::string>()), 1 / 256.86, 1e-12);
  EXPECT_EQ(j["metadata"]["axis"], "rotary");
  // The object beside the signals is skipped with a warning, not a refusal.
  EXPECT_NE(r.err.find("warning: " + kKuka + ": skipped KR300 (a MATLAB object of class SerialLink)"),
            std::string::npos)
      << r.err;
}

TEST(CliImport, WhatIsNotSaidIsAWarning) {
  auto r = runFlexarm(axisOne({"--json"}));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("the output rec.act_pos_mot_deg(1,:) is read as stored"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the input rec.act_torque_abs_nm(1,:) is read as stored: a physical model takes it as the "
                       "motor torque in N m"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("the arm angle rec.act_pos_se_deg(1,:) is taken in rad"), std::string::npos) << r.err;
  r = runFlexarm(axisOne({"--output-unit", "deg", "--json"}));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("its side was not given (--output-side motor|arm)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no gear ratio was given"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("the input rec.act_torque_abs_nm(1,:) is read as stored"), std::string::npos) << r.err;
}

TEST(CliImport, BadExpressionsAndUnitsNameTheFileAndTheProblem) {
  auto r = runFlexarm(axisOne({"--output-var", "rec.act_pos_mot_deg(7,:)"}));
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find(kKuka + ": rec.act_pos_mot_deg(7,:): 'rec.act_pos_mot_deg' row 7 is outside 1..6"),
            std::string::npos)
      << r.err;
  r = runFlexarm(axisOne({"--input-var", "rec.act_torque"}));
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("'rec' has no field 'act_torque'; its fields are time_cont, time_disc"), std::string::npos)
      << r.err;
  r = runFlexarm(axisOne({"--output-unit", "furlong"}));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--output-unit must be rad, deg, rev"), std::string::npos) << r.err;
  r = runFlexarm(axisOne({"--output-side", "arm", "--output-unit", "deg"}));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("needs the gear ratio"), std::string::npos) << r.err;
  r = runFlexarm(axisOne({"--gear-ratio", "1/0"}));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("the gear ratio '1/0' must be a positive number arm/motor"), std::string::npos) << r.err;
  // The ratio as a datasheet gives it: refused before the file is read, the inverse named.
  r = runFlexarm(axisOne({"--gear-ratio", "256.86"}));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is above 1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("give --gear-ratio 1/256.86"), std::string::npos) << r.err;
  // Without a mapping the file's variables are listed and the way to name them is shown.
  r = runFlexarm({"info", kKuka});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("the file holds n_axis"), std::string::npos) << r.err;
  // What was skipped is named too, so a user looking for the robot object learns why it is not listed.
  EXPECT_NE(r.err.find("skipped: KR300 (a MATLAB object of class SerialLink)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--input-var 'rec.tau(1,:)'"), std::string::npos) << r.err;
}
