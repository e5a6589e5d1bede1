// The session part "recursive": two runs of the seed's experiment on the chapter-6 sample log
// (forgetting factor and Kalman gain, from 20 % above a model-list entry) are saved, reopened
// and replayed; the report holds the final values in the model's names, the trajectories and
// P's diagonal; a damaged request is refused naming the part; a recorded result that differs
// from the replay is flagged.
#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include "core/session/model_json.h"
#include "core/session/recursive_part.h"
#include "core/session/replay.h"
#include "core/session/session.h"
#include "core/session/sha256.h"

namespace fs = std::filesystem;
using namespace flexarm;
using nlohmann::json;

namespace {

const std::string kLog = std::string(FLEXARM_SAMPLE_DIR) + "/diagnosis_no_fault.csv";

fs::path scratch() {
  auto p = fs::temp_directory_path() / ("flexarm_recursive_part_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

RecursiveRequest request(const std::string& label, RecursiveAlgorithm a) {
  RecursiveRequest q;
  q.label = label;
  q.model = "arm";
  q.options.algorithm = a;
  q.options.startScale = 1.2;
  return q;
}

Session session(const std::string& path) {
  Session s;
  std::string why;
  LogReference l;
  l.name = "diagnosis";
  l.path = storedLogPath(path, kLog);
  l.sha256 = sha256OfFile(kLog, &why).value_or("");
  s.logs.push_back(l);
  s.parts["models"] = json::array({modelToJson("arm", *makeModel("three-mass"), {})});
  s.parts["recursive"] = {
      {"runs", json::array({{{"request", recursiveRequestToJson(request("lambda", RecursiveAlgorithm::ForgettingFactor))}},
                            {{"request", recursiveRequestToJson(request("R1", RecursiveAlgorithm::Kalman))}}})}};
  return s;
}

const json* section(const json& report, const std::string& title) {
  for (const auto& s : report["sections"])
    if (s["title"] == title) return &s;
  return nullptr;
}

}  // namespace

TEST(RecursivePart, RequestSurvivesItsJsonAndBadOnesAreRefused) {
  RecursiveRequest q = request("a", RecursiveAlgorithm::Kalman);
  q.options.r1 = {1e-8, 2e-7, 3e-6};
  q.options.estimate = {"k_T", "J_a^-1", "f_m"};
  q.data.decimation = 5;
  q.data.range = SecondsRange{1.0, 20.0};
  q.options.gradient = RecursiveGradient::Difference;
  std::string why;
  auto back = recursiveRequestFromJson(recursiveRequestToJson(q), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(recursiveRequestToJson(*back).dump(), recursiveRequestToJson(q).dump());
  EXPECT_EQ(back->options.algorithm, RecursiveAlgorithm::Kalman);
  EXPECT_EQ(back->options.r1[2], 3e-6);
  EXPECT_EQ(back->data.range->end, 20.0);

  json j = recursiveRequestToJson(q);
  j["algorithm"] = "rls";
  EXPECT_FALSE(recursiveRequestFromJson(j, &why));
  EXPECT_NE(why.find("forgetting or kalman"), std::string::npos) << why;
  j = recursiveRequestToJson(q);
  j["lambda"] = 2.0;
  EXPECT_FALSE(recursiveRequestFromJson(j, &why));

  const std::string path = (scratch() / "damaged.json").string();
  json s = json::parse(toJsonText(session(path)));
  s["parts"]["recursive"]["runs"][0]["request"]["r1"] = "big";
  const auto parsed = parseSession(s.dump());
  EXPECT_FALSE(parsed.ok);
  EXPECT_NE(parsed.message.find("recursive"), std::string::npos) << parsed.message;
}

TEST(RecursivePart, SaveReopenReplayReportsBothRuns) {
  const std::string path = (scratch() / "recursive.json").string();
  Session s = session(path);
  std::string why;
  ASSERT_TRUE(saveSession(s, path, &why)) << why;
  const auto reopened = loadSession(path);
  ASSERT_TRUE(reopened.ok) << reopened.message;

  const ReplayResult r = replaySession(reopened.session, path);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json report = r.report.toJson();
  const json* a = section(report, "Recursive identification: lambda");
  const json* b = section(report, "Recursive identification: R1");
  ASSERT_NE(a, nullptr) << report.dump(1);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ((*a)["values"]["termination"], "converged") << (*a)["values"]["message"];
  EXPECT_EQ((*b)["values"]["algorithm"], "kalman");
  // The seed's three parameters, J_a in the model's name, near the log's truth.
  EXPECT_NEAR((*a)["values"]["final"]["J_a"].get<double>(), 1.72, 0.05);
  EXPECT_NEAR((*a)["values"]["final"]["k_T"].get<double>(), 1.0, 0.02);
  EXPECT_GT((*a)["values"]["std"]["f_m"].get<double>(), 0.0);
  EXPECT_EQ((*a)["values"]["samples"].get<int>(), 48000);  // the log's 2 kHz
  // Trajectories with bands, P's diagonal and the prediction errors are plotted.
  bool found = false;
  for (const auto& sec : r.report.sections)
    if (sec.title == "Recursive identification: lambda") {
      found = true;
      ASSERT_EQ(sec.plots.size(), 3u);
      EXPECT_EQ(sec.plots[0].series.size(), 10u);  // 3 x (estimate, -3 sigma, +3 sigma) + nominal
      EXPECT_TRUE(sec.plots[1].logY);
      EXPECT_FALSE(sec.tables.empty());
    }
  EXPECT_TRUE(found);

  // A stored result that differs from the replay is reported.
  RecursiveResult fake;
  fake.termination = Termination::Converged;
  RecursiveEstimate e;
  e.parameter.modelName = "k_T";
  e.modelFinal = 5.0;
  fake.estimates = {e};
  s.parts["recursive"]["runs"][0]["result"] = recursiveResultToJson(fake);
  const ReplayResult again = replaySession(s, path);
  bool warned = false;
  for (const auto& w : again.report.warnings) warned = warned || w.find("k_T") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(RecursivePart, AModelMissingFromTheListIsASentenceNotACrash) {
  const std::string path = (scratch() / "missing.json").string();
  Session s = session(path);
  s.parts["recursive"]["runs"][0]["request"]["model"] = "gone";
  const ReplayResult r = replaySession(s, path);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json report = r.report.toJson();
  const json* a = section(report, "Recursive identification: lambda");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ((*a)["values"]["termination"], "failed");
  EXPECT_NE((*a)["values"]["message"].get<std::string>().find("gone"), std::string::npos);
}
