// The fleet against inputs another program or a careless colleague made (hostile input, round
// three): a store whose schema was changed, a second writer through a hard link, values no
// analysis writes, a Slurm task result naming ids of no chunk, a scheduler that fails, links
// planted at the Slurm folder, and manifests naming files outside their folder.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

#include "core/fleet/manifest.h"
#include "core/fleet/store.h"
#include "core/fleet/work.h"

namespace flexarm {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const auto dir = fs::temp_directory_path() / ("flexarm_fleet_hostile_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto p = dir / name;
  fs::remove_all(p);
  for (const char* tail : {"-wal", "-shm", ".writer"}) fs::remove(p.string() + tail);
  return p;
}

std::string sha(char c) { return std::string(64, c); }

StoredLog goodLog(char c, double day) {
  StoredLog l;
  l.robot = "R01";
  l.axis = 1;
  l.day = 20513.25 + day;
  l.time = "2026-03-01T06:00:00Z";
  l.path = std::string("R01/") + c + ".csv";
  l.result.sha256 = sha(c);
  l.result.referenceSha256 = sha('0');
  l.result.ok = true;
  l.result.message = "fine";
  l.result.estimates = {{"k_T", 0.5, 0.01, 0.5}, {"J_a", 1.7, 0.02, 1.7}, {"f_m", 0.036, 0.001, 0.036}};
  return l;
}

// A store FlexArm wrote (one log), changed afterwards by SQL run outside FlexArm.
std::string storeChangedBy(const std::string& name, const std::string& sql) {
  const auto path = scratch(name).string();
  std::string why;
  {
    auto store = FleetStore::open(path, true, &why);
    EXPECT_TRUE(store) << why;
    if (store) {
      EXPECT_TRUE(store->putLogs({goodLog('a', 0)}, 1, &why)) << why;
    }
  }
  sqlite3* raw = nullptr;
  EXPECT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  char* msg = nullptr;
  EXPECT_EQ(sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, &msg), SQLITE_OK) << (msg ? msg : "");
  sqlite3_free(msg);
  sqlite3_close(raw);
  return path;
}

TEST(FleetHostile, AStoreWhoseSchemaAnotherProgramChangedIsRefusedBeforeUse) {
  struct Case {
    const char* name;
    const char* sql;
    const char* says;
  };
  for (const Case& c : {Case{"view.sqlite",
                             "DROP TABLE estimates; CREATE VIEW estimates AS SELECT sha256, reference_sha256, "
                             "'k_T' AS parameter, 1.0 AS value, 1.0 AS std, 1.0 AS reference, 0 AS position FROM logs",
                             "view 'estimates'"},
                        Case{"columns.sqlite",
                             "DROP TABLE estimates; CREATE TABLE estimates(sha256 TEXT, value REAL)",
                             "table 'estimates' has other columns"},
                        Case{"trigger.sqlite",
                             "CREATE TRIGGER wipe AFTER INSERT ON logs BEGIN DELETE FROM logs; END",
                             "trigger 'wipe'"},
                        Case{"extra.sqlite", "CREATE TABLE notes(x)", "table 'notes'"}}) {
    const auto path = storeChangedBy(c.name, c.sql);
    for (bool writable : {false, true}) {
      std::string why;
      EXPECT_FALSE(FleetStore::open(path, writable, &why)) << c.name;
      EXPECT_NE(why.find(c.says), std::string::npos) << why;
      EXPECT_NE(why.find("not a FlexArm fleet store as FlexArm wrote it"), std::string::npos) << why;
    }
  }
}

TEST(FleetHostile, ASecondWriterThroughAHardLinkIsRefused) {
  const auto path = scratch("linked.sqlite");
  const auto other = scratch("other-name.sqlite");
  std::string why;
  auto writer = FleetStore::open(path.string(), true, &why);
  ASSERT_TRUE(writer) << why;
  fs::create_hard_link(path, other);
  std::string second;
  EXPECT_FALSE(FleetStore::open(other.string(), true, &second));
  EXPECT_NE(second.find("under another name (a link to the same file)"), std::string::npos) << second;
  writer.reset();
  EXPECT_TRUE(FleetStore::open(other.string(), true, &why)) << why;
}

TEST(FleetHostile, ValuesNoAnalysisWritesAreRefusedOnTheWayInAndFlaggedOnTheWayOut) {
  const auto path = scratch("values.sqlite").string();
  std::string why;
  auto store = FleetStore::open(path, true, &why);
  ASSERT_TRUE(store) << why;
  StoredLog huge = goodLog('b', 1);
  huge.result.estimates[0].value = 1e308;
  EXPECT_FALSE(store->putLogs({huge}, 1, &why));
  EXPECT_NE(why.find("the estimate of k_T (1e+308) is not a finite value"), std::string::npos) << why;
  StoredLog negative = goodLog('c', 2);
  negative.result.estimates[2].std = -1.0;
  EXPECT_FALSE(store->putLogs({negative}, 1, &why));
  EXPECT_NE(why.find("the std of f_m (-1) is not a positive finite number"), std::string::npos) << why;
  StoredLog badSha = goodLog('d', 3);
  badSha.result.sha256 = "../../etc/passwd";
  EXPECT_FALSE(store->putLogs({badSha}, 1, &why));
  EXPECT_EQ(store->logCount(), 0u);  // the batch is refused whole
  ASSERT_TRUE(store->putLogs({goodLog('a', 0), goodLog('e', 4)}, 1, &why)) << why;
  store.reset();

  // Another program makes a faulty axis look healthy: std -1, a value of 1e308.
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw,
                         ("UPDATE estimates SET std = -1 WHERE sha256 = '" + sha('a') +
                          "' AND parameter = 'k_T'; UPDATE estimates SET value = 1e308 WHERE sha256 = '" + sha('e') +
                          "' AND parameter = 'J_a'")
                             .c_str(),
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(raw);
  auto reader = FleetStore::open(path, false, &why);
  ASSERT_TRUE(reader) << why;
  const auto logs = reader->logs();
  ASSERT_EQ(logs.size(), 2u);
  for (const auto& l : logs) {
    EXPECT_FALSE(l.result.ok) << l.path;
    EXPECT_NE(l.result.message.find("not one FlexArm wrote"), std::string::npos) << l.result.message;
  }
}

TEST(FleetHostile, AWriterThatDidNotCloseLeavesAMarkAndTheNextOneChecksTheFile) {
  const auto path = scratch("unclean.sqlite").string();
  std::string why;
  {
    auto store = FleetStore::open(path, true, &why);
    ASSERT_TRUE(store) << why;
    ASSERT_TRUE(store->putLogs({goodLog('a', 0), goodLog('b', 1), goodLog('c', 2)}, 1, &why)) << why;
  }
  {
    auto reader = FleetStore::open(path, false, &why);
    ASSERT_TRUE(reader) << why;
    EXPECT_EQ(reader->meta("writer_open").value_or(""), "0");  // closed cleanly
  }
  // A writer killed in its run leaves writer_open at 1; a damaged page is found before use.
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw, "UPDATE meta SET value = '1' WHERE key = 'writer_open'", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(raw);
  {
    auto writer = FleetStore::open(path, true, &why);
    ASSERT_TRUE(writer) << why;  // intact: the check passes
  }
  ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw,
                         "PRAGMA journal_mode=DELETE; UPDATE meta SET value = '1' WHERE key = 'writer_open';"
                         "PRAGMA writable_schema=ON;"
                         "UPDATE sqlite_master SET sql = replace(sql, 'robot, axis, day', 'robot, day, axis') "
                         "WHERE name = 'logs_axis'",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(raw);
  std::string damaged;
  EXPECT_FALSE(FleetStore::open(path, true, &damaged));
  EXPECT_NE(damaged.find("the store is damaged (SQLite's integrity check:"), std::string::npos) << damaged;
}

// --- the Slurm path, with stand-ins for sbatch and squeue ---------------------------------------

std::string script(const fs::path& dir, const std::string& name, const std::string& body) {
  const auto p = dir / name;
  std::ofstream(p) << "#!/bin/sh\n" << body;
  fs::permissions(p, fs::perms::owner_all);
  return p.string();
}

struct Collected {
  std::vector<std::size_t> delivered;
  std::vector<std::pair<std::size_t, std::string>> lost;
};

fleet::Sinks sinksInto(Collected& c) {
  fleet::Sinks s;
  s.reference = [](const fleet::ReferenceOutcome&) { return true; };
  s.log = [&c](std::size_t id, FleetLogResult) {
    c.delivered.push_back(id);
    return true;
  };
  s.lost = [&c](std::size_t id, bool, const std::string& why) { c.lost.push_back({id, why}); };
  return s;
}

fleet::WorkChunk twoLogs() {
  fleet::WorkChunk w;
  w.logs = {{0, "a.csv", sha('0')}, {1, "b.csv", sha('0')}};
  w.references[sha('0')] = "{}";
  return w;
}

TEST(FleetHostile, ATaskResultIsCheckedBeforeItIsMergedAndTheGoodPartKept) {
  const auto dir = scratch("slurm_result");
  fs::create_directories(dir);
  // The task's result: an id of no chunk (999999), one log with std -1, one good log.
  nlohmann::json good = fleetLogResultJson(goodLog('a', 0).result), bad = good, stray = good;
  good["id"] = 1;
  bad["id"] = 0;
  bad["estimates"][0]["std"] = -1.0;
  stray["id"] = 999999;
  const nlohmann::json result = {{"format", "flexarm-fleet-result"}, {"version", 1}, {"fits", nlohmann::json::array()},
                                 {"logs", {stray, bad, good, nlohmann::json("not an object")}}};
  std::ofstream(dir / "prepared.json") << result.dump();
  SlurmOptions o;
  o.executable = "flexarm";
  o.sbatch = script(dir, "sbatch", "for last; do :; done\ncp " + (dir / "prepared.json").string() +
                                       " \"$(dirname \"$last\")/result-0.json\"\necho 42\n");
  o.squeue = script(dir, "squeue", "exit 0\n");
  o.scancel = script(dir, "scancel", "exit 0\n");
  o.pollS = 0.05;
  Collected c;
  std::string why;
  ASSERT_TRUE(fleet::runOnSlurm(twoLogs(), o, (dir / "base/run-1/logs").string(), sinksInto(c), &why)) << why;
  EXPECT_EQ(c.delivered, std::vector<std::size_t>{1});
  ASSERT_EQ(c.lost.size(), 1u);
  EXPECT_EQ(c.lost[0].first, 0u);
  EXPECT_NE(c.lost[0].second.find("result for it is invalid: the std of k_T (-1)"), std::string::npos)
      << c.lost[0].second;
  struct stat st {};
  ASSERT_EQ(::stat((dir / "base/run-1/logs").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
}

TEST(FleetHostile, AFailingSchedulerEndsTheWaitWithItsOwnWords) {
  const auto dir = scratch("slurm_down");
  fs::create_directories(dir);
  SlurmOptions o;
  o.executable = "flexarm";
  o.sbatch = script(dir, "sbatch", "echo 43\n");
  o.squeue = script(dir, "squeue",
                    "echo 'slurm_load_jobs error: Unable to contact slurm controller (connect failure)' >&2\nexit 1\n");
  o.scancel = script(dir, "scancel", "exit 0\n");
  o.pollS = 0.05;
  o.timeoutS = 3600.0;
  Collected c;
  std::string why;
  const auto begin = std::chrono::steady_clock::now();
  EXPECT_FALSE(fleet::runOnSlurm(twoLogs(), o, (dir / "base/run-1/logs").string(), sinksInto(c), &why));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(), 60.0);
  EXPECT_NE(why.find("Unable to contact slurm controller"), std::string::npos) << why;
  EXPECT_EQ(c.lost.size(), 2u);  // every log reported, none silently dropped
}

TEST(FleetHostile, TheSlurmFolderIsMadeByFlexArmAndNoLinkIsFollowed) {
  const auto dir = scratch("slurm_links");
  fs::create_directories(dir / "victim");
  SlurmOptions o;
  o.executable = "flexarm";
  o.sbatch = script(dir, "sbatch", "echo 44\n");
  o.squeue = script(dir, "squeue", "exit 0\n");
  fs::create_directory_symlink(dir / "victim", dir / "store.sqlite.slurm");
  Collected c;
  std::string why;
  EXPECT_FALSE(fleet::runOnSlurm(twoLogs(), o, (dir / "store.sqlite.slurm/run-1/logs").string(), sinksInto(c), &why));
  EXPECT_NE(why.find("is a symbolic link; FlexArm makes this folder itself"), std::string::npos) << why;
  EXPECT_TRUE(fs::is_empty(dir / "victim"));
  // A line break in the folder's name would put directives into job.sh.
  EXPECT_FALSE(fleet::runOnSlurm(twoLogs(), o, (dir / "x\n#SBATCH --uid=0/run-1/logs").string(), sinksInto(c), &why));
  EXPECT_NE(why.find("line break"), std::string::npos) << why;
  SlurmOptions bad = o;
  bad.workDir = "/tmp/x\n#SBATCH --uid=0";
  EXPECT_FALSE(bad.isValid(&why));
  EXPECT_NE(why.find("--slurm-dir holds a line break"), std::string::npos) << why;
}

// --- manifests ---------------------------------------------------------------------------------

TEST(FleetHostile, AManifestNamesOnlyLogsInsideItsFolderUnlessAllowed) {
  const auto dir = scratch("manifest_folder");
  fs::create_directories(dir / "plant");
  fs::create_symlink("/etc/passwd", dir / "plant/linked.csv");
  const std::string head = "# flexarm-fleet: 1\nrobot,axis,time,log\n";
  const std::string manifest = (dir / "plant/fleet.csv").string();
  for (const std::string log : {"/etc/passwd", "../../etc/passwd", "linked.csv", "../outside.csv"}) {
    ManifestError e;
    EXPECT_FALSE(parseFleetManifest(head + "R1,1,2026-03-01," + log + "\n", manifest, &e)) << log;
    EXPECT_EQ(e.line, 3);
    EXPECT_EQ(e.column, "log");
    EXPECT_NE(e.problem.find("lies outside the manifest's folder"), std::string::npos) << e.toString();
  }
  ManifestError e;
  EXPECT_TRUE(parseFleetManifest(head + "R1,1,2026-03-01,R1/a.csv\n", manifest, &e)) << e.toString();
  ManifestReadOptions anywhere;
  anywhere.allowLogsOutside = true;
  EXPECT_TRUE(parseFleetManifest(head + "R1,1,2026-03-01,/data/a.csv\n", manifest, &e, anywhere)) << e.toString();
}

TEST(FleetHostile, AManifestsEncodingAndSizeAreNamed) {
  const std::string body = "# flexarm-fleet: 1\nrobot,axis,time,log\nR1,1,2026-03-01,a.csv\n";
  ManifestError e;
  const auto bom = parseFleetManifest("\xef\xbb\xbf" + body, "fleet.csv", &e);
  ASSERT_TRUE(bom) << e.toString();
  EXPECT_EQ(bom->entries.size(), 1u);
  std::string utf16 = "\xff\xfe";
  for (char ch : body) utf16 += std::string{ch, '\0'};
  EXPECT_FALSE(parseFleetManifest(utf16, "fleet.csv", &e));
  EXPECT_NE(e.problem.find("is UTF-16 text"), std::string::npos) << e.toString();
  ManifestReadOptions small;
  small.maxRows = 2;
  std::string three = body + "R1,1,2026-03-02,b.csv\nR1,1,2026-03-03,c.csv\n";
  EXPECT_FALSE(parseFleetManifest(three, "fleet.csv", &e, small));
  EXPECT_EQ(e.line, 5);
  EXPECT_NE(e.problem.find("more than 2 rows"), std::string::npos) << e.toString();
  // Lenient fields are not accepted, and a long field is quoted short.
  for (const std::string row : {"R1,+1,2026-03-01,a.csv", "R1, 1x,2026-03-01,a.csv", "R1,0x1,2026-03-01,a.csv"}) {
    EXPECT_FALSE(parseFleetManifest("# flexarm-fleet: 1\nrobot,axis,time,log\n" + row + "\n", "fleet.csv", &e)) << row;
    EXPECT_EQ(e.column, "axis") << row;
  }
  // Found by fuzz_manifest: a robot "#R07" reads, but its row written back is a comment.
  EXPECT_FALSE(parseFleetManifest("# flexarm-fleet: 1\nlog,time,axis,robot\nb.csv,2026-03-05T06:00,2,#R07\n", "fleet.csv", &e));
  EXPECT_EQ(e.column, "robot");
  EXPECT_FALSE(parseFleetManifest("# flexarm-fleet: 1\nrobot,axis,time,log,temperature_c\nR1,1,2026-03-01,a.csv,0x1p4\n",
                                  "fleet.csv", &e));
  EXPECT_EQ(e.column, "temperature_c");
  EXPECT_FALSE(parseFleetManifest("# flexarm-fleet: 1\nrobot,axis,time,log\nR1,1," + std::string(100000, '9') + ",a.csv\n",
                                  "fleet.csv", &e));
  EXPECT_LT(e.toString().size(), 300u) << e.toString().substr(0, 300);
}

}  // namespace
}  // namespace flexarm
