// flexarm discover end to end: the JSON the issue asks for, the hidden effect of a sample
// log named with its parameter against the truth sidecar, and the exit codes.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_test_support.h"

using namespace flexarm::test;
using nlohmann::json;

namespace {
const std::string kRipple = std::string(FLEXARM_SAMPLE_DIR) + "/effect_torque_ripple.csv";
}  // namespace

// The sample log hides a torque ripple of A = 0.05 N m, 6 periods per motor revolution
// (effect_torque_ripple.truth.json). Discovery on a three-mass base names it, with its
// amplitude within three standard deviations of the truth.
TEST(CliDiscover, NamesTheRippleOfTheSampleLogWithItsEvidence) {
  const auto r = runFlexarm({"discover", kRipple, "--model", "three-mass", "--effects",
                             "coulomb_friction,torque_ripple", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* key : {"effect", "effect_parameters", "evidence", "candidates", "base",
                          "augmented", "seconds"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["effect"], "torque_ripple") << j["evidence"];
  const auto truth = json::parse(
      readAll(std::string(FLEXARM_SAMPLE_DIR) + "/effect_torque_ripple.truth.json"));
  const double A = truth["effects"][0]["parameters"]["A"]["value"].get<double>();
  const auto& a = j["effect_parameters"]["A"];
  EXPECT_GT(a["std"].get<double>(), 0.0);
  EXPECT_LE(std::abs(a["value"].get<double>() - A), 3.0 * a["std"].get<double>()) << a;
  EXPECT_EQ(j["effect_parameters"]["n"]["value"].get<double>(), 6.0);
  // The augmented model's effect as `flexarm fit --effect` refines it.
  ASSERT_EQ(j["augmented"]["effects"].size(), 1u);
  EXPECT_EQ(j["augmented"]["effects"][0].get<std::string>().rfind("torque_ripple:", 0), 0u);
  ASSERT_EQ(j["candidates"].size(), 2u);
  for (const auto& c : j["candidates"]) {
    for (const char* key : {"effect", "loss_est", "rms_val", "aic", "significant"})
      EXPECT_TRUE(c.contains(key)) << key;
    EXPECT_EQ(c["significant"].get<bool>(), c["effect"] == "torque_ripple") << c["reason"];
  }
  for (const char* key : {"fit_percent", "fit_percent_validation", "rms_validation"}) {
    EXPECT_TRUE(j["base"].contains(key)) << key;
    EXPECT_TRUE(j["augmented"].contains(key)) << key;
  }
  EXPECT_LT(j["augmented"]["rms_estimation"].get<double>(),
            0.8 * j["base"]["rms_estimation"].get<double>());
  EXPECT_GT(j["augmented"]["fit_percent"].get<double>(), j["base"]["fit_percent"].get<double>());
  EXPECT_NE(j["evidence"].get<std::string>().find("Torque ripple"), std::string::npos) << j["evidence"];
}

TEST(CliDiscover, UsageAndBadInputExitCodes) {
  auto r = runFlexarm({"discover", kRipple, "--model", "rigid"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("gear spring"), std::string::npos) << r.err;
  r = runFlexarm({"discover", kRipple, "--model", "two-mass", "--effects", "friction"});
  EXPECT_EQ(r.code, 2) << r.err;
  r = runFlexarm({"discover", std::string(FLEXARM_TEST_DATA_DIR) + "/bad/non_numeric.csv",
                  "--model", "two-mass"});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("non_numeric.csv:"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// The "Refine:" line discovery prints is a command `flexarm fit` runs as given: the augmented
// model (its effect, the refitted base as start values, a negative damping's bound opened),
// fitted by the nonlinear grey-box pipeline with the effect's parameter free and a finite
// standard deviation. (On this closed-loop log the output-error refit from the measured
// torque does not keep discovery's ripple amplitude; the README says so.)
TEST(CliDiscover, TheRefineLineIsAFitThatRuns) {
  const auto d = runFlexarm({"discover", kRipple, "--model", "three-mass", "--effects",
                             "coulomb_friction,torque_ripple"});
  ASSERT_EQ(d.code, 0) << d.err;
  const auto at = d.out.find("Refine: flexarm fit ");
  ASSERT_NE(at, std::string::npos) << d.out;
  const std::string line = d.out.substr(at + 20, d.out.find('\n', at) - at - 20);
  std::vector<std::string> args{"fit"};
  for (std::size_t b = 0, e = 0; b < line.size(); b = e + 1) {
    e = line.find(' ', b);
    if (e == std::string::npos) e = line.size();
    if (e > b) args.push_back(line.substr(b, e - b));
  }
  EXPECT_NE(line.find("--start "), std::string::npos) << line;
  args.push_back("--json");
  const auto f = runFlexarm(args);
  ASSERT_EQ(f.code, 0) << line << "\n" << f.err;
  const json j = json::parse(f.out);
  bool found = false;
  for (const auto& e : j["effects"]) {
    if (e["name"] != "torque_ripple" || !e["parameters"].contains("A")) continue;
    found = true;
    const auto& p = e["parameters"]["A"];
    EXPECT_TRUE(p["free"].get<bool>()) << p;
    EXPECT_TRUE(p["std"].is_number() && std::isfinite(p["std"].get<double>()) && p["std"].get<double>() > 0.0) << p;
  }
  EXPECT_TRUE(found) << f.out;
}
