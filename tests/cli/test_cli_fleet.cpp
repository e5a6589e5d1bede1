// flexarm simulate --fleet and flexarm fleet, end to end: a simulated plant whose truth file
// says which axes wear, take a heavier load or lose torque constant, run through the store.
#include <gtest/gtest.h>

#include <chrono>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <thread>

#include "cli_test_support.h"
#include "core/fleet/manifest.h"
#include "core/fleet/store.h"
#include "tests/test_scale.h"

extern char** environ;

namespace flexarm {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::runFlexarm;

// The plant and a complete run of it are made once per build of flexarm and shared by the
// tests (each runs in a process of its own under ctest), under a lock.
struct Plant {
  fs::path dir, manifest, db;
  json truth, run;  // truth.json and the complete run's JSON
};

const Plant& plant() {
  static Plant p = [] {
    struct stat st {};
    ::stat(FLEXARM_EXE, &st);
    const bool reduced = test::reducedSizes();
    const fs::path root = fs::temp_directory_path() / ("flexarm_fleet_" + std::to_string(::getuid())) /
                          (std::to_string(st.st_mtime) + "-" + std::to_string(st.st_size) + (reduced ? "-r" : ""));
    fs::create_directories(root);
    Plant out;
    out.dir = root / "plant";
    out.manifest = out.dir / "manifest.csv";
    out.db = root / "full.sqlite";
    const int lock = ::open((root / "lock").c_str(), O_RDWR | O_CREAT, 0644);
    ::flock(lock, LOCK_EX);
    if (!fs::exists(root / "done")) {
      fs::remove_all(out.dir);
      for (const char* tail : {"", "-wal", "-shm", ".writer"}) fs::remove(out.db.string() + tail);
      // Three changed axes (wear, load, k_T fault) among 2 x 3 (reduced: 2 x 2), over 20 days
      // (16), the cell swinging +-10 degC.
      const auto sim = runFlexarm({"simulate", "--fleet", out.dir.string(), "--robots", "2", "--axes",
                                   reduced ? "2" : "3", "--days", reduced ? "16" : "20", "--seed", "11", "--json"});
      EXPECT_EQ(sim.code, 0) << sim.err;
      const auto run = runFlexarm({"fleet", out.manifest.string(), "--db", out.db.string(), "--json"});
      EXPECT_EQ(run.code, 0) << run.err;
      std::ofstream(root / "run.json") << run.out;
      if (sim.code == 0 && run.code == 0) std::ofstream(root / "done") << "1\n";
    }
    ::flock(lock, LOCK_UN);
    ::close(lock);
    out.truth = json::parse(test::readAll((out.dir / "truth.json").string()));
    out.run = json::parse(test::readAll((root / "run.json").string()));
    return out;
  }();
  return p;
}

fs::path fresh(const std::string& name) {
  const auto p = test::scratchDir() / name;
  for (const char* tail : {"", "-wal", "-shm", ".writer"}) fs::remove(p.string() + tail);
  return p;
}

const json* axisOf(const json& run, const std::string& robot, int axis) {
  for (const auto& a : run.at("axes"))
    if (a.at("robot") == robot && a.at("axis") == axis) return &a;
  return nullptr;
}

// Every stored log's identity and results (not the seconds they took).
std::vector<std::string> storeContent(const fs::path& db) {
  std::string why;
  auto store = FleetStore::open(db.string(), false, &why);
  EXPECT_TRUE(store) << why;
  std::vector<std::string> rows;
  if (!store) return rows;
  for (const auto& l : store->logs()) {
    json e = json::array();
    for (const auto& x : l.result.estimates) e.push_back({x.name, x.value, x.std, x.reference});
    rows.push_back(json{l.result.sha256, l.result.referenceSha256, l.robot, l.axis, l.time, l.path, l.result.ok,
                        l.result.message, l.result.verdict,
                        l.result.verdictTimeS ? json(*l.result.verdictTimeS) : json(nullptr), e}
                       .dump());
  }
  for (const auto& a : store->axes()) rows.push_back(a.robot + std::to_string(a.axis) + a.referenceSha256 + a.referenceJson);
  return rows;
}

TEST(CliFleet, NamesTheChangedAxesWithTheirParameterAndNoHealthyOne) {
  const Plant& p = plant();
  const json& run = p.run;
  const int logs = p.truth.at("robots").get<int>() * p.truth.at("axes_per_robot").get<int>() * p.truth.at("days").get<int>();
  EXPECT_EQ(run.at("analysed"), logs);
  EXPECT_EQ(run.at("failed"), 0);
  int changed = 0;
  for (const auto& t : p.truth.at("axes")) {
    const auto* a = axisOf(run, t.at("robot"), t.at("axis"));
    ASSERT_NE(a, nullptr) << t.dump();
    const std::string scenario = t.at("scenario");
    SCOPED_TRACE(t.dump() + "\n" + a->dump(2));
    if (scenario == "healthy") {
      EXPECT_EQ(a->at("status"), "healthy");
      continue;
    }
    ++changed;
    EXPECT_EQ(a->at("status"), scenario == "wear" ? "drift" : "fault");
    EXPECT_EQ(a->at("parameter"), t.at("parameter"));
    const double start = *parseIsoDay(t.at("start").get<std::string>());
    const double since = *parseIsoDay(a->at("since").get<std::string>());
    // A step is dated by its first faulty log (the change falls between two daily logs).
    EXPECT_NEAR(since, start, scenario == "wear" ? 3.0 : 1.0);
  }
  EXPECT_EQ(changed, 3);
  // The temperature moved f_m by far more than the scatter: alpha was estimated on each axis.
  for (const auto& a : run.at("axes")) EXPECT_FALSE(a.at("trend").at("temperature").at("alpha_per_degc").is_null());
}

TEST(CliFleet, NamesEachChangeWithinAFewDays) {
  const Plant& p = plant();
  ManifestError e;
  const auto manifest = readFleetManifest(p.manifest.string(), &e);
  ASSERT_TRUE(manifest) << e.toString();
  for (const auto& t : p.truth.at("axes")) {
    const std::string scenario = t.at("scenario");
    if (scenario == "healthy") continue;
    // The axis' logs up to a few days after its change began: 3 days for a step, 6 for wear.
    const double start = *parseIsoDay(t.at("start").get<std::string>());
    const double until = start + (scenario == "wear" ? 6.0 : 3.0);
    std::vector<FleetEntry> entries;
    for (const auto& x : manifest->entries)
      if (x.robot == t.at("robot") && x.axis == t.at("axis") && x.day <= until) {
        entries.push_back(x);
        entries.back().log = x.path;
      }
    const auto m = fresh("early-" + scenario + ".csv");
    std::ofstream(m) << fleetManifestText(entries);
    // The logs stay in the plant's folder, this manifest elsewhere: --allow-logs-outside.
    const auto r = runFlexarm({"fleet", m.string(), "--allow-logs-outside", "--db",
                               fresh("early-" + scenario + ".sqlite").string(), "--json"});
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = json::parse(r.out);
    ASSERT_EQ(j.at("axes").size(), 1u);
    const auto& a = j.at("axes")[0];
    EXPECT_NE(a.at("status"), "healthy") << scenario << ": " << a.dump(2);
    EXPECT_EQ(a.at("parameter"), t.at("parameter")) << a.dump(2);
  }
}

TEST(CliFleet, RerunAddsNothingAndWritesTheReport) {
  const Plant& p = plant();
  const auto before = storeContent(p.db);
  const auto html = test::scratchDir() / "fleet.html";
  std::vector<std::string> args = {"fleet", p.manifest.string(), "--db", p.db.string(), "--json"};
  if (FLEXARM_GUI_BUILD) args.insert(args.end(), {"--report", html.string()});
  const auto r = runFlexarm(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("analysed"), 0);
  EXPECT_EQ(j.at("skipped"), p.run.at("analysed"));
  EXPECT_EQ(j.at("references_fitted"), 0);
  EXPECT_EQ(storeContent(p.db), before);
  for (std::size_t i = 0; i < j.at("axes").size(); ++i)
    EXPECT_EQ(j.at("axes")[i].at("status"), p.run.at("axes")[i].at("status"));
  if (FLEXARM_GUI_BUILD) {
    const std::string text = test::readAll(html.string());
    EXPECT_NE(text.find("Maintenance at the next stop"), std::string::npos);
    for (const auto& a : j.at("axes")) {
      if (a.at("status") == "healthy") continue;
      EXPECT_NE(text.find(a.at("robot").get<std::string>() + " axis " + std::to_string(a.at("axis").get<int>()) +
                          ": " + a.at("status").get<std::string>()),
                std::string::npos);
    }
  }
}

TEST(CliFleet, AKilledRunLosesNothingCommittedAndResumes) {
  const Plant& p = plant();
  const auto db = fresh("killed.sqlite");
  std::vector<std::string> args = {FLEXARM_EXE, "fleet", p.manifest.string(), "--db", db.string(), "--jobs", "1"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, FLEXARM_EXE, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Read the store while the run writes it; kill the run once a batch (16 logs) is in.
  std::size_t seen = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(600);
  while (std::chrono::steady_clock::now() < deadline) {
    std::string why;
    if (auto reader = FleetStore::open(db.string(), false, &why)) seen = reader->logCount();
    if (seen >= 16) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before it could be killed";
  const int total = p.run.at("analysed");
  std::string why;
  std::size_t committed = 0;
  {
    auto store = FleetStore::open(db.string(), false, &why);
    ASSERT_TRUE(store) << why;
    committed = store->logCount();
  }
  EXPECT_GE(committed, 16u);
  EXPECT_LT(committed, static_cast<std::size_t>(total));
  const auto r = runFlexarm({"fleet", p.manifest.string(), "--db", db.string(), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("skipped"), committed);
  EXPECT_EQ(j.at("analysed"), total - static_cast<int>(committed));
  EXPECT_EQ(storeContent(db), storeContent(p.db));
}

TEST(CliFleet, ABadLogIsReportedAndTheRestGoesOn) {
  const Plant& p = plant();
  const auto dir = test::scratchDir() / "badfleet";
  fs::create_directories(dir);
  // Two more days for the first axis: one log spoiled on its 100th line, one missing.
  ManifestError e;
  auto manifest = readFleetManifest(p.manifest.string(), &e);
  ASSERT_TRUE(manifest) << e.toString();
  std::vector<FleetEntry> entries = manifest->entries;
  for (auto& x : entries) x.log = x.path;
  FleetEntry bad = manifest->entries.front(), missing = bad;
  bad.reference = missing.reference = false;
  bad.day += 40;
  bad.time = isoFromDay(bad.day);
  bad.log = (dir / "spoiled.csv").string();
  missing.day += 41;
  missing.time = isoFromDay(missing.day);
  missing.log = (dir / "absent.csv").string();
  fs::remove(missing.log);
  {
    std::ifstream in(manifest->entries.front().path);
    std::ofstream out(bad.log);
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) out << (n == 100 ? "0.1,abc,0,0" : line) << "\n";
  }
  entries.push_back(bad);
  entries.push_back(missing);
  const auto m = dir / "manifest.csv";
  std::ofstream(m) << fleetManifestText(entries);
  const auto db = fresh("bad.sqlite");
  fs::copy_file(p.db, db);
  const auto r = runFlexarm({"fleet", m.string(), "--allow-logs-outside", "--db", db.string(), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("analysed"), 0);
  EXPECT_EQ(j.at("skipped"), p.run.at("analysed"));
  ASSERT_EQ(j.at("failed"), 2) << j.at("failures").dump(2);
  const std::string first = j.at("failures")[0].at("message"), second = j.at("failures")[1].at("message");
  const std::string both = first + "\n" + second;
  EXPECT_NE(both.find("spoiled.csv:100"), std::string::npos) << both;
  EXPECT_NE(both.find("'abc'"), std::string::npos) << both;
  EXPECT_NE(both.find("absent.csv"), std::string::npos) << both;
  // The axis' trend went on without them.
  const auto* a = axisOf(j, entries.front().robot, entries.front().axis);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->at("logs"), p.truth.at("days"));
  // Again: the spoiled bytes are known (skipped), the missing file is reported again.
  const auto again = json::parse(runFlexarm({"fleet", m.string(), "--allow-logs-outside", "--db", db.string(), "--json"}).out);
  EXPECT_EQ(again.at("failed"), 1);
  EXPECT_EQ(again.at("skipped"), p.run.at("analysed").get<int>() + 1);
  // Another model's analyses are not mixed into the store.
  const auto other = runFlexarm({"fleet", m.string(), "--allow-logs-outside", "--db", db.string(), "--model", "two-mass"});
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.err.find("holds three-mass analyses"), std::string::npos) << other.err;
  // A manifest that cannot be read ends the run before anything is written.
  std::ofstream(dir / "broken.csv") << "# flexarm-fleet: 1\nrobot,axis,time,log\nR01,1,yesterday,a.csv\n";
  const auto broken = runFlexarm({"fleet", (dir / "broken.csv").string(), "--db", db.string()});
  EXPECT_EQ(broken.code, 3);
  EXPECT_NE(broken.err.find("broken.csv:3: column time: 'yesterday'"), std::string::npos) << broken.err;
}

// Runs under the ctest fixture that starts a one-node Slurm (tests/cli/slurm_fixture.sh),
// which sets SLURM_CONF; elsewhere it is skipped.
TEST(CliFleetSlurm, GivesTheSameStoreAsLocal) {
  if (!std::getenv("SLURM_CONF")) GTEST_SKIP() << "no Slurm (run by the ctest test cli.fleet_slurm)";
  const Plant& p = plant();
  const auto db = fresh("slurm.sqlite");
  const auto r = runFlexarm({"fleet", p.manifest.string(), "--db", db.string(), "--engine", "slurm",
                             "--logs-per-task", "16", "--slurm-timeout", "600", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("engine"), "slurm");
  EXPECT_EQ(j.at("analysed"), p.run.at("analysed"));
  EXPECT_EQ(storeContent(db), storeContent(p.db));
  for (std::size_t i = 0; i < j.at("axes").size(); ++i) {
    EXPECT_EQ(j.at("axes")[i].at("status"), p.run.at("axes")[i].at("status"));
    EXPECT_EQ(j.at("axes")[i].at("evidence"), p.run.at("axes")[i].at("evidence"));
  }
}

}  // namespace
}  // namespace flexarm
