// One fit, one JSON: `flexarm fit --json`, the session part "fits" (what a session stores with
// a fit) and the report's data of `flexarm run --json` write a fit result with one writer
// (core/ident/fit_json.h), so the same log and options give the same bytes in each.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_test_support.h"
#include "core/ident/fit_json.h"
#include "core/io/log_io.h"
#include "core/models/physical_models.h"
#include "core/session/fit_request.h"
#include "core/session/session.h"
#include "core/session/sha256.h"

using flexarm::test::runFlexarm;
using flexarm::test::scratchDir;
using nlohmann::json;

namespace {

const std::string kDaisy = std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat";
const std::string kChirp = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";

// A session on log whose part "fits" holds request, written to a file; its path.
std::string sessionWith(const std::string& log, const flexarm::FitRequest& request, const std::string& file) {
  flexarm::Session s;
  std::string why;
  s.logs.push_back({"estimation", log, flexarm::sha256OfFile(log, &why).value_or(""), {}});
  s.parts["fits"] = {{"nonparametric", false}, {"requests", json::array({flexarm::fitRequestToJson(request)})}};
  const std::string path = (scratchDir() / file).string();
  EXPECT_TRUE(flexarm::saveSession(s, path, &why)) << why;
  return path;
}

// The fit object of the report section "Fit NAME" of `flexarm run SESSION --json`.
json reportedFit(const std::string& session, const std::string& name) {
  const auto r = runFlexarm({"run", session, "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  if (r.code != 0) return nullptr;
  const json report = json::parse(r.out);
  for (const auto& s : report["sections"])
    if (s["title"] == "Fit " + name) return s["values"]["fit"];
  ADD_FAILURE() << "no section Fit " << name << " in " << r.out;
  return nullptr;
}

// The verb's JSON without the run's time, which is no result of the fit.
json verbFit(const std::vector<std::string>& args) {
  const auto r = runFlexarm(args);
  EXPECT_EQ(r.code, 0) << r.err;
  if (r.code != 0) return nullptr;
  json j = json::parse(r.out);
  EXPECT_GT(j["seconds"].get<double>(), 0.0);
  j.erase("seconds");
  return j;
}

TEST(CliFitJson, VerbAndReportWriteTheSameBytesForABlackBoxFit) {
  flexarm::FitRequest request;
  request.name = "oe daisy";
  request.options.model.kind = flexarm::FitModelKind::BlackBox;
  request.options.model.structure = flexarm::PolyStructure::Oe;
  request.options.model.orders = flexarm::PolyOrders{0, 2, 0, 0, 2, 1};
  request.estimation = flexarm::SecondsRange{0.0, 699.0};
  request.validation = flexarm::SecondsRange{700.0, 1023.0};
  const json verb = verbFit({"fit", kDaisy, "--model", "oe:2,2,1", "--range", "0:699", "--validation-range",
                             "700:1023", "--json"});
  const json report = reportedFit(sessionWith(kDaisy, request, "oe_daisy.json"), request.name);
  ASSERT_TRUE(verb.is_object() && report.is_object());
  EXPECT_EQ(verb["format"], flexarm::kFitJsonFormat);
  EXPECT_EQ(verb["version"], flexarm::kFitJsonVersion);
  EXPECT_EQ(verb["status"], "ok");
  EXPECT_EQ(verb["fit_percent_validation_experiments"][0]["log"], kDaisy);
  EXPECT_EQ(verb.dump(2), report.dump(2));
}

TEST(CliFitJson, VerbAndReportWriteTheSameBytesForAPhysicalFit) {
  flexarm::FitRequest request;
  request.name = "two-mass chirp";
  flexarm::FitOptions& o = request.options;
  o.model.kind = flexarm::FitModelKind::Physical;
  o.model.start = flexarm::makeModel("two-mass");
  o.decimation = 10;
  o.closedLoop = flexarm::ClosedLoopChoice::TwoStage;
  o.startValues = {{"J_a", 10.0}};
  o.bounds = {{"d_a", 0.0, 1000.0}};
  request.estimation = flexarm::SecondsRange{0.5, 12.0};
  request.validation = flexarm::SecondsRange{12.0, 17.5};
  const json verb = verbFit({"fit", kChirp, "--model", "two-mass", "--decimate", "10", "--closed-loop", "two-stage",
                             "--start", "J_a=10", "--bound", "d_a=0:1000", "--range", "0.5:12", "--validation-range",
                             "12:17.5", "--json"});
  const std::string session = sessionWith(kChirp, request, "two_mass_chirp.json");
  const json report = reportedFit(session, request.name);
  ASSERT_TRUE(verb.is_object() && report.is_object());
  EXPECT_EQ(verb["closed_loop_method"], "two-stage");
  EXPECT_EQ(verb["parameters"]["J_a"].is_number(), true);
  EXPECT_EQ(verb.dump(2), report.dump(2));

  // What a session keeps of the fit is the same object's keys, written by the same pieces.
  flexarm::FitResult run;
  {
    const auto read = flexarm::readLog(kChirp, {});
    ASSERT_TRUE(read.ok);
    run = flexarm::runFitRequest(request, read.data);
  }
  ASSERT_TRUE(run.ok()) << run.message;
  const json stored = flexarm::storedFitToJson(flexarm::storedFitOf(run));
  ASSERT_FALSE(stored.empty());
  for (const auto& [key, value] : stored.items()) {
    ASSERT_TRUE(verb.contains(key)) << key;
    EXPECT_EQ(value.dump(), verb[key].dump()) << key;
  }
}

}  // namespace
