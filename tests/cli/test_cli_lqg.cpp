// The lqg verb end to end: the seed's three designs of chapter 8 as JSON (Section 8.3 cases
// (i) and (ii), Section 8.7 with acceleration feedback) and its usage errors.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"

using flexarm::test::runFlexarm;
using nlohmann::json;

namespace {

json lqgJson(std::vector<std::string> args) {
  args.insert(args.begin(), "lqg");
  args.push_back("--json");
  const auto r = runFlexarm(args);
  EXPECT_EQ(r.code, 0) << r.err;
  return r.code == 0 ? json::parse(r.out) : json::object();
}

int rhpCount(const json& poles) {
  int n = 0;
  for (const auto& p : poles) n += p[0].get<double>() > 1e-6 ? 1 : 0;
  return n;
}

}  // namespace

TEST(CliLqg, SeedCaseIIsAStableRegulator) {
  // Defaults are case (i): Table 8.1, Q1 = diag(100,1,0,0,0), Q2 = 1, R1 = diag(0,0,0,0,1),
  // R2 = 1e-6.
  const json j = lqgJson({});
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j["rhp_regulator_poles"], 0);
  EXPECT_EQ(j["regulator_stability"], "the regulator is stable");
  EXPECT_EQ(rhpCount(j["regulator_poles"]), 0);
  EXPECT_EQ(j["regulator_poles"].size(), 5u);
  EXPECT_EQ(j["closed_loop_poles"].size(), 9u);  // the arm (4) and the estimate (5 with x5)
  EXPECT_TRUE(j["closed_loop_stable"].get<bool>());
  EXPECT_EQ(j["encirclements"], 0);
  EXPECT_EQ(j["expected_encirclements"], 0);
  // (8.37) with no right-half-plane poles: the integral of log|S| vanishes.
  EXPECT_NEAR(j["bode_integral"].get<double>(), 0.0, 1e-3);
  EXPECT_EQ(j["bode_prediction"].get<double>(), 0.0);
  EXPECT_LT(j["lqr_residual"].get<double>(), 1e-10);
  EXPECT_LT(j["kalman_residual"].get<double>(), 1e-10);
  ASSERT_EQ(j["L"].size(), 1u);
  EXPECT_EQ(j["L"][0].size(), 5u);
  EXPECT_EQ(j["K"].size(), 5u);
  EXPECT_EQ(j["K"][0].size(), 1u);
  // max |S| is 1 / min |1 + F_y G| (8.38).
  EXPECT_NEAR(j["max_sensitivity"].get<double>() * j["min_distance_to_minus_one"].get<double>(),
              1.0, 1e-9);
}

TEST(CliLqg, SeedCaseIIIsUnstableWithTwoRhpPolesAndRejectsTheArmStepBetter) {
  const json i = lqgJson({});
  const json ii = lqgJson({"--r2", "1e-8"});
  ASSERT_FALSE(ii.empty());
  EXPECT_EQ(ii["rhp_regulator_poles"], 2);
  EXPECT_EQ(rhpCount(ii["regulator_poles"]), 2);
  EXPECT_EQ(ii["regulator_stability"], "the regulator is unstable: 2 poles in the RHP");
  EXPECT_TRUE(ii["closed_loop_stable"].get<bool>());
  // Section 8.6: the Nyquist curve of F_y G encircles -1 twice.
  EXPECT_EQ(ii["encirclements"], 2);
  EXPECT_EQ(ii["expected_encirclements"], 2);
  // (8.37): the integral equals pi times the sum of the real parts of the two RHP poles.
  double sum = 0.0;
  for (const auto& p : ii["regulator_poles"])
    if (p[0].get<double>() > 1e-6) sum += p[0].get<double>();
  const double prediction = ii["bode_prediction"].get<double>();
  EXPECT_NEAR(prediction, M_PI * sum, 1e-9 * prediction);
  EXPECT_NEAR(ii["bode_integral"].get<double>(), prediction, 1e-3 * prediction);
  // Same L for both cases (only K changes), larger max |S| for the unstable one, and the
  // smaller peak arm deviation of Figure 8.3.
  for (int k = 0; k < 5; ++k)
    EXPECT_DOUBLE_EQ(ii["L"][0][k].get<double>(), i["L"][0][k].get<double>()) << k;
  EXPECT_GT(ii["max_sensitivity"].get<double>(), i["max_sensitivity"].get<double>());
  EXPECT_LT(ii["peak_arm_deviation"].get<double>(), i["peak_arm_deviation"].get<double>());
}

TEST(CliLqg, AccelerationFeedbackIsStableWithLowerSensitivity) {
  // Section 8.7: R2 = diag(1e-8, 1e-1), the --accel default.
  const json a = lqgJson({"--accel"});
  const json explicitR2 = lqgJson({"--accel", "--r2", "1e-8,1e-1"});
  const json ii = lqgJson({"--r2", "1e-8"});
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a["measurement"], "motor-angle+arm-acceleration");
  EXPECT_EQ(a["rhp_regulator_poles"], 0);
  EXPECT_EQ(a["regulator_stability"], "the regulator is stable");
  EXPECT_EQ(a["encirclements"], 0);
  ASSERT_EQ(a["K"].size(), 5u);
  EXPECT_EQ(a["K"][0].size(), 2u);
  EXPECT_LT(a["max_sensitivity"].get<double>(), ii["max_sensitivity"].get<double>());
  EXPECT_EQ(explicitR2["max_sensitivity"], a["max_sensitivity"]);
}

TEST(CliLqg, ParametersAndSaturationReachTheDesign) {
  const json stiff = lqgJson({"--param", "k=86", "--saturation", "2.5"});
  const json base = lqgJson({});
  ASSERT_FALSE(stiff.empty());
  EXPECT_NE(stiff["L"][0][0], base["L"][0][0]);
  ASSERT_TRUE(stiff.contains("saturation"));
  EXPECT_EQ(stiff["saturation"]["limit"], 2.5);
  EXPECT_TRUE(stiff["saturation"].contains("with_anti_windup"));
  EXPECT_FALSE(base.contains("saturation"));
}

TEST(CliLqg, UsageErrorsExitWithTwoAndSayWhy) {
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"lqg", "--q1", "1,2,x,0,0"}, "comma-separated numbers"},
      {{"lqg", "--q1", "1,2,3"}, "Q1"},
      {{"lqg", "--r2", "0"}, "R2"},
      {{"lqg", "--q2", "0"}, "Q2 must be positive"},
      {{"lqg", "--q2", "one"}, "q2"},
      {{"lqg", "--model", "three-mass"}, "--model must be two-mass"},
      {{"lqg", "--param", "k"}, "NAME=VALUE"},
      {{"lqg", "--param", "k=stiff"}, "expects a number"},
      {{"lqg", "--param", "stiffness=3"}, "stiffness"},
      {{"lqg", "--param", "J_m=-1"}, "J_m must be positive"},
      {{"lqg", "extra"}, "unexpected argument 'extra'"},
      {{"lqg", "--frobnicate"}, "frobnicate"},
  };
  for (const auto& c : cases) {
    const auto r = runFlexarm(c.args);
    std::string all;
    for (const auto& a : c.args) all += a + " ";
    EXPECT_EQ(r.code, 2) << all << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << all << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << all;
  }
  const auto help = runFlexarm({"lqg", "--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("Usage: flexarm lqg"), std::string::npos);
}
