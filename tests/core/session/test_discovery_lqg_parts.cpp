// The session parts "discovery" and "lqg": a session that runs discovery on a log with a hidden
// torque ripple (sample_logs/effect_torque_ripple.truth.json) and holds the seed's LQG
// case (ii) (R2 = 1e-8, an unstable regulator, Section 8.6) is saved, reopened and replayed:
// the verdict names the hidden effect and both replays give the same numbers; damaged
// sections are refused naming the part.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "core/session/discovery_part.h"
#include "core/session/lqg_part.h"
#include "core/session/model_json.h"
#include "core/session/replay.h"
#include "core/session/session.h"
#include "core/session/sha256.h"

namespace fs = std::filesystem;
using namespace flexarm;
using nlohmann::json;

namespace {

const std::string kDir = FLEXARM_SAMPLE_DIR;
const std::string kChirp = kDir + "/three_mass_estimation_chirp.csv";
const std::string kRipple = kDir + "/effect_torque_ripple.csv";
const char* kDiscoveryTitle = "Discovery: the missing effect";
const char* kLqgTitle = "LQG design (chapter 8)";

const json* values(const json& report, const std::string& title) {
  for (const auto& s : report["sections"])
    if (s["title"] == title) return &s["values"];
  return nullptr;
}

double truthOf(const std::string& parameter) {
  std::ifstream in(kDir + "/effect_torque_ripple.truth.json");
  const json t = json::parse(in);
  return t["effects"][0]["parameters"][parameter]["value"].get<double>();
}

DiscoveryRequest rippleRequest() {
  DiscoveryRequest q;
  q.baseStructure = "three-mass";  // the logs' arm: Table 5.7 p6
  q.rawData = true;
  q.estimation = {"ripple", SecondsRange{0.0, 6.0}};
  q.validation = DiscoveryDataRef{"ripple", SecondsRange{6.0, 10.0}};
  q.options.candidates = {EffectKind::CoulombFriction, EffectKind::Backlash, EffectKind::TorqueRipple};
  return q;
}

// The chirp log analysed, the ripple log for discovery, and the two parts; discovery starts
// from the model list's nominal three-mass arm, named "arm".
Session session(const std::string& path) {
  Session s;
  std::string why;
  for (const auto& [name, file] : {std::pair{"estimation", kChirp}, std::pair{"ripple", kRipple}}) {
    LogReference l;
    l.name = name;
    l.path = storedLogPath(path, file);
    l.sha256 = sha256OfFile(file, &why).value_or("");
    s.logs.push_back(l);
  }
  s.parts["models"] = json::array({modelToJson("arm", *makeModel("three-mass"), {})});
  DiscoveryRequest q = rippleRequest();
  q.baseStructure.clear();
  q.baseModel = "arm";
  s.parts["discovery"] = {{"request", discoveryRequestToJson(q)}};
  LqgRequest lqg;
  lqg.design = LqgOptions::seedCaseII();
  s.parts["lqg"] = lqgRequestToJson(lqg);
  return s;
}

fs::path scratch() {
  auto p = fs::temp_directory_path() / ("flexarm_parts_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

}  // namespace

TEST(DiscoveryPart, RequestAndResultSurviveTheirJson) {
  DiscoveryRequest q = rippleRequest();
  q.options.observerBandwidthHz = 0.5;
  q.options.threads = 1;
  q.options.maxEffects = 3;
  q.options.startEffects = {Effect::withDefaults(EffectKind::CoulombFriction)};
  std::string why;
  auto back = discoveryRequestFromJson(discoveryRequestToJson(q), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(discoveryRequestToJson(*back).dump(), discoveryRequestToJson(q).dump());
  EXPECT_EQ(back->options.candidates.size(), 3u);
  EXPECT_EQ(back->options.observerBandwidthHz, 0.5);
  EXPECT_EQ(back->options.maxEffects, 3);
  ASSERT_EQ(back->options.startEffects.size(), 1u);
  EXPECT_EQ(back->options.startEffects[0].kind, EffectKind::CoulombFriction);
  ASSERT_TRUE(back->validation && back->validation->range);
  EXPECT_EQ(back->validation->range->start, 6.0);

  DiscoveryResult r;
  r.effect = EffectKind::Backlash;
  r.tied = {EffectKind::InputDelay};
  r.evidence = "the gap shrinks";
  r.hasValidation = true;
  r.base.rmsValidation = 0.3;
  r.augmented.rmsValidation = 0.1;
  CandidateFit c;
  c.kind = EffectKind::Backlash;
  c.parameters = {{"b", "rad", 2e-4, 1e-5, 1.7e-4, 2.3e-4, true}};
  c.lossEst = 0.01;
  c.significant = true;
  c.reason = "all four tests pass";
  r.candidates = {c};
  r.best = 0;
  // The loop's steps: each effect with its parameters, confirmation and scores.
  FoundEffect f;
  f.kind = EffectKind::Backlash;
  f.effect = Effect::withDefaults(EffectKind::Backlash);
  f.parameters = c.parameters;
  f.evidence = "a gap";
  f.confirmation.ran = true;
  f.confirmation.confirmed = true;
  f.confirmation.text = "confirmed on the validation data";
  r.candidates[0].confirmation = f.confirmation;  // the named candidate keeps its own
  f.before.rmsValidation = 0.3;
  f.after.rmsValidation = 0.1;
  r.found = {f};
  r.stopReason = "none of the candidates is significant";
  r.validationData = "the validation data";
  auto rb = discoveryResultFromJson(discoveryResultToJson(r), &why);
  ASSERT_TRUE(rb) << why;
  EXPECT_EQ(discoveryResultToJson(*rb).dump(), discoveryResultToJson(r).dump());
  EXPECT_EQ(rb->candidates[0].parameters[0].std, 1e-5);
  ASSERT_EQ(rb->found.size(), 1u);
  EXPECT_TRUE(rb->found[0].confirmation.confirmed);
  // The named candidate says "yes, confirmed" again in the reopened panel.
  EXPECT_TRUE(rb->candidates[0].confirmation.ran && rb->candidates[0].confirmation.confirmed);
  EXPECT_EQ(rb->candidates[0].confirmation.text, f.confirmation.text);
  EXPECT_EQ(rb->found[0].after.rmsValidation, 0.1);
  EXPECT_EQ(rb->stopReason, r.stopReason);
}

TEST(LqgPart, RequestSurvivesItsJsonAndBadOnesAreRefused) {
  LqgRequest r;
  r.design = LqgOptions::seedAccelerationFeedback();
  r.design.parameters.k = 40.0;
  r.saturationLimit = 2.5;
  r.source = "model: two-mass";
  std::string why;
  auto back = lqgRequestFromJson(lqgRequestToJson(r), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(lqgRequestToJson(*back).dump(), lqgRequestToJson(r).dump());
  EXPECT_EQ(back->design.measurement, LqgMeasurement::MotorAngleAndArmAcceleration);
  EXPECT_EQ(back->design.r2(1), 1e-1);

  json j = lqgRequestToJson(r);
  j["q1"] = json::array({1.0, 2.0});
  EXPECT_FALSE(lqgRequestFromJson(j, &why));
  EXPECT_NE(why.find("Q1"), std::string::npos) << why;
}

TEST(SessionParts, DamagedDiscoveryAndLqgSectionsAreRefusedNamingThem) {
  const std::string path = (scratch() / "damaged.json").string();
  json j = json::parse(toJsonText(session(path)));
  json noBase = j;
  noBase["parts"]["discovery"]["request"].erase("base_model");
  auto a = parseSession(noBase.dump());
  EXPECT_FALSE(a.ok);
  EXPECT_NE(a.message.find("discovery"), std::string::npos) << a.message;
  EXPECT_NE(a.message.find("base_model"), std::string::npos) << a.message;

  json badEffect = j;
  badEffect["parts"]["discovery"]["request"]["options"]["candidates"] = json::array({"gremlins"});
  auto b = parseSession(badEffect.dump());
  EXPECT_FALSE(b.ok);
  EXPECT_NE(b.message.find("gremlins"), std::string::npos) << b.message;

  json badResult = j;
  badResult["parts"]["discovery"]["result"] = {{"effect", "torque_ripple"}};
  auto c = parseSession(badResult.dump());
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.message.find("discovery result"), std::string::npos) << c.message;

  json badLqg = j;
  badLqg["parts"]["lqg"]["q2"] = -1.0;
  auto d = parseSession(badLqg.dump());
  EXPECT_FALSE(d.ok);
  EXPECT_NE(d.message.find("lqg"), std::string::npos) << d.message;
  EXPECT_NE(d.message.find("LQG design"), std::string::npos) << d.message;

  EXPECT_TRUE(parseSession(j.dump()).ok);
}

TEST(SessionParts, SaveReopenReplayGivesTheSameVerdictAndLqgNumbers) {
  const std::string path = (scratch() / "parts.json").string();
  const Session s = session(path);
  std::string why;
  ASSERT_TRUE(saveSession(s, path, &why)) << why;
  auto reopened = loadSession(path);
  ASSERT_TRUE(reopened.ok) << reopened.message;

  const ReplayResult first = replaySession(s, path);
  ASSERT_EQ(first.termination, Termination::Converged) << first.message;
  const json a = first.report.toJson();
  const json* d = values(a, kDiscoveryTitle);
  ASSERT_NE(d, nullptr) << a.dump(1);
  EXPECT_EQ((*d)["effect"], "torque_ripple") << (*d)["evidence"];
  EXPECT_EQ((*d)["base_model"], "arm");
  // The augmented model explains the validation data better than the base.
  EXPECT_LT((*d)["augmented"]["rms_validation"].get<double>(),
            0.9 * (*d)["base"]["rms_validation"].get<double>());
  // The ripple amplitude A (N m) within 3 std of the value that generated the log.
  ASSERT_FALSE((*d)["effects"].empty());
  const json& magnitude = (*d)["effects"][0]["magnitude"];
  EXPECT_EQ(magnitude["name"], "A_1");
  const double amplitude = magnitude["value"].get<double>();
  const double sd = magnitude["std"].get<double>();
  EXPECT_GT(sd, 0.0);
  EXPECT_NEAR(amplitude, std::abs(truthOf("a_1")), 3.0 * sd);

  const json* l = values(a, kLqgTitle);
  ASSERT_NE(l, nullptr);
  // Case (ii): the regulator is unstable, the closed loop stable, so F_y G encircles -1
  // counter-clockwise once per right-half-plane pole of the regulator (Section 8.6).
  EXPECT_FALSE((*l)["regulator_stable"].get<bool>());
  EXPECT_TRUE((*l)["closed_loop_stable"].get<bool>());
  EXPECT_GT((*l)["rhp_regulator_poles"].get<int>(), 0);
  EXPECT_EQ((*l)["encirclements"], (*l)["rhp_regulator_poles"]);
  EXPECT_NEAR((*l)["min_distance_to_minus_one"].get<double>() * (*l)["max_sensitivity"].get<double>(), 1.0, 1e-6);

  // The result stored with the request; the reopened session replays to the same numbers.
  Session withResult = reopened.session;
  const ReplayResult second = replaySession(withResult, path);
  ASSERT_EQ(second.termination, Termination::Converged) << second.message;
  const json b = second.report.toJson();
  ASSERT_NE(values(b, kDiscoveryTitle), nullptr);
  EXPECT_EQ(values(b, kDiscoveryTitle)->dump(), d->dump());
  EXPECT_EQ(values(b, kLqgTitle)->dump(), l->dump());
}

TEST(SessionParts, MissingLogOrModelBecomesASentence) {
  const std::string path = (scratch() / "missing.json").string();
  Session s = session(path);
  DiscoveryRequest q = rippleRequest();
  q.estimation.log = "tomorrow";
  s.parts["discovery"] = {{"request", discoveryRequestToJson(q)}};
  s.parts.erase("lqg");
  const ReplayResult r = replaySession(s, path);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const json report = r.report.toJson();
  const json* d = values(report, kDiscoveryTitle);
  ASSERT_NE(d, nullptr);
  EXPECT_TRUE((*d)["effect"].is_null());
  EXPECT_NE((*d)["message"].get<std::string>().find("tomorrow"), std::string::npos);

  q = rippleRequest();
  q.baseStructure.clear();
  q.baseModel = "no such model";
  s.parts["discovery"] = {{"request", discoveryRequestToJson(q)}};
  const json again = replaySession(s, path).report.toJson();
  const json* m = values(again, kDiscoveryTitle);
  ASSERT_NE(m, nullptr);
  EXPECT_NE((*m)["message"].get<std::string>().find("no such model"), std::string::npos);
}
