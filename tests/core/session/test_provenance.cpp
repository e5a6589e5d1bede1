// Provenance of results: every estimate and run records the data it was computed on, a report
// on other data shows the stored numbers with "computed on X; the open log is Y" instead of
// recomputing them, sessions keep the record, and names of estimates on different data differ.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/session/fit_request.h"
#include "core/session/provenance.h"
#include "core/session/replay.h"
#include "core/session/session.h"
#include "core/session/sha256.h"

using namespace flexarm;
using nlohmann::json;

namespace {

const std::string kDir = std::string(FLEXARM_SAMPLE_DIR);
const std::string kSample = kDir + "/sample_session.json";
const std::string kChirp = "three_mass_estimation_chirp.csv";
const std::string kBacklash = "effect_backlash.csv";

std::string sumOf(const std::string& file) {
  std::string why;
  auto s = sha256OfFile(kDir + "/" + file, &why);
  EXPECT_TRUE(s) << why;
  return s.value_or("");
}

Provenance chirpProvenance(const Session& s) {
  Provenance p = sessionDataProvenance(s, kDir + "/" + kChirp, sumOf(kChirp));
  p.when = "2026-11-20T10:00:00Z";
  return p;
}

// The sample session with only its three-mass fit, stored as computed on the chirp log with
// numbers no replay produces (J_g = 11.1, fit % -121.65: the values).
Session sessionWithStoredFit() {
  auto loaded = loadSession(kSample);
  EXPECT_TRUE(loaded.ok) << loaded.message;
  Session s = loaded.session;
  s.logs.resize(1);
  std::string why;
  auto request = fitRequestFromJson(s.parts["fits"]["requests"][0], &why);
  EXPECT_TRUE(request) << why;
  request->name = "three-mass estimate (three_mass_estimation_chirp.csv 0.5-12 s)";
  request->provenance = chirpProvenance(s);
  StoredFit f;
  f.parameters = {{"J_m", "kg m^2", 0.000512, 1e-5, 0.000486, 0.000538, true, "", true, {}},
                  {"J_g", "kg m^2", 11.1, 0.4, 10.07, 12.13, true, "", true, {}},
                  {"f_m", "N m s/rad", 0.0355, 0.0, 0.0, 0.0, false, "", true, {}}};
  f.loss = 0.0123;
  f.fitEstimation = -121.65;
  f.notches = {101.5};
  f.peaks = {160.2, 211.1};
  request->stored = f;
  s.parts = json::object();
  s.parts["fits"] = {{"nonparametric", false}, {"requests", json::array({fitRequestToJson(*request)})}};
  return s;
}

const json* sectionValues(const json& report, const std::string& title) {
  for (const auto& s : report["sections"])
    if (s["title"] == title) return &s["values"];
  return nullptr;
}

}  // namespace

TEST(Provenance, JsonRoundTripAndRefusals) {
  Provenance p;
  p.log = "chirp.csv";
  p.sha256 = std::string(64, 'a');
  p.preprocessing = {"motor velocity by central differences", "mean removal"};
  p.estimation = SecondsRange{0.5, 12.0};
  p.validation = SecondsRange{12.0, 17.5};
  p.when = "2026-11-24T04:45:00Z";
  std::string why;
  auto back = provenanceFromJson(json::parse(provenanceToJson(p).dump()), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(*back, p);
  json bad = provenanceToJson(p);
  bad["preprocessing"] = json::array({1, 2});
  EXPECT_FALSE(provenanceFromJson(bad, &why));
  EXPECT_NE(why.find("preprocessing"), std::string::npos) << why;
  bad = provenanceToJson(p);
  bad.erase("sha256");
  EXPECT_FALSE(provenanceFromJson(bad, &why));
  EXPECT_NE(why.find("sha256"), std::string::npos) << why;
  bad = provenanceToJson(p);
  bad["estimation_s"] = json::array({3.0, 1.0});
  EXPECT_FALSE(provenanceFromJson(bad, &why));
}

TEST(Provenance, SameDataIsTheSameLogPreprocessedTheSameWay) {
  Provenance a;
  a.log = "chirp.csv";
  a.sha256 = "11";
  a.estimation = SecondsRange{0.5, 12.0};
  Provenance b = a;
  b.estimation = SecondsRange{1.0, 5.0};  // another range of the same signal
  b.when = "later";
  EXPECT_TRUE(sameData(a, b));
  EXPECT_EQ(dataMismatch(a, b), "");
  b.preprocessing = {"mean removal"};
  EXPECT_FALSE(sameData(a, b));
  EXPECT_NE(dataMismatch(a, b).find("preprocessed differently"), std::string::npos);
  b = a;
  b.log = "effect_backlash.csv";
  b.sha256 = "22";
  const std::string m = dataMismatch(a, b);
  EXPECT_NE(m.find("computed on chirp.csv (SHA-256 11"), std::string::npos) << m;
  EXPECT_NE(m.find("the open log is effect_backlash.csv (SHA-256 22"), std::string::npos) << m;
}

TEST(Provenance, EstimatesOnDifferentDataNeverShareAName) {
  Provenance a;
  a.log = "chirp.csv";
  a.estimation = SecondsRange{0.5, 12.0};
  Provenance b;
  b.log = "effect_backlash.csv";
  std::vector<std::string> taken = {"three-mass"};
  const std::string first = uniqueResultName("three-mass estimate", a, taken);
  EXPECT_EQ(first, "three-mass estimate (chirp.csv 0.5-12 s)");
  taken.push_back(first);
  const std::string second = uniqueResultName("three-mass estimate", b, taken);
  EXPECT_EQ(second, "three-mass estimate 2 (effect_backlash.csv whole log)");
  taken.push_back(second);
  // The same data again still gets a name of its own; a session's old plain name counts too.
  const std::string third = uniqueResultName("three-mass estimate", a, taken);
  EXPECT_EQ(third, "three-mass estimate 3 (chirp.csv 0.5-12 s)");
  EXPECT_EQ(uniqueResultName("two-mass estimate", a, {"two-mass estimate"}),
            "two-mass estimate 2 (chirp.csv 0.5-12 s)");
}

TEST(Provenance, FitRequestKeepsProvenanceAndStoredNumbersThroughJson) {
  const Session s = sessionWithStoredFit();
  std::string why;
  auto r = fitRequestFromJson(json::parse(s.parts["fits"]["requests"][0].dump()), &why);
  ASSERT_TRUE(r) << why;
  ASSERT_TRUE(r->provenance && r->stored);
  EXPECT_EQ(*r->provenance, chirpProvenance(s));
  ASSERT_EQ(r->stored->parameters.size(), 3u);
  EXPECT_EQ(r->stored->parameters[1].name, "J_g");
  EXPECT_EQ(r->stored->parameters[1].value, 11.1);
  EXPECT_FALSE(r->stored->parameters[2].free);
  EXPECT_EQ(r->stored->fitEstimation, -121.65);
  EXPECT_FALSE(r->stored->fitValidation);
  EXPECT_EQ(r->stored->peaks, (std::vector<double>{160.2, 211.1}));
  // Sessions written before provenance still read: a request without it has none.
  json old = s.parts["fits"]["requests"][0];
  old.erase("provenance");
  old.erase("result");
  r = fitRequestFromJson(old, &why);
  ASSERT_TRUE(r) << why;
  EXPECT_FALSE(r->provenance);
  EXPECT_FALSE(r->stored);
  // And the whole session survives its text form.
  auto parsed = parseSession(toJsonText(s));
  ASSERT_TRUE(parsed.ok) << parsed.message;
  EXPECT_EQ(parsed.session.parts["fits"], s.parts["fits"]);
}

// The case: fit on the chirp log, open effect_backlash.csv, export the report.
TEST(Provenance, ReportOnAnotherLogShowsTheStoredFitAndRecomputesNothing) {
  Session s = sessionWithStoredFit();
  s.logs.front().path = kBacklash;
  s.logs.front().sha256 = sumOf(kBacklash);
  const ReplayResult r = replaySession(s, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json j = r.report.toJson();
  const json* fit = sectionValues(j, "Fit three-mass estimate (three_mass_estimation_chirp.csv 0.5-12 s)");
  ASSERT_NE(fit, nullptr) << j.dump(1);
  EXPECT_FALSE((*fit)["recomputed"].get<bool>());
  EXPECT_EQ((*fit)["computed_on"]["log"], kChirp);
  EXPECT_EQ((*fit)["computed_on"]["sha256"], sumOf(kChirp));
  const json& stored = (*fit)["fit"];  // the fit schema's keys a stored fit keeps
  EXPECT_EQ(stored["parameters"]["J_g"].get<double>(), 11.1);
  EXPECT_EQ(stored["parameter_rows"][1]["name"], "J_g");
  EXPECT_EQ(stored["fit_percent"].get<double>(), -121.65);
  EXPECT_FALSE(stored.contains("termination"));  // no fit ran
  // The section says where the numbers come from and which log is open.
  const ReportSection* section = nullptr;
  for (const auto& sec : r.report.sections)
    if (sec.title.rfind("Fit ", 0) == 0) section = &sec;
  ASSERT_NE(section, nullptr);
  const std::string& first = section->paragraphs.front();
  EXPECT_NE(first.find("computed on " + kChirp + " (SHA-256 " + sumOf(kChirp).substr(0, 16)), std::string::npos)
      << first;
  EXPECT_NE(first.find("the open log is " + kBacklash + " (SHA-256 " + sumOf(kBacklash).substr(0, 16)),
            std::string::npos)
      << first;
  EXPECT_TRUE(std::any_of(r.report.warnings.begin(), r.report.warnings.end(),
                          [](const std::string& w) { return w.find("computed on") != std::string::npos; }));
  EXPECT_EQ(r.report.logs.front().sha256, sumOf(kBacklash));
}

TEST(Provenance, ReportOnTheSameDataRecomputesAndSaysOnWhat) {
  Session s = sessionWithStoredFit();
  const ReplayResult r = replaySession(s, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json j = r.report.toJson();
  const json* fit = sectionValues(j, "Fit three-mass estimate (three_mass_estimation_chirp.csv 0.5-12 s)");
  ASSERT_NE(fit, nullptr);
  EXPECT_TRUE((*fit)["recomputed"].get<bool>());
  EXPECT_EQ((*fit)["fit"]["termination"], "converged");
  // A real fit on the chirp log, not the stored J_g = 11.1 (Table 5.7's 9.92 within 20 %).
  EXPECT_NEAR((*fit)["fit"]["parameters"]["J_g"].get<double>() / 9.92, 1.0, 0.2);
}

TEST(Provenance, PartOnOtherDataShowsItsStoredResultOnly) {
  auto loaded = loadSession(kSample);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  Session s = loaded.session;
  json discovery = s.parts["discovery"];
  ASSERT_TRUE(discovery.contains("result"));
  Provenance other = chirpProvenance(s);
  other.log = "old_run.csv";
  other.sha256 = std::string(64, '0');
  discovery["provenance"] = provenanceToJson(other);
  s.parts = json::object();
  s.parts["discovery"] = discovery;
  json diagnosis = loaded.session.parts["diagnosis"];
  diagnosis["provenance"] = provenanceToJson(other);
  s.parts["diagnosis"] = diagnosis;
  const ReplayResult r = replaySession(s, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json j = r.report.toJson();
  const json* d = sectionValues(j, "Discovery: the missing effect");
  ASSERT_NE(d, nullptr) << j.dump(1);
  EXPECT_FALSE((*d)["recomputed"].get<bool>());
  EXPECT_EQ((*d)["computed_on"]["log"], "old_run.csv");
  EXPECT_EQ((*d)["effect"], discovery["result"]["effect"]);  // the stored verdict
  const json* g = sectionValues(j, "Diagnosis (computed on other data)");
  ASSERT_NE(g, nullptr) << j.dump(1);
  EXPECT_FALSE((*g)["recomputed"].get<bool>());
}
