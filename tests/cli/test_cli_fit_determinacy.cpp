// A parameter the data do not determine is said to be undetermined, with why, in the text and
// the JSON; never a std of 0 or nan quoted as if it were one. On the real KUKA KR300 recording
// (sample_logs/kuka_kr300) a two-mass fit on 0.5-7 s has a singular Hessian and three
// parameters on their bounds; on the simulated chirp the three-mass fit determines every one.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.h"

namespace flexarm {
namespace {

using nlohmann::json;
using test::runFlexarm;

std::vector<std::string> kukaFit(const std::vector<std::string>& extra) {
  std::vector<std::string> a = {"fit",
                                std::string(FLEXARM_SAMPLE_DIR) + "/kuka_kr300/rec_B_data.mat",
                                "--time-var", "rec.time_cont",
                                "--input-var", "rec.act_torque_abs_nm(1,:)",
                                "--output-var", "rec.act_pos_mot_deg(1,:)",
                                "--output-unit", "deg", "--output-side", "arm",
                                "--arm-var", "rec.act_pos_se_deg(1,:)", "--arm-unit", "deg",
                                "--gear-ratio", "1/256.86", "--ref-var", "rec.ref_pos_deg(1,:)",
                                "--model", "two-mass", "--range", "0.5:7"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

TEST(CliFitDeterminacy, UndeterminedParametersAreNamedNotGivenAStdOfZero) {
  const auto text = runFlexarm(kukaFit({}));
  ASSERT_EQ(text.code, 0) << text.err;
  const auto r = runFlexarm(kukaFit({"--json"}));
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  int undetermined = 0;
  for (const auto& p : j.at("parameter_rows")) {
    if (!p.at("free").get<bool>()) continue;
    const std::string name = p.at("name");
    if (p.at("determined").get<bool>()) {
      EXPECT_TRUE(p.at("undetermined").is_null()) << name;
      EXPECT_GT(p.at("std").get<double>(), 0.0) << name;
      continue;
    }
    ++undetermined;
    EXPECT_FALSE(p.at("undetermined").get<std::string>().empty()) << name;
    // The text says why instead of quoting its std.
    std::istringstream lines(text.out);
    bool found = false;
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("  " + name + " = ", 0) != 0) continue;
      found = true;
      EXPECT_NE(line.find("(undetermined: "), std::string::npos) << line;
      EXPECT_EQ(line.find("+- 0 "), std::string::npos) << line;
      EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    }
    EXPECT_TRUE(found) << name << " not in\n" << text.out;
  }
  // J_a, k_a and d_a end on their lower bounds, and the Hessian is singular.
  EXPECT_GE(undetermined, 3) << r.out;
}

TEST(CliFitDeterminacy, AWellExcitedFitDeterminesEveryParameter) {
  const auto r = runFlexarm({"fit", std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv", "--model",
                             "three-mass", "--range", "0.5:9", "--validation-range", "9:17.5", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  for (const auto& p : j.at("parameter_rows")) {
    if (p.at("free").get<bool>()) {
      EXPECT_TRUE(p.at("determined").get<bool>()) << p.dump();
    }
  }
  EXPECT_TRUE(j.at("undetermined_direction").is_null());
}

}  // namespace
}  // namespace flexarm
