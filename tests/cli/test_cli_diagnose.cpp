// flexarm diagnose end to end: the sample logs whose fault steps in at 12 s are isolated with
// the parameter their truth sidecar names and a time shortly after the step, the healthy log
// raises no alarm, the JSON the issue asks for, the seed's way of making a fault, --param
// instead of a reference log, flexarm simulate --step, and the exit codes.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"

using namespace flexarm::test;
using nlohmann::json;

namespace {

std::string sample(const std::string& name) { return std::string(FLEXARM_SAMPLE_DIR) + "/" + name; }

json diagnose(const std::string& log, std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"diagnose", sample(log), "--reference-log",
                                   sample("diagnosis_no_fault.csv"), "--model", "three-mass", "--json"};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = runFlexarm(args);
  EXPECT_EQ(r.code, 0) << r.err;
  return r.code == 0 ? json::parse(r.out) : json::object();
}

}  // namespace

TEST(CliDiagnose, IsolatesEachSampleFaultAfterItsStep) {
  const std::pair<const char*, const char*> logs[] = {
      {"diagnosis_step_k_T", "k_T"}, {"diagnosis_step_J_a_inv", "J_a"}, {"diagnosis_step_f_m", "f_m"}};
  for (const auto& [log, parameter] : logs) {
    const json j = diagnose(std::string(log) + ".csv");
    const json truth = json::parse(readAll(sample(std::string(log) + ".truth.json")));
    const auto& step = truth["parameter_steps"][0];
    EXPECT_EQ(step["name"].get<std::string>(), parameter);
    EXPECT_EQ(j["verdict"], parameter) << j["summary"];
    ASSERT_TRUE(j["alarm_time_s"].is_number()) << log;
    const double delay = j["alarm_time_s"].get<double>() - step["time_s"].get<double>();
    EXPECT_GT(delay, 0.0) << log;
    EXPECT_LT(delay, 2.0) << log;
    for (const char* key : {"detection_time_s", "window", "reference", "estimates", "decision", "tests",
                            "thresholds_provenance"})
      EXPECT_TRUE(j.contains(key)) << key;
    for (const char* test : {"classical", "robust", "cusum", "hypothesis"}) {
      ASSERT_TRUE(j["tests"].contains(test)) << test;
      EXPECT_TRUE(j["tests"][test].contains("columns")) << test;
      EXPECT_TRUE(j["tests"][test].contains("thresholds")) << test;
    }
    EXPECT_EQ(j["window"]["kind"], "sliding");
  }
}

TEST(CliDiagnose, HealthyLogRaisesNoAlarm) {
  const json j = diagnose("diagnosis_step_none.csv");
  EXPECT_EQ(j["verdict"], "none") << j["summary"];
  EXPECT_TRUE(j["alarm_time_s"].is_null());
  EXPECT_TRUE(j["detection_time_s"].is_null());
  for (const char* test : {"robust", "cusum", "hypothesis"})
    EXPECT_EQ(j["tests"][test]["verdict"], "none") << test;
}

// The seed's Section 7.5: theta_0 of f_m moved 20 % on fault-free data; its cumulative window.
TEST(CliDiagnose, SeedFaultOnFaultFreeData) {
  const auto r = runFlexarm({"diagnose", sample("diagnosis_no_fault.csv"), "--reference-log",
                             sample("diagnosis_step_none.csv"), "--model", "three-mass", "--predictor",
                             "direct", "--window", "cumulative", "--seed-fault", "f_m=1.2", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["verdict"], "f_m") << j["summary"];
  EXPECT_EQ(j["window"]["kind"], "cumulative");
  EXPECT_NE(j["reference"]["source"].get<std::string>().find("Section 7.5"), std::string::npos);
}

// theta_0 from typed values: the model is simulated under the log's controller and reference.
TEST(CliDiagnose, ModelInsteadOfAReferenceLog) {
  const auto r = runFlexarm({"diagnose", sample("diagnosis_step_J_a_inv.csv"), "--model", "three-mass",
                             "--param", "J_a=1.72", "--tests", "cusum,hypothesis", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["verdict"], "J_a") << j["summary"];
  EXPECT_FALSE(j["tests"].contains("robust"));
  EXPECT_NE(j["reference"]["source"].get<std::string>().find("given model"), std::string::npos);
}

TEST(CliDiagnose, UsageAndBadInputExitCodes) {
  auto r = runFlexarm({"diagnose", sample("diagnosis_step_k_T.csv")});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("reference"), std::string::npos) << r.err;
  r = runFlexarm({"diagnose", sample("diagnosis_step_k_T.csv"), "--model", "three-mass", "--tests", "bayes"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bayes"), std::string::npos) << r.err;
  r = runFlexarm({"diagnose", sample("diagnosis_step_k_T.csv"), "--model", "three-mass", "--monitor", "k_x"});
  EXPECT_EQ(r.code, 2) << r.err;
  r = runFlexarm({"diagnose", std::string(FLEXARM_TEST_DATA_DIR) + "/bad/non_numeric.csv",
                  "--model", "three-mass", "--param", "k_T=1"});
  EXPECT_EQ(r.code, 3) << r.err;
  r = runFlexarm({"simulate", "--model", "three-mass", "--duration", "1", "--step", "k_T=1.2",
                  "--out", (scratchDir() / "bad_step.csv").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("NAME=VALUE@SECONDS"), std::string::npos) << r.err;
}

// flexarm simulate --step writes the step into the log's metadata and the truth.
TEST(CliDiagnose, SimulateWritesTheStep) {
  const std::string out = (scratchDir() / "step.csv").string();
  const auto r = runFlexarm({"simulate", "--model", "three-mass", "--duration", "2", "--rate", "200",
                             "--step", "f_m=0.05@1", "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(readAll(out).find("# parameter_steps: f_m=0.05@1"), std::string::npos);
  const json truth = json::parse(readAll(out.substr(0, out.size() - 4) + ".truth.json"));
  EXPECT_EQ(truth["parameter_steps"][0]["name"], "f_m");
  EXPECT_DOUBLE_EQ(truth["parameter_steps"][0]["value_before"].get<double>(), 0.0355);
  EXPECT_DOUBLE_EQ(truth["parameter_steps"][0]["time_s"].get<double>(), 1.0);
}

// The model check, the joint test and the temperature in the JSON: a healthy log fits; stated
// on the command line 15 degC warmer than its reference, with alpha = 1 %/degC theta_0's f_m
// is carried 15 % up, so the unchanged friction of this log now reads as an f_m fault (the
// correction is in effect); alpha and the logs' temperatures are checked with sentences.
TEST(CliDiagnose, ModelCheckJointTestAndTemperatureInTheJson) {
  const json plain = diagnose("diagnosis_step_none.csv");
  EXPECT_EQ(plain["verdict"], "none") << plain["summary"];
  EXPECT_EQ(plain["temperature"]["applied"], false);
  const json j = diagnose("diagnosis_step_none.csv", {"--friction-alpha", "0.01", "--temperature", "40",
                                                      "--reference-temperature", "25"});
  EXPECT_EQ(j["verdict"], "f_m") << j["summary"];
  EXPECT_EQ(j["model_check"]["fits"], true) << j["model_check"]["message"];
  EXPECT_EQ(j["model_check"]["checked"], true);
  EXPECT_LT(j["model_check"]["median_ratio"].get<double>(), 1.5);
  ASSERT_TRUE(j["tests"].contains("joint"));
  EXPECT_TRUE(j["tests"]["joint"]["thresholds"].contains("scale"));
  EXPECT_EQ(j["temperature"]["applied"], true) << j["temperature"]["message"];
  EXPECT_DOUBLE_EQ(j["temperature"]["monitored_c"].get<double>(), 40.0);
  EXPECT_DOUBLE_EQ(j["temperature"]["alpha_per_c"].get<double>(), 0.01);
  EXPECT_GT(j["temperature"]["f_m_expected"].get<double>(), j["temperature"]["f_m_reference"].get<double>());
  EXPECT_EQ(j["tests_verdict"], "f_m");
  auto r = runFlexarm({"diagnose", sample("diagnosis_step_none.csv"), "--reference-log",
                       sample("diagnosis_no_fault.csv"), "--friction-alpha", "0.5"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("friction"), std::string::npos) << r.err;
  r = runFlexarm({"diagnose", sample("diagnosis_step_none.csv"), "--reference-log",
                  sample("diagnosis_no_fault.csv"), "--temperature-logs", sample("diagnosis_step_none.csv")});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("temperature"), std::string::npos) << r.err;
}
