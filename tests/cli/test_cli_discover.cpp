// flexarm discover end to end: the JSON the issue asks for, the hidden effect of a sample
// log named with its parameter against the truth sidecar and confirmed, the loop
// (--until-none) and a start from a model with effects (--effect), the Refine line as a fit
// that keeps what discovery found, and the exit codes.
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

// The estimate named `name` of a parameter list (discoveryResultJson's shape).
json param(const json& list, const std::string& name) {
  for (const auto& p : list)
    if (p["name"] == name) return p;
  return json();
}
}  // namespace

// The sample log hides a torque ripple of A = 0.05 N m, 6 periods per motor revolution
// (effect_torque_ripple.truth.json). Discovery on a three-mass base names it, with its
// amplitude within three standard deviations of the truth.
TEST(CliDiscover, NamesTheRippleOfTheSampleLogWithItsEvidence) {
  const auto r = runFlexarm({"discover", kRipple, "--model", "three-mass", "--effects",
                             "coulomb_friction,torque_ripple", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* key : {"schema", "effect", "effects", "also_tried", "evidence", "candidates", "base",
                          "augmented", "fit_percent_definition"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["effect"], "torque_ripple") << j["evidence"];
  const auto truth = json::parse(
      readAll(std::string(FLEXARM_SAMPLE_DIR) + "/effect_torque_ripple.truth.json"));
  const double A = truth["effects"][0]["parameters"]["a_1"]["value"].get<double>();
  ASSERT_FALSE(j["effects"].empty()) << j["evidence"];
  const json a = param(j["effects"][0]["parameters"], "A_1");
  ASSERT_TRUE(a.is_object()) << j["effects"][0]["parameters"];
  EXPECT_GT(a["std"].get<double>(), 0.0);
  EXPECT_LE(std::abs(a["value"].get<double>() - A), 3.0 * a["std"].get<double>()) << a;
  EXPECT_EQ(param(j["effects"][0]["parameters"], "n")["value"].get<double>(), 6.0);
  EXPECT_EQ(j["effects"][0]["magnitude"]["name"], "A_1");
  EXPECT_GT(j["effects"][0]["size"]["share"].get<double>(), 0.02);
  // The augmented model's effect as `flexarm fit --effect` refines it.
  ASSERT_EQ(j["augmented"]["effects"].size(), 1u);
  EXPECT_EQ(j["augmented"]["effects"][0].get<std::string>().rfind("torque_ripple:", 0), 0u);
  ASSERT_EQ(j["candidates"].size(), 2u);
  for (const auto& c : j["candidates"]) {
    for (const char* key : {"effect", "loss_est", "score", "aic", "significant", "magnitude", "size"})
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
  // The second method confirms it, with its numbers.
  ASSERT_EQ(j["effects"].size(), 1u);
  EXPECT_TRUE(j["effects"][0]["confirmed"].get<bool>()) << j["effects"][0]["confirmation"]["text"];
  EXPECT_EQ(j["effects"][0]["confirmation"]["text"].get<std::string>().rfind("confirmed on ", 0), 0u);
  EXPECT_GT(j["effects"][0]["confirmation"]["z"].get<double>(), 2.58);
}

// The loop on the same log: the ripple, then nothing more; every step with its scores before
// and after, the rounds with their candidates.
TEST(CliDiscover, UntilNoneFindsTheRippleAndStops) {
  const auto r = runFlexarm({"discover", kRipple, "--model", "three-mass", "--effects",
                             "coulomb_friction,torque_ripple", "--until-none", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["effects"].size(), 1u) << j["effects"];
  EXPECT_EQ(j["effects"][0]["effect"], "torque_ripple");
  for (const char* key : {"rms_estimation", "rms_validation", "fit_percent", "fit_percent_validation",
                          "fit_percent_nrmse", "fit_percent_validation_nrmse"}) {
    EXPECT_TRUE(j["effects"][0]["before"].contains(key)) << key;
    EXPECT_TRUE(j["effects"][0]["after"].contains(key)) << key;
  }
  EXPECT_LT(j["effects"][0]["after"]["rms_validation"].get<double>(),
            j["effects"][0]["before"]["rms_validation"].get<double>());
  const json a = param(j["effects"][0]["parameters"], "A_1");
  EXPECT_LE(a["lower"].get<double>(), 0.05) << a;
  EXPECT_GE(a["upper"].get<double>(), 0.05) << a;
  ASSERT_EQ(j["rounds"].size(), 2u);
  EXPECT_EQ(j["rounds"][1]["effect"], "none");
  EXPECT_EQ(j["rounds"][1]["candidates"].size(), 1u);  // the ripple is in the model
  EXPECT_EQ(j["stop_reason"], "none of the candidates is significant");
}

// --effect starts from a model that has the ripple already (at 0.03): it is refitted with the
// base (to the truth 0.05) and not looked for again; nothing else is missing.
TEST(CliDiscover, StartsFromAModelWithAnEffect) {
  const auto r = runFlexarm({"discover", kRipple, "--model", "three-mass", "--effects",
                             "coulomb_friction,torque_ripple", "--effect", "torque_ripple:0.03,6", "--until-none",
                             "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["effect"], "none");
  EXPECT_TRUE(j["effects"].empty()) << j["effects"];
  ASSERT_EQ(j["augmented"]["effects"].size(), 1u);
  const std::string spec = j["augmented"]["effects"][0].get<std::string>();
  ASSERT_EQ(spec.rfind("torque_ripple:", 0), 0u) << spec;
  EXPECT_NEAR(std::stod(spec.substr(14)), 0.05, 0.01) << spec;
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
  r = runFlexarm({"discover", kRipple, "--model", "two-mass", "--max-effects", "2"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--until-none"), std::string::npos) << r.err;
  r = runFlexarm({"discover", kRipple, "--model", "two-mass", "--effect", "ripple:1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--effect ripple:1"), std::string::npos) << r.err;
}

// The "Refine:" line discovery prints is a command `flexarm fit` runs as given: the augmented
// model (its effect, the refitted base as start values, a negative damping's bound opened),
// fitted by the nonlinear grey-box pipeline with the effect's parameter free and a finite
// standard deviation. The fit predicts through the same load observer on this closed-loop
// log, so it keeps the ripple discovery found (A within 20 % of discovery's value).
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
    if (e["name"] != "torque_ripple" || !e["parameters"].contains("a_1")) continue;
    found = true;
    const auto& p = e["parameters"]["a_1"];
    EXPECT_TRUE(p["free"].get<bool>()) << p;
    EXPECT_TRUE(p["std"].is_number() && std::isfinite(p["std"].get<double>()) && p["std"].get<double>() > 0.0) << p;
    const auto ripple = line.find("--effect torque_ripple:");
    ASSERT_NE(ripple, std::string::npos) << line;
    const double discovered = std::stod(line.substr(ripple + 23));
    EXPECT_NEAR(p["value"].get<double>(), discovered, 0.2 * discovered) << p;
  }
  EXPECT_TRUE(found) << f.out;
}
