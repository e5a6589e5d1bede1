// Sessions: format round trip, refusal of damaged and newer files, atomic save under a write
// that fails or crashes half-way, replay of the sample session and its reproducibility.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/io/log_io.h"
#include "core/session/model_json.h"
#include "core/session/replay.h"
#include "core/session/session.h"
#include "core/session/sha256.h"
#include "core/signal/preprocess.h"

namespace fs = std::filesystem;
using namespace flexarm;

namespace {

const std::string kSample = std::string(FLEXARM_SAMPLE_DIR) + "/sample_session.json";
const std::string kChirp = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const std::string kMultisine =
    std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_validation_multisine.csv";

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch() {
  auto p = fs::temp_directory_path() / ("flexarm_session_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

Session sampleSession() {
  auto r = loadSession(kSample);
  EXPECT_TRUE(r.ok) << r.message;
  return r.session;
}

const nlohmann::json* sectionValues(const nlohmann::json& report, const std::string& title) {
  for (const auto& s : report["sections"])
    if (s["title"] == title) return &s["values"];
  return nullptr;
}

}  // namespace

TEST(Sha256, KnownDigestsOfFips180Examples) {
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Session, SampleSessionChecksumsMatchItsLogs) {
  Session s = sampleSession();
  // The chirp analysed, the torque-ripple log for discovery, the log diagnosed and its
  // fault-free reference.
  ASSERT_EQ(s.logs.size(), 4u);
  std::string why;
  EXPECT_EQ(sha256OfFile(kChirp, &why).value_or(why), s.logs[0].sha256);
  const char* others[] = {"effect_torque_ripple.csv", "diagnosis_step_k_T.csv", "diagnosis_no_fault.csv"};
  for (std::size_t i = 1; i < 4; ++i)
    EXPECT_EQ(sha256OfFile(std::string(FLEXARM_SAMPLE_DIR) + "/" + others[i - 1], &why).value_or(why),
              s.logs[i].sha256) << others[i - 1];
  EXPECT_TRUE(s.preprocessed);
  EXPECT_TRUE(s.preprocess.differentiateAngle);
  EXPECT_EQ(s.preprocess.decimation.factor, 10);
  EXPECT_EQ(s.preprocess.detrend, Detrend::Mean);
}

TEST(Session, TextRoundTripKeepsEveryField) {
  Session s = sampleSession();
  s.preprocess.range = SampleRange{100, 30000};
  s.logs[0].read.format = LogFormat::Table;
  s.logs[0].read.inputColumn = 3;
  s.logs[0].read.sampleTime = 0.0005;
  s.validation.reset();
  const std::string text = toJsonText(s);
  auto back = parseSession(text);
  ASSERT_TRUE(back.ok) << back.message;
  EXPECT_EQ(toJsonText(back.session), text);
  EXPECT_EQ(back.session.logs[0].read.format, LogFormat::Table);
  EXPECT_EQ(back.session.logs[0].read.inputColumn, 3);
  ASSERT_TRUE(back.session.preprocess.range);
  EXPECT_EQ(back.session.preprocess.range->end, 30000u);
  EXPECT_FALSE(back.session.validation);
  ASSERT_TRUE(back.session.estimation);
  EXPECT_EQ(*back.session.estimation, (SecondsRange{0.5, 12.0}));
}

TEST(Session, ModelJsonRoundTripKeepsValuesFreeFlagsAndEffects) {
  auto m = makeModel("three-mass");
  m->setParameter("k_g", 1.234e5);
  m->setFree("J_m", false);
  std::vector<Effect> fx = {Effect::withDefaults(EffectKind::Backlash)};
  fx[0].values[0] = 3e-4;
  std::string why;
  auto back = modelFromJson(modelToJson("arm", *m, fx), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->name, "arm");
  EXPECT_EQ(back->model->value("k_g"), 1.234e5);
  EXPECT_FALSE(back->model->parameters()[back->model->indexOf("J_m")].free);
  ASSERT_EQ(back->effects.size(), 1u);
  EXPECT_EQ(back->effects[0].kind, EffectKind::Backlash);
  EXPECT_EQ(back->effects[0].values[0], 3e-4);
}

TEST(Session, DamagedFilesAreRefusedWithThePlace) {
  const std::string text = toJsonText(sampleSession());
  auto cut = parseSession(text.substr(0, text.size() / 2));
  EXPECT_FALSE(cut.ok);
  EXPECT_NE(cut.message.find("damaged"), std::string::npos) << cut.message;
  EXPECT_NE(cut.message.find("line"), std::string::npos) << cut.message;

  auto j = nlohmann::json::parse(text);
  j["ranges"]["estimation_s"] = nlohmann::json::array({5.0, 1.0});
  auto backwards = parseSession(j.dump());
  EXPECT_FALSE(backwards.ok);
  EXPECT_NE(backwards.message.find("ranges.estimation_s"), std::string::npos) << backwards.message;

  j = nlohmann::json::parse(text);
  j["parts"]["models"][0]["parameters"][0]["value"] = -1.0;  // J_m below its bound
  auto bad = parseSession(j.dump());
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.message.find("J_m"), std::string::npos) << bad.message;

  j = nlohmann::json::parse(text);
  j["parts"]["hologram"] = nlohmann::json::object();
  auto unknown = parseSession(j.dump());
  EXPECT_FALSE(unknown.ok);
  EXPECT_NE(unknown.message.find("hologram"), std::string::npos) << unknown.message;

  j = nlohmann::json::parse(text);
  j["logs"][0].erase("sha256");
  auto noSum = parseSession(j.dump());
  EXPECT_FALSE(noSum.ok);
  EXPECT_NE(noSum.message.find("sha256"), std::string::npos) << noSum.message;

  EXPECT_FALSE(parseSession("{\"hello\": 1}").ok);

  // A number beyond a double (found by fuzz_session) is a refusal, not an exception.
  SessionParseResult huge;
  ASSERT_NO_THROW(huge = parseSession("{\"format\": 2e66666666662666666666666}"));
  EXPECT_FALSE(huge.ok);
  EXPECT_NE(huge.message.find("too large"), std::string::npos) << huge.message;
  // A writer that is no text (found by fuzz_session) does not stop the version message.
  SessionParseResult odd;
  ASSERT_NO_THROW(odd = parseSession(
                      "{\"format\": \"flexarm-session\", \"version\": 99, \"written_by\": {}}"));
  EXPECT_FALSE(odd.ok);
  EXPECT_NE(odd.message.find("99"), std::string::npos) << odd.message;
}

TEST(Session, NewerVersionIsRefusedNamingBothVersions) {
  auto j = nlohmann::json::parse(toJsonText(sampleSession()));
  j["version"] = kSessionVersion + 1;
  j["written_by"] = "FlexArm 9.0";
  auto r = parseSession(j.dump());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("FlexArm 9.0"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("format " + std::to_string(kSessionVersion + 1)), std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("newer"), std::string::npos) << r.message;
}

// A save whose write fails half-way (file size limit) and one whose process dies half-way
// (SIGXFSZ kills it, as a crash would) both leave the previous session file untouched.
TEST(Session, WriteFailingOrCrashingMidSaveKeepsTheOldFile) {
  const auto dir = scratch();
  const std::string path = (dir / "kept.json").string();
  Session small = sampleSession();
  std::string why;
  ASSERT_TRUE(saveSession(small, path, &why)) << why;
  const std::string before = readText(path);
  Session big = small;
  big.parts["view"] = {{"padding", std::string(200000, 'x')}};
  ASSERT_GT(toJsonText(big).size(), 100000u);

  for (bool crash : {false, true}) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      if (!crash) std::signal(SIGXFSZ, SIG_IGN);  // the write then fails with EFBIG
      rlimit limit{50000, 50000};
      setrlimit(RLIMIT_FSIZE, &limit);
      std::string childWhy;
      const bool ok = saveSession(big, path, &childWhy);
      _exit(ok ? 0 : 7);
    }
    int status = 0;
    waitpid(child, &status, 0);
    if (crash) {
      ASSERT_TRUE(WIFSIGNALED(status));
      EXPECT_EQ(WTERMSIG(status), SIGXFSZ);
    } else {
      ASSERT_TRUE(WIFEXITED(status));
      EXPECT_EQ(WEXITSTATUS(status), 7) << "the failed write must be reported";
    }
    EXPECT_EQ(readText(path), before);
    auto reread = loadSession(path);
    EXPECT_TRUE(reread.ok) << reread.message;
  }
  ASSERT_TRUE(saveSession(big, path, &why)) << why;  // without the limit it succeeds
  EXPECT_EQ(readText(path), toJsonText(big));
}

TEST(Replay, SampleSessionPreparesDataAsTheSeed) {
  Session s = sampleSession();
  ReplayResult r = replaySession(s, kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const nlohmann::json j = r.report.toJson();
  const auto* data = sectionValues(j, "Data");
  ASSERT_NE(data, nullptr);
  // The same steps by hand: differentiate, decimate by 10 (2 kHz -> 200 Hz), remove means.
  auto log = readLog(kChirp);
  ASSERT_TRUE(log.ok);
  PreprocessOptions p;
  p.differentiateAngle = true;
  p.decimation.factor = 10;
  p.detrend = Detrend::Mean;
  const IdData pre = preprocess(log.data, p);
  EXPECT_EQ((*data)["samples"].get<std::size_t>(), pre.samples());
  EXPECT_DOUBLE_EQ((*data)["rate_hz"].get<double>(), 200.0);
  EXPECT_EQ((*data)["ranges"]["estimation"]["samples"].get<std::size_t>(),
            pre.rangeForTimes(0.5, 12.0).size());
  EXPECT_EQ(r.report.logs.at(0).sha256, s.logs[0].sha256);
  EXPECT_TRUE(r.report.warnings.empty());
}

TEST(Replay, TrueThreeMassModelFitsBetterThanTheTwoMassModel) {
  ReplayResult r = replaySession(sampleSession(), kSample);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const nlohmann::json j = r.report.toJson();
  const auto* three = sectionValues(j, "Model three-mass");
  const auto* two = sectionValues(j, "Model two-mass");
  ASSERT_NE(three, nullptr);
  ASSERT_NE(two, nullptr);
  // The chirp log was simulated with the three-mass model (Table 5.7 p6) the session holds.
  EXPECT_GT((*three)["fit_percent_validation"].get<double>(), (*two)["fit_percent_validation"].get<double>());
  EXPECT_GT((*three)["fit_percent"].get<double>(), (*two)["fit_percent"].get<double>());
  EXPECT_EQ((*three)["parameters"]["J_m"].get<double>(), 0.000456);
  // Two lightly damped resonances of the three-mass model, one of the two-mass model.
  EXPECT_EQ((*three)["peaks_rad_s"].size(), 2u);
  EXPECT_EQ((*two)["peaks_rad_s"].size(), 1u);
}

TEST(Replay, SaveReopenGivesIdenticalResults) {
  const auto dir = scratch();
  const std::string path = (dir / "reopen.json").string();
  Session s = sampleSession();
  for (auto& l : s.logs) l.path = storedLogPath(path, std::string(FLEXARM_SAMPLE_DIR) + "/" + l.path);
  std::string why;
  ASSERT_TRUE(saveSession(s, path, &why)) << why;
  auto reopened = loadSession(path);
  ASSERT_TRUE(reopened.ok) << reopened.message;
  nlohmann::json a = replaySession(sampleSession(), kSample).report.toJson();
  nlohmann::json b = replaySession(reopened.session, path).report.toJson();
  a.erase("session");
  b.erase("session");
  // The logs' paths are as the session writes them; a fit names its experiments' logs so too.
  for (auto* j : {&a, &b}) {
    for (auto& l : (*j)["logs"]) l.erase("path");
    for (auto& section : (*j)["sections"])
      if (section["values"].contains("fit"))
        for (const char* list : {"fit_percent_experiments", "fit_percent_validation_experiments"})
          for (auto& e : section["values"]["fit"][list]) e.erase("log");
  }
  EXPECT_EQ(a.dump(), b.dump());
}

TEST(Replay, SubstitutedAndChangedLogsAreNamed) {
  Session s = sampleSession();
  ReplayOptions o;
  o.substitutes["estimation"] = kMultisine;
  ReplayResult sub = replaySession(s, kSample, o);
  ASSERT_EQ(sub.termination, Termination::Converged) << sub.message;
  EXPECT_EQ(sub.report.logs[0].note, "substituted");
  EXPECT_NE(sub.report.logs[0].sha256, s.logs[0].sha256);

  o.substitutes = {{"tomorrow", kMultisine}};
  ReplayResult unknown = replaySession(s, kSample, o);
  EXPECT_EQ(unknown.termination, Termination::Failed);
  EXPECT_TRUE(unknown.badInput);
  EXPECT_NE(unknown.message.find("tomorrow"), std::string::npos);

  s.logs[0].sha256 = std::string(64, '0');
  ReplayResult changed = replaySession(s, kSample);
  ASSERT_EQ(changed.termination, Termination::Converged);
  ASSERT_EQ(changed.report.warnings.size(), 1u);
  EXPECT_NE(changed.report.warnings[0].find("changed since the session was saved"), std::string::npos);

  s.logs[0].path = "no_such_log.csv";
  ReplayResult missing = replaySession(s, kSample);
  EXPECT_EQ(missing.termination, Termination::Failed);
  EXPECT_NE(missing.message.find("no_such_log.csv"), std::string::npos) << missing.message;
}

TEST(Session, ResamplingStepRoundTripsAndReplaysTheIrregularLog) {
  // The irregular sample log, read as recorded and put on a 2 kHz grid by the session.
  const fs::path dir = scratch() / "resampled";
  fs::create_directories(dir);
  fs::copy_file(std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_irregular_timing.csv", dir / "log.csv",
                fs::copy_options::overwrite_existing);
  Session s;
  LogReference ref;
  ref.name = "estimation";
  ref.path = "log.csv";
  ref.sha256 = sha256OfFile((dir / "log.csv").string(), nullptr).value_or("");
  ref.read.keepIrregularTime = true;
  s.logs.push_back(ref);
  s.preprocessed = true;
  UniformGridOptions u;
  u.rateHz = 2000;
  u.method = InterpolationMethod::Pchip;
  u.maxGapSeconds = 0.004;
  s.preprocess.resample = u;
  s.preprocess.decimation.factor = 10;
  const std::string text = toJsonText(s);
  auto back = parseSession(text);
  ASSERT_TRUE(back.ok) << back.message;
  EXPECT_EQ(toJsonText(back.session), text);
  ASSERT_TRUE(back.session.preprocess.resample);
  EXPECT_EQ(*back.session.preprocess.resample, u);
  EXPECT_TRUE(back.session.logs[0].read.keepIrregularTime);
  const auto steps = describePreprocessing(back.session.preprocess);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(steps[0], "resampling onto a uniform 2000 Hz grid (pchip for irregular time stamps, gaps up to 4 ms; "
                      "anti-alias FIR, 80 dB)");
  // Replayed, the log is read as recorded, resampled and decimated: 12000 -> 1200 samples.
  const std::string path = (dir / "session.json").string();
  std::string why;
  ASSERT_TRUE(saveSession(back.session, path, &why)) << why;
  const ReplayResult r = replaySession(back.session, path);
  ASSERT_EQ(r.termination, Termination::Converged) << r.message;
  const nlohmann::json report = r.report.toJson();
  const auto* data = sectionValues(report, "Data");
  ASSERT_NE(data, nullptr);
  EXPECT_EQ((*data)["samples"].get<std::size_t>(), 1200u);
  // Without keeping the irregular stamps, the log is refused as when opened.
  back.session.logs[0].read.keepIrregularTime = false;
  const ReplayResult refused = replaySession(back.session, path);
  EXPECT_EQ(refused.termination, Termination::Failed);
  EXPECT_NE(refused.message.find("does not increase"), std::string::npos) << refused.message;
}
