// The session part "fits": requests survive their JSON form, malformed ones are refused with
// a sentence, and replaying the sample session identifies the three-mass arm of the chirp
// log (Table 5.7 p6 truth) with 99 % intervals (5.7), fit % (5.2), notches and peaks (5.4)
// and residual tests, the same on every replay.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "core/ident/fit_json.h"
#include "core/io/log_io.h"
#include "core/models/analysis.h"
#include "core/signal/preprocess.h"
#include "core/session/fit_request.h"
#include "core/session/replay.h"
#include "core/session/session.h"
#include "tests/core/ident/nonlinear_logs.h"

using namespace flexarm;
using nlohmann::json;

namespace {

const std::string kSample = std::string(FLEXARM_SAMPLE_DIR) + "/sample_session.json";
const std::string kTruth =
    std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.truth.json";

const json* section(const json& report, const std::string& title) {
  for (const auto& s : report["sections"])
    if (s["title"] == title) return &s["values"];
  return nullptr;
}

std::map<std::string, double> truth() {
  std::ifstream in(kTruth);
  const json t = json::parse(in);
  std::map<std::string, double> out;
  for (const auto& p : t["model"]["parameters"]) out[p["name"]] = p["value"].get<double>();
  return out;
}

FitRequest blackBoxRequest() {
  FitRequest r;
  r.name = "oe[4 4 1]";
  FitModelSpec& m = r.options.model;
  m.kind = FitModelKind::BlackBox;
  m.structure = PolyStructure::Oe;
  m.orders.na = 0;
  m.orders.nb = 4;
  m.orders.nf = 4;
  m.orders.nk = 1;
  r.options.decimation = 2;
  r.estimation = SecondsRange{0.5, 12.0};
  return r;
}

FitRequest physicalRequest(std::shared_ptr<const PhysicalModel> start) {
  FitRequest r;
  r.options.model.kind = FitModelKind::Physical;
  r.options.model.start = std::move(start);
  return r;
}

}  // namespace

TEST(FitRequest, JsonRoundTripKeepsEveryField) {
  auto start = makeModel("three-mass");
  for (const auto& q : start->parameters()) start->setFree(q.name, q.name == "k_g" || q.name == "J_a");
  start->setParameter("k_g", 123456.0);
  FitRequest p = physicalRequest(std::move(start));
  p.name = "three-mass estimate";
  p.options.noiseModel = NoiseModel::Innovations;
  p.options.closedLoop = ClosedLoopChoice::Direct;
  p.options.randomStarts = 3;
  p.options.seed = 7;
  p.options.decimation = 5;
  p.options.maxIterations = 40;
  p.estimation = SecondsRange{0.5, 12.0};
  p.validation = SecondsRange{12.0, 17.5};
  p.options.startValues = {{"J_a", 1.5}, {"r", 1.0}};
  p.options.bounds = {{"k_g", 1e4, INFINITY}, {"d_g", -INFINITY, INFINITY}};
  std::string why;
  auto back = fitRequestFromJson(fitRequestToJson(p), &why);
  ASSERT_TRUE(back) << why;
  // Start values and bounds come back, open ends (null in JSON) as infinities.
  ASSERT_EQ(back->options.startValues.size(), 2u);
  EXPECT_EQ(back->options.startValues[0].name, "J_a");
  EXPECT_EQ(back->options.startValues[0].value, 1.5);
  ASSERT_EQ(back->options.bounds.size(), 2u);
  EXPECT_EQ(back->options.bounds[0].name, "d_g");  // JSON objects keep names in order
  EXPECT_EQ(back->options.bounds[0].lower, -INFINITY);
  EXPECT_EQ(back->options.bounds[1].lower, 1e4);
  EXPECT_EQ(back->options.bounds[1].upper, INFINITY);
  {
    json bad = fitRequestToJson(p);
    bad["start_values"]["J_x"] = 1.0;
    EXPECT_FALSE(fitRequestFromJson(bad, &why));
    EXPECT_NE(why.find("no parameter 'J_x'"), std::string::npos) << why;
    bad = fitRequestToJson(p);
    bad["bounds"]["k_g"] = json::array({5.0});
    EXPECT_FALSE(fitRequestFromJson(bad, &why));
    EXPECT_NE(why.find("[lower, upper]"), std::string::npos) << why;
  }
  EXPECT_EQ(fitRequestToJson(*back).dump(), fitRequestToJson(p).dump());
  EXPECT_TRUE(back->physical());
  EXPECT_EQ(back->options.model.start->value("k_g"), 123456.0);
  EXPECT_EQ(back->options.noiseModel, NoiseModel::Innovations);
  EXPECT_EQ(back->options.seed, 7u);
  EXPECT_EQ(*back->validation, (SecondsRange{12.0, 17.5}));
  // Auto is stored as such; a request written before closed_loop existed ran direct fits.
  p.options.noiseModel = NoiseModel::OutputError;
  p.options.closedLoop = ClosedLoopChoice::Auto;
  json j = fitRequestToJson(p);
  EXPECT_EQ(j["closed_loop"], "auto");
  EXPECT_EQ(fitRequestFromJson(j, &why)->options.closedLoop, ClosedLoopChoice::Auto);
  j.erase("closed_loop");
  EXPECT_EQ(fitRequestFromJson(j, &why)->options.closedLoop, ClosedLoopChoice::Direct);

  auto bb = fitRequestFromJson(fitRequestToJson(blackBoxRequest()), &why);
  ASSERT_TRUE(bb) << why;
  EXPECT_FALSE(bb->physical());
  EXPECT_EQ(bb->options.model.orders.nf, 4);
  EXPECT_FALSE(bb->validation.has_value());
}

TEST(FitRequest, MalformedRequestsAreRefusedWithASentence) {
  json j = fitRequestToJson(blackBoxRequest());
  std::string why;
  json bad = j;
  bad["structure"] = "narx";
  EXPECT_FALSE(fitRequestFromJson(bad, &why));
  EXPECT_NE(why.find("arx, armax, oe, bj or ss"), std::string::npos) << why;
  bad = j;
  bad["decimation"] = 0;
  EXPECT_FALSE(fitRequestFromJson(bad, &why));
  EXPECT_NE(why.find("decimation"), std::string::npos) << why;
  bad = j;
  bad["estimation_s"] = {12.0, 0.5};
  EXPECT_FALSE(fitRequestFromJson(bad, &why));
  EXPECT_NE(why.find("start < end"), std::string::npos) << why;
  bad = j;
  bad["orders"]["nb"] = 0;  // no input term
  EXPECT_FALSE(fitRequestFromJson(bad, &why));
  EXPECT_NE(why.find("orders"), std::string::npos) << why;

  // A physical request without a free parameter is refused, and so is a session holding it.
  auto start = makeModel("two-mass");
  for (const auto& q : start->parameters()) start->setFree(q.name, false);
  FitRequest p = physicalRequest(std::move(start));
  p.name = "fixed";
  EXPECT_FALSE(fitRequestFromJson(fitRequestToJson(p), &why));
  EXPECT_NE(why.find("free parameter"), std::string::npos) << why;
  auto loaded = loadSession(kSample);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  loaded.session.parts["fits"]["requests"].push_back(fitRequestToJson(p));
  const auto parsed = parseSession(toJsonText(loaded.session));
  EXPECT_FALSE(parsed.ok);
  EXPECT_NE(parsed.message.find("fits"), std::string::npos) << parsed.message;
}

TEST(FitsPart, SampleSessionIdentifiesTheThreeMassArm) {
  auto loaded = loadSession(kSample);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  ReplayResult r = replaySession(loaded.session, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json j = r.report.toJson();
  const json* fit = section(j, "Fit three-mass estimate");
  ASSERT_NE(fit, nullptr) << j.dump(1);
  fit = &fit->at("fit");  // the fit schema's object (core/ident/fit_json.h)
  EXPECT_EQ((*fit)["termination"], "converged");
  const auto t = truth();
  // The free parameters start 12-32 % off the truth. The log is closed loop and decimated to
  // 200 Hz, so the output-error estimate is biased by the noise fed back into the input
  // (4.43): on this log J_m and J_g land 14-16 % off (random starts find the same minimum),
  // far beyond their 99 % intervals; the springs and J_a within 10 %.
  for (const char* p : {"J_m", "J_g", "J_a", "k_g", "k_a"}) {
    const double v = (*fit)["parameters"][p].get<double>(), s = (*fit)["std"][p].get<double>();
    EXPECT_GT(s, 0.0) << p;
    const double tol = std::string(p) == "J_m" || std::string(p) == "J_g" ? 0.20 : 0.10;
    EXPECT_NEAR(v / t.at(p), 1.0, tol) << p << " = " << v << " +- " << s;
  }
  for (const char* p : {"f_m", "d_g", "d_a"}) {  // held at their start values
    EXPECT_EQ((*fit)["std"][p].get<double>(), 0.0) << p;
    EXPECT_EQ((*fit)["parameters"][p].get<double>(), t.at(p)) << p;
  }
  EXPECT_GT((*fit)["fit_percent"].get<double>(), 75.0);
  EXPECT_GT((*fit)["fit_percent_validation"].get<double>(), 75.0);
  // The report names both fit percentages: (5.2) and MATLAB compare's NRMSE fit.
  for (const char* k : {"fit_percent", "fit_percent_validation"})
    EXPECT_NEAR((*fit)[std::string(k) + "_nrmse"].get<double>(),
                100.0 * (1.0 - std::sqrt(1.0 - (*fit)[k].get<double>() / 100.0)), 1e-9) << k;
  EXPECT_GT((*fit)["loss"].get<double>(), 0.0);
  // Three masses: two anti-resonances and two resonances (5.4), each within 10 % of the
  // truth's, which the resonances determine better than single parameters.
  const StateSpace truthSys = makeModel("three-mass")->stateSpace();
  const auto truthNotches = notchFrequencies(truthSys), truthPeaks = peakFrequencies(truthSys);
  ASSERT_EQ((*fit)["notches_rad_s"].size(), truthNotches.size());
  ASSERT_EQ((*fit)["peaks_rad_s"].size(), truthPeaks.size());
  ASSERT_EQ(truthPeaks.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_NEAR((*fit)["notches_rad_s"][i].get<double>() / truthNotches[i].frequency, 1.0, 0.10) << i;
    EXPECT_NEAR((*fit)["peaks_rad_s"][i].get<double>() / truthPeaks[i].frequency, 1.0, 0.10) << i;
  }
  // One definition of notches and peaks (core/models/analysis.h): the report's are those of
  // the estimated model as `flexarm model` and the Model panel compute them.
  {
    auto estimate = makeModel("three-mass");
    for (auto it = (*fit)["parameters"].begin(); it != (*fit)["parameters"].end(); ++it)
      estimate->setParameter(it.key(), it.value().get<double>());
    const NotchesPeaks np = notchesAndPeaks(estimate->stateSpace());
    ASSERT_EQ(np.notches.size(), 2u);
    ASSERT_EQ(np.peaks.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_NEAR((*fit)["notches_rad_s"][i].get<double>() / np.notches[i], 1.0, 1e-6) << i;
      EXPECT_NEAR((*fit)["peaks_rad_s"][i].get<double>() / np.peaks[i], 1.0, 1e-6) << i;
    }
  }
  // Closed-loop output error leaves coloured residuals: the tests say so.
  EXPECT_FALSE((*fit)["residuals"]["white"].get<bool>());

  // The SPA of the estimation range (0.5-12 s at 200 Hz): the lag window chosen from the data
  // spans 1 s (200 lags, less than N/10 = 230), and the report says why.
  const json* np = section(j, "Non-parametric estimate (SPA)");
  ASSERT_NE(np, nullptr);
  const json* data = section(j, "Data");
  ASSERT_NE(data, nullptr);
  EXPECT_EQ((*np)["samples"], (*data)["ranges"]["estimation"]["samples"]);
  EXPECT_EQ((*np)["lag_window"].get<int>(), 200);
  EXPECT_NE((*np)["lag_window_note"].get<std::string>().find("chosen from the data: 1 s at 200 Hz"),
            std::string::npos) << (*np)["lag_window_note"];

  // The report's parameter table shows value, std and the 99 % interval (z = 2.576).
  const ReportSection* rs = nullptr;
  for (const auto& s : r.report.sections)
    if (s.title == "Fit three-mass estimate") rs = &s;
  ASSERT_NE(rs, nullptr);
  const auto& rows = rs->tables.at(0).rows;
  int checked = 0;
  for (const auto& row : rows) {
    if (row[2] == "fixed") continue;
    const double v = std::stod(row[1]), s = std::stod(row[2]);
    const double lo = std::stod(row[3]), hi = std::stod(row[4]);
    EXPECT_NEAR((hi - lo) / 2.0, 2.576 * s, 0.01 * s + 1e-5 * std::abs(v)) << row[0];
    ++checked;
  }
  EXPECT_EQ(checked, 5);
  // Bode magnitude with its band, phase, compare, and two correlation plots.
  ASSERT_EQ(rs->plots.size(), 5u);
  EXPECT_EQ(rs->plots[0].series.size(), 3u);
}

TEST(FitsPart, BlackBoxRequestIsReplayedAtItsDecimatedRate) {
  auto loaded = loadSession(kSample);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  Session s = loaded.session;
  FitRequest bb = blackBoxRequest();
  bb.validation = SecondsRange{12.0, 17.5};
  s.parts["fits"]["requests"] = json::array({fitRequestToJson(bb)});
  s.parts["fits"]["nonparametric"] = false;
  ReplayResult r = replaySession(s, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json j = r.report.toJson();
  EXPECT_EQ(section(j, "Non-parametric estimate (SPA)"), nullptr);
  const json* fit = section(j, "Fit oe[4 4 1]");
  ASSERT_NE(fit, nullptr);
  fit = &fit->at("fit");
  EXPECT_EQ((*fit)["parameters"].size(), 8u);  // b1..b4, f1..f4
  EXPECT_GT((*fit)["fit_percent_validation"].get<double>(), 50.0);
  // The same request on the same data gives the same numbers.
  auto prepared = prepareSession(s, kSample);
  ASSERT_TRUE(prepared.ok) << prepared.message;
  const FitResult run = runFitRequest(bb, prepared.logs[0].data);
  ASSERT_TRUE(run.polynomial);
  EXPECT_NEAR(run.polynomial->sampleTime, 0.01, 1e-12);  // 200 Hz decimated by 2
  EXPECT_EQ(run.fitValidation().value(), (*fit)["fit_percent_validation"].get<double>());
}

TEST(FitsPart, DataFailuresBecomeSentences) {
  auto loaded = loadSession(kSample);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  Session s = loaded.session;
  FitRequest bb = blackBoxRequest();
  bb.estimation = SecondsRange{100.0, 200.0};  // beyond the log's 18 s
  s.parts["fits"]["requests"] = json::array({fitRequestToJson(bb)});
  ReplayResult r = replaySession(s, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  for (const auto& sec : r.report.sections)
    if (sec.title == "Fit oe[4 4 1]") {
      EXPECT_EQ(sec.values["fit"]["status"], "bad-data");
      ASSERT_FALSE(sec.paragraphs.empty());  // the sentence names the range and the log's extent
      EXPECT_NE(sec.paragraphs.back().find("No fit: the estimation range 100-200 s holds no samples of the log"),
                std::string::npos)
          << sec.paragraphs.back();
      return;
    }
  FAIL() << "no fit section";
}

// The indirect closed-loop fit as the Fit panel and a session run it: the chirp sample log's
// controller (from its metadata) closed around the three-mass model, fitted from the
// reference; every free parameter's 99 % interval holds the truth of the sidecar, from a start
// 10-30 % away. Decimated data, where the controller's loop cannot be closed, get a sentence.
TEST(FitsPart, IndirectRequestRecoversTheChirpTruthInsideItsIntervals) {
  const auto read = readLog(std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv");
  ASSERT_TRUE(read.ok) << read.error.problem;
  auto start = makeModel("three-mass");
  const std::pair<const char*, double> off[] = {{"J_m", 1.2}, {"J_g", 0.8}, {"J_a", 1.15},
                                                {"k_g", 0.85}, {"k_a", 1.1}, {"d_a", 1.25}};
  for (const auto& [name, f] : off) start->setParameter(name, start->value(name) * f);
  FitRequest req = physicalRequest(std::move(start));
  req.name = "three-mass indirect";
  req.options.closedLoop = ClosedLoopChoice::Indirect;
  // The truth's d_g is the seed's negative -62 (Table 5.7 p6): the request opens the fit's
  // default bound d_g >= 0, and the session keeps the open bound.
  req.options.bounds = {{"d_g", -INFINITY, INFINITY}};
  req.estimation = SecondsRange{0.0, 12.0};
  req.validation = SecondsRange{12.0, 17.5};
  std::string why;
  const auto back = fitRequestFromJson(fitRequestToJson(req), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->options.closedLoop, ClosedLoopChoice::Indirect);

  const FitResult run = runFitRequest(*back, read.data);
  ASSERT_EQ(run.termination, Termination::Converged) << run.message;
  ASSERT_TRUE(run.method.has_value());
  EXPECT_EQ(*run.method, ClosedLoopMethod::Indirect);
  EXPECT_NE(run.methodDescription.find("indirect closed-loop fit"), std::string::npos) << run.methodDescription;
  EXPECT_NE(run.controllerSource.find("metadata"), std::string::npos) << run.controllerSource;
  const auto t = truth();
  int checked = 0;
  for (const auto& p : run.parameters) {
    if (!p.free) continue;
    EXPECT_GE(t.at(p.name), p.lower) << p.name << " = " << p.value << " +- " << p.std;
    EXPECT_LE(t.at(p.name), p.upper) << p.name << " = " << p.value << " +- " << p.std;
    ++checked;
  }
  EXPECT_EQ(checked, 8);
  ASSERT_TRUE(run.fitValidation().has_value());
  EXPECT_GT(*run.fitValidation(), 70.0);

  // Decimated data cannot carry the controller's loop: the request is refused with a sentence.
  FitRequest decimated = *back;
  decimated.options.decimation = 4;
  EXPECT_FALSE(decimated.isValid(&why));
  EXPECT_EQ(fitOptionsOf(decimated, nullptr).checkExceptData().issue, FitIssue::IndirectExcludesDecimation) << why;
  EXPECT_THROW(runFitRequest(decimated, read.data), std::invalid_argument);
  // The session's own preprocessing may decimate the log: then the data say so.
  DecimateOptions d4;
  d4.factor = 4;
  const FitResult refused = runFitRequest(*back, decimate(read.data, d4));
  EXPECT_EQ(refused.termination, Termination::Failed);
  EXPECT_NE(refused.message.find("controller's rate"), std::string::npos) << refused.message;
}

// A physical fit with effects: the request keeps the start model's effects, their values and
// which are free through its JSON form, and its replay on the log is the fit pipeline's
// nonlinear fit, number for number; a malformed effects_free is refused with a sentence.
TEST(FitRequest, EffectsRoundTripAndReplayAsTheFit) {
  FitRequest p = physicalRequest(makeModel("three-mass"));
  p.name = "three-mass + effects estimate";
  FitEffect spring = FitEffect::defaults(EffectKind::NonlinearSpring);
  spring.effect.values[0] = 1.5e6;
  FitEffect coulomb = FitEffect::defaults(EffectKind::CoulombFriction);
  coulomb.effect.values = {0.03, 0.2};
  coulomb.free = {true, true};
  p.options.model.effects = {spring, coulomb};
  p.options.maxIterations = 6;
  std::string why;
  auto back = fitRequestFromJson(json::parse(fitRequestToJson(p).dump()), &why);
  ASSERT_TRUE(back) << why;
  ASSERT_EQ(back->options.model.effects.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const FitEffect& a = p.options.model.effects[i];
    const FitEffect& b = back->options.model.effects[i];
    EXPECT_EQ(a.effect.kind, b.effect.kind);
    EXPECT_EQ(a.effect.values, b.effect.values);
    EXPECT_EQ(a.free, b.free);
  }
  const IdData data = flexarm::testing::nonlinearLog(1200, 0, 21);
  const FitResult replayed = runFitRequest(*back, data);
  const std::shared_ptr<const IdData> view(&data, [](const IdData*) {});
  const FitResult direct = fitModel(fitOptionsOf(p, view));
  ASSERT_TRUE(replayed.ok()) << replayed.message;
  ASSERT_EQ(replayed.parameters.size(), direct.parameters.size());
  for (std::size_t i = 0; i < direct.parameters.size(); ++i) {
    EXPECT_EQ(replayed.parameters[i].value, direct.parameters[i].value) << direct.parameters[i].name;
    EXPECT_EQ(replayed.parameters[i].effect, direct.parameters[i].effect);
  }
  ASSERT_EQ(replayed.effects.size(), 2u);
  EXPECT_EQ(replayed.effects[1].kind, EffectKind::CoulombFriction);

  json bad = fitRequestToJson(p);
  bad["effects_free"] = json::array({json::array({true, true})});
  EXPECT_FALSE(fitRequestFromJson(bad, &why));
  EXPECT_NE(why.find("effects_free"), std::string::npos) << why;
}

// A session keeps a fit's numbers in the fit schema's keys (core/ident/fit_json.h); one written
// before version 2 of the schema ("parameters" a list, fit_estimation_percent and
// fit_validation_percent) still opens with the same numbers.
TEST(FitsPart, StoredFitsOfEitherSchemaVersionRead) {
  StoredFit f;
  f.parameters = {{"J_m", "kg m^2", 5e-4, 1e-5, 4.7e-4, 5.3e-4, true, "", true, {}},
                  {"beta", "1/rad^2", 2e6, 0.0, 0.0, 0.0, false, "nonlinear_spring", true, {}}};
  f.loss = 0.5;
  f.fitEstimation = 91.5;
  f.notches = {100.0};
  const json now = storedFitToJson(f);
  EXPECT_EQ(now["version"], kFitJsonVersion);
  EXPECT_EQ(now["fit_percent"], 91.5);
  EXPECT_TRUE(now["fit_percent_validation"].is_null());
  EXPECT_EQ(now["parameters"]["J_m"], 5e-4);
  EXPECT_EQ(now["parameter_rows"][1]["effect"], "nonlinear_spring");
  const json before = {{"parameters", json::array({{{"name", "J_m"}, {"unit", "kg m^2"}, {"value", 5e-4},
                                                     {"std", 1e-5}, {"free", true}}})},
                       {"loss", 0.5},
                       {"fit_estimation_percent", 91.5},
                       {"fit_validation_percent", 88.25},
                       {"notches_rad_s", {100.0}}};
  std::string why;
  for (const json& j : {now, before}) {
    const auto back = storedFitFromJson(j, &why);
    ASSERT_TRUE(back) << why << "\n" << j.dump();
    EXPECT_EQ(back->parameters.at(0).name, "J_m");
    EXPECT_EQ(back->parameters.at(0).value, 5e-4);
    EXPECT_EQ(back->fitEstimation, 91.5);
    EXPECT_EQ(back->notches, std::vector<double>{100.0});
  }
  EXPECT_EQ(storedFitFromJson(before, &why)->fitValidation, 88.25);
  EXPECT_FALSE(storedFitFromJson(now, &why)->fitValidation.has_value());
  json newer = now;
  newer["version"] = kFitJsonVersion + 1;
  EXPECT_FALSE(storedFitFromJson(newer, &why));
}
