// flexarm run: replays the sample session headless and writes PDF and HTML reports whose text
// carries the section titles, parameter names, checksums and the same fit % as --json.
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "cli_test_support.h"

using flexarm::test::pdfText;
using flexarm::test::readAll;
using flexarm::test::runFlexarm;
using flexarm::test::scratchDir;

namespace {

const std::string kSession = std::string(FLEXARM_SAMPLE_DIR) + "/sample_session.json";
const std::string kMultisine =
    std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_validation_multisine.csv";

// This build renders reports (the GUI build); a build without Qt refuses --report clearly.

}  // namespace

TEST(CliRun, JsonNamesVersionLogChecksumAndEveryModel) {
  auto r = runFlexarm({"run", kSession, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["flexarm_version"], FLEXARM_VERSION);
  auto session = nlohmann::json::parse(readAll(kSession));
  EXPECT_EQ(j["logs"][0]["sha256"], session["logs"][0]["sha256"]);
  std::vector<std::string> titles;
  for (const auto& s : j["sections"]) titles.push_back(s["title"]);
  EXPECT_EQ(titles, (std::vector<std::string>{"Data", "Model three-mass", "Model two-mass",
                                              "Non-parametric estimate (SPA)",
                                              "Fit three-mass estimate",
                                              "Discovery: the missing effect",
                                              "LQG design (chapter 8)",
                                              "Diagnosis (chapter 7)"}));
  EXPECT_EQ(j["sections"][0]["values"]["rate_hz"].get<double>(), 200.0);
}

#if FLEXARM_GUI_BUILD
// Reports are rendered with Qt: these run in the GUI build, which CI and README use.
TEST(CliRun, PdfTextHasTitlesParametersChecksumAndTheJsonFitPercent) {
  const std::string pdf = (scratchDir() / "report.pdf").string();
  auto r = runFlexarm({"run", kSession, "--report", pdf, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  const std::string text = pdfText(pdf);
  ASSERT_FALSE(text.empty());
  EXPECT_NE(text.find("FlexArm " FLEXARM_VERSION), std::string::npos);
  // The checksum may wrap between its groups of 16 characters: whole once spaces go.
  std::string compact;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) compact += c;
  EXPECT_NE(compact.find(j["logs"][0]["sha256"].get<std::string>()), std::string::npos);
  EXPECT_EQ(text.find("Log log:"), std::string::npos) << "the log's label says log once";
  int fits = 0, stds = 0;
  for (const auto& s : j["sections"]) {
    EXPECT_NE(text.find(s["title"].get<std::string>()), std::string::npos) << s["title"];
    // A model's numbers are its section's values, a fit's the fit object in them.
    const nlohmann::json& values = s["values"].contains("fit") ? s["values"]["fit"] : s["values"];
    if (!values.contains("parameters")) continue;
    for (const auto& [name, value] : values["parameters"].items())
      EXPECT_NE(text.find(name), std::string::npos) << name;
    for (const char* key : {"fit_percent", "fit_percent_validation"}) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.2f", values[key].get<double>());
      EXPECT_NE(text.find(buf), std::string::npos) << key << " " << buf;
      ++fits;
    }
    if (!values.contains("std")) continue;
    // An estimate's table row: the name, its value and its std as printed (4 and 3 digits).
    for (const auto& [name, sd] : values["std"].items()) {
      if (sd.get<double>() == 0.0) continue;  // fixed
      char value[32], sdText[32];
      std::snprintf(value, sizeof value, "%.6g", values["parameters"][name].get<double>());
      std::snprintf(sdText, sizeof sdText, "%.3g", sd.get<double>());
      const std::regex row(name + R"(\s+)" + std::regex_replace(value, std::regex(R"([.+])"), R"(\$&)") +
                           R"(\s+)" + std::regex_replace(sdText, std::regex(R"([.+])"), R"(\$&)") + R"(\s)");
      EXPECT_TRUE(std::regex_search(text, row)) << name << " " << value << " +- " << sdText;
      ++stds;
    }
  }
  EXPECT_EQ(fits, 6);  // two models and the estimate, each on both ranges
  EXPECT_EQ(stds, 5);  // the estimate's free parameters
  for (const char* title : {"Estimated parameters (value +- std, 99 % interval)",
                            "Loss and fit %: the seed's (5.2) and MATLAB compare's NRMSE",
                            "Notches and peaks of the estimate: minima and maxima of |G(i w)|", "Residual tests on the validation range",
                            "Bode magnitude, three-mass estimate with its 99 % band",
                            "Measured and simulated output on the validation range",
                            "Residual autocorrelation", "Cross-correlation of residuals and input",
                            "Bode magnitude, SPA of the estimation data"})
    EXPECT_NE(text.find(title), std::string::npos) << title;

  // Discovery on the torque-ripple log names the effect that generated it, with the
  // numbers of --json as printed: fit % with 2 decimals, residual RMS with 4 digits.
  const nlohmann::json truth =
      nlohmann::json::parse(readAll(std::string(FLEXARM_SAMPLE_DIR) + "/effect_torque_ripple.truth.json"));
  const std::string hidden = truth["effects"][0]["name"];
  const nlohmann::json* discovery = nullptr;
  const nlohmann::json* lqg = nullptr;
  const nlohmann::json* diagnosis = nullptr;
  for (const auto& s : j["sections"]) {
    if (s["title"] == "Discovery: the missing effect") discovery = &s["values"];
    if (s["title"] == "LQG design (chapter 8)") lqg = &s["values"];
    if (s["title"] == "Diagnosis (chapter 7)") diagnosis = &s["values"];
  }
  ASSERT_NE(discovery, nullptr);
  ASSERT_NE(lqg, nullptr);
  EXPECT_EQ((*discovery)["effect"], hidden);
  EXPECT_NE(text.find("Verdict: the missing effect is " + hidden), std::string::npos);
  for (const char* model : {"base", "augmented"}) {
    char rms[32], fit[32];
    std::snprintf(rms, sizeof rms, "%.4g", (*discovery)[model]["rms_validation"].get<double>());
    std::snprintf(fit, sizeof fit, "%.2f", (*discovery)[model]["fit_percent_validation"].get<double>());
    EXPECT_NE(text.find(rms), std::string::npos) << model << " RMS " << rms;
    EXPECT_NE(text.find(fit), std::string::npos) << model << " fit % " << fit;
  }
  EXPECT_LT((*discovery)["augmented"]["rms_validation"].get<double>(),
            (*discovery)["base"]["rms_validation"].get<double>());
  for (const char* title : {"Candidates", "Base and augmented model: fit % (5.2) and residual RMS",
                            "Motor velocity on the validation data, before and after",
                            "Residual on the validation data, before and after"})
    EXPECT_NE(text.find(title), std::string::npos) << title;
  // Case (i) of the seed: a stable regulator (Section 8.6), max |S| as printed.
  EXPECT_EQ((*lqg)["regulator_stability"], "the regulator is stable");
  EXPECT_NE(text.find("Regulator: the regulator is stable"), std::string::npos);
  char maxS[32];
  std::snprintf(maxS, sizeof maxS, "%.4g", (*lqg)["max_sensitivity"].get<double>());
  EXPECT_NE(text.find(std::string("max |S| (8.36)")), std::string::npos);
  EXPECT_NE(text.find(maxS), std::string::npos) << maxS;
  for (const char* title : {"Design options", "Nyquist curve of F_y G near -1",
                            "Sensitivity |S| (8.36) and complementary sensitivity |T|"})
    EXPECT_NE(text.find(title), std::string::npos) << title;
  // The diagnosis of the log whose torque constant steps up at 12 s names it shortly after,
  // and the report states the thresholds with the false-alarm rate they were chosen for.
  ASSERT_NE(diagnosis, nullptr);
  const nlohmann::json step = nlohmann::json::parse(
      readAll(std::string(FLEXARM_SAMPLE_DIR) + "/diagnosis_step_k_T.truth.json"))["parameter_steps"][0];
  EXPECT_EQ((*diagnosis)["verdict"], step["name"]);
  const double delay = (*diagnosis)["alarm_time_s"].get<double>() - step["time_s"].get<double>();
  EXPECT_GT(delay, 0.0);
  EXPECT_LT(delay, 2.0);
  // Paragraphs wrap where the page ends: the words are looked for with every run of white
  // space read as one space.
  std::string flat;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) flat += c;
    else if (flat.empty() || flat.back() != ' ') flat += ' ';
  for (const char* words : {"Diagnosis (chapter 7)", "Verdict: k_T changed", "Thresholds",
                            "no false alarm in 0.3 h of fault-free runs (at most 10 false alarms per hour",
                            "Decision structure (Section 7.5.2)",
                            "CUSUM (7.1), (7.15)-(7.17) against its threshold", "Alarm timeline"})
    EXPECT_NE(flat.find(words), std::string::npos) << words;
}

TEST(CliRun, HtmlIsSelfContained) {
  const std::string html = (scratchDir() / "report.html").string();
  auto r = runFlexarm({"run", kSession, "--report", html});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = readAll(html);
  EXPECT_NE(text.find("Model three-mass"), std::string::npos);
  EXPECT_EQ(text.find("http:"), std::string::npos);
  EXPECT_EQ(text.find("https:"), std::string::npos);
  EXPECT_EQ(text.find("<link"), std::string::npos);
  EXPECT_EQ(text.find("url("), std::string::npos);
  // Every image is embedded: src attributes are data URIs, and there are plots.
  const std::regex src("src=\"([^\"]{0,16})");
  int images = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), src); it != std::sregex_iterator(); ++it) {
    EXPECT_EQ((*it)[1].str().rfind("data:image/png", 0), 0u) << (*it)[1].str();
    ++images;
  }
  // Bode magnitude, phase and compare plot of each of the two models; the SPA's Bode plots;
  // the estimate's Bode, compare and two correlation plots.
  EXPECT_GE(images, 6 + 2 + 5);
}
#else
TEST(CliRun, ReportsAreRefusedWithoutTheGui) {
  auto r = runFlexarm({"run", kSession, "--report", (scratchDir() / "r.pdf").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("built without the GUI"), std::string::npos) << r.err;
}
#endif

TEST(CliRun, SubstitutedLogIsReplayedAndNamed) {
  auto r = runFlexarm({"run", kSession, "--log", "estimation=" + kMultisine, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["logs"][0]["note"], "substituted");
  EXPECT_EQ(j["logs"][0]["path"], kMultisine);
}

TEST(CliRun, BadInputAndUsageExitCodes) {
  const auto dir = scratchDir();
  const std::string damaged = (dir / "damaged.json").string();
  std::string text = readAll(kSession);
  std::ofstream(damaged) << text.substr(0, text.size() / 3);
  auto r = runFlexarm({"run", damaged, "--json"});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("damaged"), std::string::npos) << r.err;

  auto j = nlohmann::json::parse(text);
  j["version"] = 99;
  const std::string newer = (dir / "newer.json").string();
  std::ofstream(newer) << j.dump();
  r = runFlexarm({"run", newer, "--json"});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("newer FlexArm"), std::string::npos) << r.err;

  EXPECT_EQ(runFlexarm({"run", kSession}).code, 2);
  EXPECT_EQ(runFlexarm({"run", kSession, "--report", "out.docx"}).code, 2);
  EXPECT_EQ(runFlexarm({"run", kSession, "--log", "estimation", "--json"}).code, 2);
  r = runFlexarm({"run", kSession, "--log", "tomorrow=" + kMultisine, "--json"});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("no log named 'tomorrow'"), std::string::npos) << r.err;
  EXPECT_EQ(runFlexarm({"run", "--help"}).code, 0);
}
