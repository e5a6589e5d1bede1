#include "core/fleet/store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace flexarm {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const auto dir = fs::temp_directory_path() / ("flexarm_store_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto p = dir / name;
  for (const char* tail : {"", "-wal", "-shm", ".writer"}) fs::remove(p.string() + tail);
  return p;
}

// Checksums as FlexArm writes them: 64 hex digits ("a" stands for aaaa...a).
std::string sha(const std::string& letter) { return std::string(64, letter[0]); }
const std::string kRef(64, '0');

StoredLog logOf(const std::string& letter, int day, double kT) {
  StoredLog l;
  l.robot = "R01";
  l.axis = 2;
  l.day = 20513.25 + day;
  l.time = "2026-03-0" + std::to_string(day + 1) + "T06:00:00Z";
  l.path = "R01/ax2/" + letter + ".csv";
  l.temperatureC = 20.0 + day;
  l.result.sha256 = sha(letter);
  l.result.referenceSha256 = kRef;
  l.result.ok = true;
  l.result.message = "fine";
  l.result.verdict = day > 1 ? "k_T" : "none";
  if (day > 1) l.result.verdictTimeS = 3.5;
  l.result.estimates = {{"k_T", kT, 0.01, 1.0}, {"J_a", 1.7, 0.02, 1.72}, {"f_m", 0.036, 0.001, 0.0355}};
  l.result.seconds = 0.05;
  return l;
}

TEST(FleetStore, IsVersionedInWalAndKeepsWhatItWasGiven) {
  const auto path = scratch("a.sqlite").string();
  std::string why;
  {
    auto store = FleetStore::open(path, true, &why);
    ASSERT_TRUE(store) << why;
    EXPECT_EQ(store->schemaVersion(), kFleetSchemaVersion);
    EXPECT_EQ(store->journalMode(), "wal");
    ASSERT_TRUE(store->putAxis({"R01", 2, kRef, "R01/ax2/ref.csv", 21.5, "{\"x\":1}"}, &why)) << why;
    const long run = store->beginRun("local", "m.csv", &why);
    ASSERT_GT(run, 0) << why;
    ASSERT_TRUE(store->putLogs({logOf("b", 1, 1.0), logOf("a", 0, 1.01)}, run, &why)) << why;
    // Stored again: left as it was.
    ASSERT_TRUE(store->putLogs({logOf("a", 0, 5.0)}, run, &why)) << why;
  }
  auto store = FleetStore::open(path, false, &why);
  ASSERT_TRUE(store) << why;
  const auto logs = store->logs("R01", 2, kRef);
  ASSERT_EQ(logs.size(), 2u);
  EXPECT_EQ(logs[0].result.sha256, sha("a"));  // by day
  EXPECT_EQ(logs[0].result.estimates[0].value, 1.01);
  EXPECT_EQ(logs[1].result.estimates.size(), 3u);
  EXPECT_EQ(logs[1].result.estimates[2].name, "f_m");
  EXPECT_FALSE(logs[0].result.verdictTimeS);
  EXPECT_EQ(logs[1].temperatureC.value_or(0), 21.0);
  EXPECT_EQ(store->axis("R01", 2)->referenceTemperatureC.value_or(0), 21.5);
  EXPECT_EQ(store->storedKeys().count({sha("b"), kRef}), 1u);
  EXPECT_TRUE(store->logs("R01", 1).empty());
}

// The verdicts a diagnosis gives are the verdicts a store keeps: detected (a change not
// isolated) beside none, model_mismatch and the parameters; anything else is refused.
TEST(FleetStore, KeepsEveryVerdictADiagnosisGives) {
  const auto path = scratch("verdicts.sqlite").string();
  std::string why;
  auto store = FleetStore::open(path, true, &why);
  ASSERT_TRUE(store) << why;
  ASSERT_TRUE(store->putAxis({"R01", 2, kRef, "R01/ax2/ref.csv", 21.5, "{}"}, &why)) << why;
  const long run = store->beginRun("local", "m.csv", &why);
  StoredLog detected = logOf("d", 2, 1.0);
  detected.result.verdict = "detected";
  StoredLog mismatch = logOf("e", 3, 1.0);
  mismatch.result.verdict = "model_mismatch";
  ASSERT_TRUE(store->putLogs({detected, mismatch}, run, &why)) << why;
  const auto logs = store->logs("R01", 2, kRef);
  ASSERT_EQ(logs.size(), 2u);
  EXPECT_EQ(logs[0].result.verdict, "detected");
  EXPECT_EQ(logs[1].result.verdict, "model_mismatch");
  StoredLog other = logOf("f", 4, 1.0);
  other.result.verdict = "fault";
  EXPECT_FALSE(store->putLogs({other}, run, &why));
  EXPECT_NE(why.find("not none, detected, model_mismatch"), std::string::npos) << why;
}

TEST(FleetStore, OneWriterAndReadersWhileItWrites) {
  const auto path = scratch("b.sqlite").string();
  std::string why;
  auto writer = FleetStore::open(path, true, &why);
  ASSERT_TRUE(writer) << why;
  std::string second;
  EXPECT_FALSE(FleetStore::open(path, true, &second));
  EXPECT_NE(second.find("another flexarm fleet is writing"), std::string::npos) << second;
  auto reader = FleetStore::open(path, false, &why);
  ASSERT_TRUE(reader) << why;
  EXPECT_EQ(reader->logCount(), 0u);
  ASSERT_TRUE(writer->putLogs({logOf("a", 0, 1.0)}, 1, &why)) << why;
  EXPECT_EQ(reader->logCount(), 1u);  // the committed batch, while the writer stays open
  // A reader in the middle of a read transaction keeps its snapshot while the writer commits.
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw, "BEGIN; SELECT count(*) FROM logs;", nullptr, nullptr, nullptr), SQLITE_OK);
  ASSERT_TRUE(writer->putLogs({logOf("b", 1, 1.0)}, 1, &why)) << why;  // not blocked by the reader
  EXPECT_EQ(reader->logCount(), 2u);
  sqlite3_exec(raw, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(raw);
  writer.reset();
  EXPECT_TRUE(FleetStore::open(path, true, &why)) << why;  // the lock went with the writer
}

TEST(FleetStore, RefusesOtherFilesAndOtherVersions) {
  std::string why;
  const auto text = scratch("c.sqlite").string();
  std::ofstream(text) << "time_s,motor_angle_rad\n0,0\n";
  EXPECT_FALSE(FleetStore::open(text, true, &why));
  EXPECT_NE(why.find("not a FlexArm fleet store"), std::string::npos) << why;

  const auto newer = scratch("d.sqlite").string();
  ASSERT_TRUE(FleetStore::open(newer, true, &why)) << why;
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(newer.c_str(), &raw), SQLITE_OK);
  sqlite3_exec(raw, "UPDATE meta SET value = '2' WHERE key = 'schema_version'", nullptr, nullptr, nullptr);
  sqlite3_close(raw);
  EXPECT_FALSE(FleetStore::open(newer, false, &why));
  EXPECT_NE(why.find("schema version 2, this FlexArm reads version 1"), std::string::npos) << why;
  EXPECT_FALSE(FleetStore::open(scratch("absent.sqlite").string(), false, &why));
  EXPECT_NE(why.find("no such store"), std::string::npos) << why;
}

}  // namespace
}  // namespace flexarm

namespace flexarm {
namespace {

TEST(FleetStore, KeepsAFilesChecksumOnlyWhileItsStampHolds) {
  const auto path = scratch("e.sqlite").string();
  std::string why;
  auto store = FleetStore::open(path, true, &why);
  ASSERT_TRUE(store) << why;
  const FleetStore::FileStamp stamp{1754844, 1780000000123456789LL, 42};
  EXPECT_FALSE(store->knownSha256("/logs/a.csv", stamp));
  ASSERT_TRUE(store->putSha256({{"/logs/a.csv", {stamp, "abc"}}}, &why)) << why;
  EXPECT_EQ(store->knownSha256("/logs/a.csv", stamp).value_or(""), "abc");
  for (FleetStore::FileStamp other : {FleetStore::FileStamp{1754845, stamp.mtimeNs, 42},
                                      FleetStore::FileStamp{stamp.size, stamp.mtimeNs + 1, 42},
                                      FleetStore::FileStamp{stamp.size, stamp.mtimeNs, 43}})
    EXPECT_FALSE(store->knownSha256("/logs/a.csv", other));
  EXPECT_FALSE(store->knownSha256("/logs/b.csv", stamp));
}

}  // namespace
}  // namespace flexarm
