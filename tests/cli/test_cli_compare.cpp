// `flexarm compare`, `flexarm residuals` and `flexarm sensitivity` end to end: the fit % a
// comparison prints for a fitted model is the one `flexarm fit` printed for it, every figure
// names what it is of, bad input gets the documented exit codes, and a session's compare part
// replays into the report with the verb's numbers.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "tests/cli/cli_test_support.h"

namespace flexarm {
namespace {

using test::runFlexarm;

const std::string kChirp = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";

TEST(CliCompare, TheFitsOwnFitPercentOnBothRanges) {
  const auto dir = test::scratchDir();
  const std::string fitJson = (dir / "fit3.json").string();
  auto fit = runFlexarm({"fit", kChirp, "--model", "three-mass", "--free", "J_m,J_a,k_g,k_a,d_a", "--decimate", "10",
                         "--range", "0.5:9", "--validation-range", "9:17.5", "--json"});
  ASSERT_EQ(fit.code, 0) << fit.err;
  std::ofstream(fitJson) << fit.out;
  const auto f = nlohmann::json::parse(fit.out);
  auto cmp = runFlexarm({"compare", kChirp, "--model-file", fitJson, "--decimation", "10", "--estimation", "0.5:9",
                         "--validation", "9:17.5", "--json"});
  ASSERT_EQ(cmp.code, 0) << cmp.err;
  const auto c = nlohmann::json::parse(cmp.out);
  ASSERT_EQ(c["models"].size(), 1u);
  const auto& m = c["models"][0];
  EXPECT_EQ(m["status"], "compared");
  EXPECT_DOUBLE_EQ(m["fit_percent"].get<double>(), f["fit_percent_validation"].get<double>());
  EXPECT_DOUBLE_EQ(m["fit_percent_nrmse"].get<double>(), f["fit_percent_validation_nrmse"].get<double>());
  EXPECT_EQ(m["basis"]["kind"], "simulation");
  EXPECT_EQ(m["basis"]["start"], "log");
  EXPECT_DOUBLE_EQ(m["basis"]["rate_hz"].get<double>(), 200.0);
  EXPECT_EQ(m["basis"]["range"], "validation 9-17.5 s");
  auto est = runFlexarm({"compare", kChirp, "--model-file", fitJson, "--decimation", "10", "--estimation", "0.5:9",
                         "--validation", "9:17.5", "--on", "estimation", "--json"});
  ASSERT_EQ(est.code, 0) << est.err;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(est.out)["models"][0]["fit_percent"].get<double>(),
                   f["fit_percent"].get<double>());
  // The text names both figures and the rate.
  auto text = runFlexarm({"compare", kChirp, "--model-file", fitJson, "--decimation", "10", "--estimation", "0.5:9",
                          "--validation", "9:17.5"});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("% (5.2)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("% NRMSE (at 200 Hz)"), std::string::npos) << text.out;
}

TEST(CliCompare, KStepPredictionAndExitCodes) {
  auto one = runFlexarm({"compare", kChirp, "--model", "three-mass", "--horizon", "3", "--validation", "9:17.5",
                         "--json"});
  ASSERT_EQ(one.code, 0) << one.err;
  const auto j = nlohmann::json::parse(one.out);
  EXPECT_EQ(j["models"][0]["basis"]["kind"], "prediction");
  EXPECT_EQ(j["models"][0]["basis"]["horizon"], 3);
  EXPECT_EQ(j["models"][0]["message"], "an output-error model predicts what it simulates");
  EXPECT_EQ(runFlexarm({"compare", kChirp, "--model", "three-mass", "--horizon", "-1"}).code, 2);
  EXPECT_EQ(runFlexarm({"compare", kChirp}).code, 2);  // no model
  EXPECT_EQ(runFlexarm({"compare", kChirp, "--model", "three-mass", "--on", "middle"}).code, 2);
  EXPECT_EQ(runFlexarm({"compare", "/nonexistent/log.csv", "--model", "three-mass"}).code, 3);
  const auto help = runFlexarm({"compare", "--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--horizon"), std::string::npos);
}

TEST(CliCompare, ResidualsOfAModelAndTheirCodes) {
  auto r = runFlexarm({"residuals", kChirp, "--model", "three-mass", "--estimation", "0.5:9", "--lags", "30",
                       "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["code"], "ok");
  EXPECT_EQ(j["lags"].size(), 31u);
  EXPECT_EQ(j["cross_lags"].size(), 61u);
  EXPECT_EQ(j["errors"], "output_error");
  EXPECT_DOUBLE_EQ(j["autocorrelation"][0].get<double>(), 1.0);
  // No validation range: the data cannot carry it (exit 3, code no_range).
  auto none = runFlexarm({"residuals", kChirp, "--model", "three-mass", "--on", "validation", "--json"});
  EXPECT_EQ(none.code, 3);
  EXPECT_EQ(nlohmann::json::parse(none.out)["code"], "no_range");
  EXPECT_EQ(runFlexarm({"residuals", kChirp, "--model", "three-mass", "--lags", "0"}).code, 2);
}

TEST(CliCompare, SensitivityStudyOfAModel) {
  auto s = runFlexarm({"sensitivity", kChirp, "--model", "two-mass", "--free", "J_m", "--fixed", "J_a", "--fixed", "k_a",
                       "--fixed", "d_a", "--fixed", "f_m",
                       "--decimation", "10", "--estimation", "0.5:6", "--runs", "4", "--json"});
  ASSERT_EQ(s.code, 0) << s.err << s.out;
  const auto j = nlohmann::json::parse(s.out);
  EXPECT_EQ(j["code"], "ok");
  EXPECT_EQ(j["monte_carlo"]["completed"], 4);
  ASSERT_EQ(j["attraction"]["parameters"].size(), 1u);
  EXPECT_EQ(j["attraction"]["parameters"][0]["name"], "J_m");
  EXPECT_LT(j["attraction"]["parameters"][0]["lower_factor"].get<double>(), 1.0);
  EXPECT_EQ(runFlexarm({"sensitivity", kChirp, "--model", "two-mass", "--runs", "-3"}).code, 2);
}

TEST(CliCompare, ASessionsComparePartReplaysTheVerbsNumbers) {
  const auto dir = test::scratchDir() / "compare_session";
  std::filesystem::create_directories(dir);
  for (const char* f : {"three_mass_estimation_chirp.csv", "effect_torque_ripple.csv", "diagnosis_step_k_T.csv",
                        "diagnosis_no_fault.csv"})
    std::filesystem::copy_file(std::string(FLEXARM_SAMPLE_DIR) + "/" + f, dir / f,
                               std::filesystem::copy_options::overwrite_existing);
  auto session = nlohmann::json::parse(test::readAll(std::string(FLEXARM_SAMPLE_DIR) + "/sample_session.json"));
  auto& parts = session["parts"];
  for (const char* drop : {"fits", "discovery", "lqg", "diagnosis", "recursive"}) parts.erase(drop);
  parts["compare"] = {{"models", {"three-mass", "two-mass"}}, {"range", "validation"}, {"horizon", 0}};
  parts["residuals"] = {{"model", "three-mass"}, {"range", "validation"}, {"lags", 20}};
  const std::string path = (dir / "s.json").string();
  std::ofstream(path) << session.dump(2);
  auto run = runFlexarm({"run", path, "--json"});
  ASSERT_EQ(run.code, 0) << run.err;
  const auto report = nlohmann::json::parse(run.out);
  const nlohmann::json* compare = nullptr;
  const nlohmann::json* residuals = nullptr;
  std::map<std::string, double> modelSections;
  for (const auto& s : report["sections"]) {
    const std::string title = s["title"];
    if (title.rfind("Compare", 0) == 0) compare = &s["values"];
    if (title.rfind("Residual analysis", 0) == 0) residuals = &s["values"];
    if (title.rfind("Model ", 0) == 0 && s["values"].contains("fit_percent_validation"))
      modelSections[title.substr(6)] = s["values"]["fit_percent_validation"].get<double>();
  }
  ASSERT_TRUE(compare && residuals);
  ASSERT_EQ((*compare)["models"].size(), 2u);
  EXPECT_EQ((*residuals)["code"], "ok");
  // The verb on the session gives the same numbers as its report: Compare's and the model
  // list's sections alike.
  auto verb = runFlexarm({"compare", "--session", path, "--json"});
  ASSERT_EQ(verb.code, 0) << verb.err;
  const auto v = nlohmann::json::parse(verb.out);
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string name = (*compare)["models"][i]["name"];
    EXPECT_DOUBLE_EQ((*compare)["models"][i]["fit_percent"].get<double>(), v["models"][i]["fit_percent"].get<double>());
    ASSERT_TRUE(modelSections.count(name)) << name;
    EXPECT_DOUBLE_EQ(modelSections[name], v["models"][i]["fit_percent"].get<double>()) << name;
  }
}

}  // namespace
}  // namespace flexarm
