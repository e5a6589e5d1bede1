// Hostile inputs, round three: the plant's store, its manifests, the cluster path and options
// outside what a diagnosis can use, end to end. Every run is held to a time and memory ceiling
// and traced (strace): a manifest row naming /etc/passwd is refused before the file is opened,
// and nothing outside the test's folder is written.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "hostile_support.h"

using flexarm::test::confined;
using flexarm::test::expectConfined;
using flexarm::test::joined;
using flexarm::test::MeasuredRun;
using flexarm::test::runFlexarm;
namespace fs = std::filesystem;

namespace {

const std::string kHealthy = std::string(FLEXARM_SAMPLE_DIR) + "/diagnosis_no_fault.csv";
const std::string kFault = std::string(FLEXARM_SAMPLE_DIR) + "/diagnosis_step_k_T.csv";

fs::path folder(const std::string& name) {
  const fs::path dir = flexarm::test::scratchDir() / ("hostile3_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST(HostileThree, AManifestRowNamingAFileOutsideItsFolderIsRefusedUnread) {
  const fs::path dir = folder("leak");
  fs::create_symlink("/etc/passwd", dir / "innocent.csv");
  for (const std::string log : {"/etc/passwd", "../../../../../../etc/passwd", "innocent.csv", "/etc/shadow"}) {
    const fs::path manifest = dir / "fleet.csv";
    { std::ofstream(manifest) << "# flexarm-fleet: 1\nrobot,axis,time,log\nR01,1,2026-03-01T06:00:00Z," << log << "\n"; }
    const auto r = confined({"fleet", manifest.string(), "--db", (dir / "f.sqlite").string(), "--json"});
    expectConfined(r, 3, "fleet.csv:3: column log: '" + log + "' lies outside the manifest's folder", 100);
    EXPECT_EQ(r.err.find("root:"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("root:"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "f.sqlite"));  // refused before the store is made
  }
}

TEST(HostileThree, RowsOfIdenticalBytesAreNamedAndTheLogAnalysedOnce) {
  const fs::path dir = folder("same_bytes");
  fs::copy_file(kHealthy, dir / "ref.csv");
  fs::copy_file(kFault, dir / "a.csv");
  fs::copy_file(kFault, dir / "b.csv");
  {
    std::ofstream(dir / "fleet.csv") << "# flexarm-fleet: 1\nrobot,axis,time,log,temperature_c,role\n"
                                     << "R01,1,2026-03-01T06:00:00Z,ref.csv,25,reference\n"
                                     << "R01,1,2026-03-02T06:00:00Z,a.csv,25,\n"
                                     << "R01,1,2026-03-03T06:00:00Z,b.csv,25,\n"
                                     << "R01,1,2026-03-04T06:00:00Z,a.csv,25,\n";
  }
  const std::string db = (dir / "f.sqlite").string();
  for (int run = 0; run < 2; ++run) {
    const auto r = runFlexarm({"fleet", (dir / "fleet.csv").string(), "--db", db, "--json"});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("analysed").get<int>(), run == 0 ? 2 : 0);  // the reference and a.csv
    EXPECT_EQ(j.at("failed").get<int>(), 2) << r.out;           // rows 5 and 6, every run alike
    ASSERT_EQ(j.at("failures").size(), 2u);
    EXPECT_NE(j.at("failures")[0].at("message").get<std::string>().find(
                  "line 5 names a log of the same bytes as line 4 (a.csv)"),
              std::string::npos)
        << j.at("failures")[0];
    EXPECT_NE(j.at("failures")[1].at("message").get<std::string>().find("line 6"), std::string::npos);
    EXPECT_FALSE(j.at("logs_outside_allowed").get<bool>());
  }
}

TEST(HostileThree, AStoreAnotherProgramChangedIsRefusedWithASentence) {
  const fs::path dir = folder("store_view");
  const std::string db = (dir / "f.sqlite").string();
  fs::copy_file(kHealthy, dir / "ref.csv");
  { std::ofstream(dir / "fleet.csv") << "# flexarm-fleet: 1\nrobot,axis,time,log\nR01,1,2026-03-01T06:00:00Z,ref.csv\n"; }
  {
    // A store as FlexArm makes it, then its estimates table turned into a view.
    const auto made = runFlexarm({"fleet", (dir / "fleet.csv").string(), "--db", db, "--json"});
    ASSERT_EQ(made.code, 0) << made.err;
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(raw, "DROP TABLE estimates; CREATE VIEW estimates AS SELECT * FROM logs", nullptr, nullptr,
                           nullptr),
              SQLITE_OK);
    sqlite3_close(raw);
  }
  expectConfined(confined({"fleet", (dir / "fleet.csv").string(), "--db", db}), 3,
                 "holds view 'estimates', which FlexArm does not write", 200);
}

TEST(HostileThree, OptionsOutsideWhatADiagnosisCanUseAreRefusedByName) {
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"diagnose", kHealthy, "--reference-log", kHealthy, "--k", "1e308"}, "--k expects a number from 0.1 to 100, got '1e308'"},
      {{"diagnose", kHealthy, "--reference-log", kHealthy, "--alpha2", "1e308"}, "--alpha2 expects a number from 0.01 to 10000"},
      {{"diagnose", kHealthy, "--reference-log", kHealthy, "--hypothesis-threshold", "1e308"}, "--hypothesis-threshold expects a number from 0.01 to 100"},
      {{"diagnose", kHealthy, "--reference-log", kHealthy, "--settle", "1e308"}, "--settle expects a number from 0 to 3600"},
      {{"fleet", "m.csv", "--db", "x.sqlite", "--limit", "0"}, "--limit expects a whole number from 1"},
      {{"fleet", "m.csv", "--db", "x.sqlite", "--slurm-timeout", "1e308"}, "--slurm-timeout expects a number from 1 to"},
      {{"fleet", "m.csv", "--db", "x.sqlite", "--engine", "slurm", "--slurm-dir", "/tmp/x\n#SBATCH --uid=0"},
       "--slurm-dir holds a line break"},
      {{"fit", kHealthy, "--model", "three-mass", "--effect", "coulomb_friction:1e308"},
       "coulomb_friction: 1e+308 is beyond the +-1e15"},
      {{"diagnose", kHealthy, "--reference-log", kHealthy, "--k", std::string(5000, '7')}, "(5000 characters)"}};
  for (const auto& c : cases) {
    const auto r = confined(c.args, 30);
    expectConfined(r, 2, c.says, 100);
    EXPECT_LT(r.err.size(), 600u) << r.err.substr(0, 600);
  }
}

TEST(HostileThree, ThresholdsSetByHandAreSaidToBeUncalibrated) {
  const auto byHand = runFlexarm({"diagnose", kHealthy, "--reference-log", kHealthy, "--k", "5", "--json"});
  ASSERT_EQ(byHand.code, 0) << byHand.err;
  const std::string said = nlohmann::json::parse(byHand.out).at("thresholds_provenance").get<std::string>();
  EXPECT_NE(said.find("set by hand (k (classical) = 5, k (robust) = 5"), std::string::npos) << said;
  EXPECT_NE(said.find("not measured"), std::string::npos) << said;
  EXPECT_EQ(said.find("isolated 99 %"), std::string::npos) << said;
  const auto settle = runFlexarm({"diagnose", kHealthy, "--reference-log", kHealthy, "--settle", "3000"});
  EXPECT_NE(settle.code, 0);
  EXPECT_NE(settle.err.find("no alarm is raised in the first 3000 s (the settling time), and the log lasts"),
            std::string::npos)
      << settle.err;
}

TEST(HostileThree, AFileThatIsNotALogIsNamedWithoutItsFirstLine) {
  // The user named /etc/passwd as a log: it is read (they asked), and refused without its text.
  const auto temperature =
      runFlexarm({"diagnose", kHealthy, "--reference-log", kHealthy, "--temperature-logs", "/etc/passwd"});
  EXPECT_NE(temperature.code, 0);
  EXPECT_NE(temperature.err.find("/etc/passwd:1"), std::string::npos) << temperature.err;
  EXPECT_NE(temperature.err.find("not a CSV log's header"), std::string::npos) << temperature.err;
  EXPECT_EQ(temperature.err.find("root:"), std::string::npos) << temperature.err;
  const auto info = runFlexarm({"info", "/etc/passwd"});
  EXPECT_EQ(info.code, 3);
  EXPECT_EQ(info.err.find("root:"), std::string::npos) << info.err;
}
