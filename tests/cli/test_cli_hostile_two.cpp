// Hostile inputs, round two (tests/data/hostile/README.md): dead data, v7.3 .mat files that
// point outside themselves or never end, work sized by the request, links planted where
// reports are written, and messages. Every run is held to a time and memory ceiling and traced
// (strace): nothing outside the test's own folder is written, and nothing outside it, the
// source tree and the system's libraries is read (not /etc/passwd, not a pipe).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cli_test_support.h"
#include "hostile_support.h"

using flexarm::test::ceilingMb;
using flexarm::test::confined;
using flexarm::test::expectConfined;
using flexarm::test::joined;
using flexarm::test::kUnderAddressSanitizer;
using flexarm::test::MeasuredRun;
using flexarm::test::RunLimits;
using flexarm::test::runFlexarmMeasured;
namespace fs = std::filesystem;

namespace {

const std::string kSample = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const std::string kHealthy = std::string(FLEXARM_SAMPLE_DIR) + "/diagnosis_no_fault.csv";

std::string hostile(const std::string& name) { return std::string(FLEXARM_TEST_DATA_DIR) + "/hostile/" + name; }


// A session of one log (its checksum unknown: the replay warns) and the given parts.
void writeSession(const fs::path& path, const std::string& logName, const std::string& logPath,
                  const std::string& parts) {
  std::ofstream f(path);
  f << R"({"format": "flexarm-session", "version": 1, "written_by": "FlexArm 0.1.0", "logs": [{"name": ")"
    << logName << R"(", "path": ")" << logPath << R"(", "sha256": ")" << std::string(64, '0')
    << R"(", "read": {"format": "auto"}}], "preprocessing": {"applied": false, "differentiate_angle": false,
    "range_samples": null, "decimation": {"factor": 1, "filter": "fir", "stopband_db": 80.0}, "detrend": "none"},
    "ranges": {"estimation_s": null, "validation_s": null}, "parts": )"
    << parts << "}";
}

std::string bigFile(const std::string& name, const std::string& extension) {
  std::string file = flexarm::test::bigHostileFile(name, extension);
  if (file.empty()) ADD_FAILURE() << "scripts/make_hostile_data.py --big could not make " << name;
  return file;
}

}  // namespace

// --- 1 and 5: dead data are refused before any analysis, naming the channel ------------------

TEST(HostileTwo, DiagnosisOnADeadReferenceLogIsRefusedNotCrashed) {
  // These died with SIGSEGV in referenceFromSignals after a "converged" singular fit.
  expectConfined(confined({"diagnose", kHealthy, "--model", "three-mass", "--reference-log",
                           hostile("dead_stuck_encoder.csv")}),
                 3, "dead_stuck_encoder.csv: the channel motor_angle_rad carries no signal: it is constant (every sample is 1.25)",
                 300);
  expectConfined(confined({"diagnose", kHealthy, "--model", "three-mass", "--reference-log",
                           hostile("dead_all_zero.csv")}),
                 3, "the channel torque_ref_nm carries no signal: it is constant (every sample is 0)", 300);
  expectConfined(confined({"diagnose", kHealthy, "--model", "three-mass", "--reference-log",
                           hostile("dead_subnormal.csv")}),
                 3, "too small for its squares to be told from zero", 300);
}

TEST(HostileTwo, SessionDiagnosisOnADeadLogWarnsInsteadOfCrashing) {
  // `flexarm run` of a session holding such a diagnosis died the same way.
  const fs::path session = flexarm::test::scratchDir() / "dead_reference.json";
  writeSession(session, "stuck", hostile("dead_stuck_encoder.csv"),
               R"({"diagnosis": {"request": {"log": "stuck", "reference_log": "stuck", "structure": "three-mass",
                                             "seed_fault": null, "calibrate": false}}})");
  const MeasuredRun r = confined({"run", session.string(), "--json"});
  expectConfined(r, 0, "flexarm run: warning: diagnosis: could not run: ", 300);
  EXPECT_NE(r.err.find("the channel motor_angle_rad carries no signal"), std::string::npos) << r.err;
}

TEST(HostileTwo, SingularReferenceFitEndsAsASentence) {
  // A time step of 1e6 s leaves the parameters unidentifiable: the fit's Hessian is singular
  // and gives no covariance, which the thresholds need.
  expectConfined(confined({"diagnose", kHealthy, "--model", "three-mass", "--reference-log",
                           hostile("time_step_1e6.csv")}),
                 4, "the data cannot tell the parameters apart (the fit's Hessian is singular", 300);
}

TEST(HostileTwo, EveryAnalysisRefusesDeadData) {
  // Each of these answered with confidence (exit 0): an effect named on zero torque, "no
  // fault" on an all-zero log, a fit of "-inf %", k_T = 0.013 from a stuck encoder.
  struct Case {
    const char* verb;
    const char* file;
    const char* model;
    const char* message;
  };
  const Case cases[] = {
      {"discover", "dead_zero_torque.csv", "two-mass",
       "dead_zero_torque.csv: the channel torque_ref_nm carries no signal: it is constant"},
      {"discover", "dead_torque_1e308.csv", "two-mass",
       "the channel torque_ref_nm carries no signal: it reaches 1e+308 in magnitude"},
      {"diagnose", "dead_all_zero.csv", "three-mass", "dead_all_zero.csv: the channel torque_ref_nm carries no signal"},
      {"diagnose", "dead_zero_torque.csv", "three-mass", "the channel torque_ref_nm carries no signal"},
      {"fit", "dead_stuck_encoder.csv", "arx:2,2,1", "dead_stuck_encoder.csv: the channel motor_angle_rad carries no signal"},
      {"fit", "dead_stuck_encoder.csv", "two-mass", "the channel motor_angle_rad carries no signal"},
      {"recursive", "dead_stuck_encoder.csv", "two-mass", "the channel motor_angle_rad carries no signal"},
      {"recursive", "dead_stuck_large_reading.csv", "two-mass",
       "varies by only 2.27374e-13 around 1000 (constant to 12 digits: a stuck sensor)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.verb) + " " + c.file);
    expectConfined(confined({c.verb, hostile(c.file), "--model", c.model}), 3, c.message, 200);
  }
}

// --- 2: v7.3 .mat files are walked before HDF5 opens them -------------------------------------

TEST(HostileTwo, V73ExternalStorageIsRefusedWithoutReadingTheOtherFile) {
  // Its data lived in /etc/passwd: preprocess copied that file into the CSV with exit 0.
  const auto out = (flexarm::test::scratchDir() / "leak.csv").string();
  const MeasuredRun r = confined({"preprocess", hostile("v73_external_storage.mat"), "--out", out});
  expectConfined(r, 3, "/motor_angle_rad keeps its data in another file (HDF5 external storage)", 100);
  EXPECT_FALSE(fs::exists(out));
}

TEST(HostileTwo, V73ExternalStorageInAPipeDoesNotBlock) {
  const auto file = bigFile("v73_external_fifo", ".mat");
  expectConfined(confined({"info", file}, 30), 3, "keeps its data in another file", 100);
}

TEST(HostileTwo, V73LinksLeavingTheFileAreRefused) {
  expectConfined(confined({"info", hostile("v73_external_link.mat")}), 3,
                 "/leak is an external link to another file; FlexArm reads only the file it was given", 100);
  expectConfined(confined({"info", hostile("v73_soft_link.mat")}), 3,
                 "/alias is a soft link (to a path)", 100);
}

TEST(HostileTwo, V73LinkCyclesAreNamedNotFollowed) {
  expectConfined(confined({"info", hostile("v73_hard_link_cycle.mat")}, 30), 3,
                 "a link cycle: /s/inner leads back to an object on its own path", 100);
  expectConfined(confined({"info", hostile("v73_reference_cycle.mat")}, 30), 3,
                 "a link cycle: /#refs#/a (reference 1) leads back", 100);
}

TEST(HostileTwo, V73NestingAndVariableCountsAreBounded) {
  // 3000 nested structs and 20 000 variables each took over a minute.
  const auto nested = bigFile("v73_nested_3000", ".mat");
  expectConfined(confined({"info", nested}, 30), 3, "is nested 17 levels deep, more than the 16 FlexArm follows", 150);
  const auto many = bigFile("v73_20000_variables", ".mat");
  expectConfined(confined({"info", many}, 30), 3, "the file holds 20003 variables, more than the 1000", 250);
}

TEST(HostileTwo, V73CompressionBombIsRefusedBeforeInflating) {
  // 152 KB that inflate to 128 MiB (the first probe: 0.94 MB took 2.24 GB and 7.5 s).
  expectConfined(confined({"info", hostile("v73_gzip_bomb.mat")}), 3,
                 "/zeros would take 128.0 MiB in memory uncompressed", 60);
}

TEST(HostileTwo, V73PluginFiltersAndDamageAreRefused) {
  expectConfined(confined({"info", hostile("v73_plugin_filter.mat")}), 3,
                 "is compressed with filter 32000 (a plug-in library HDF5 would load)", 100);
  expectConfined(confined({"info", hostile("v73_truncated.mat")}), 3, "points outside the file", 100);
}

TEST(HostileTwo, V73HeapsThatMadeHdf5LoopForeverAreRefused) {
  // A global heap whose free space does not advance (found by fuzz_mat73: HDF5 spun in
  // H5HG_read reading a struct's field names) and a local heap whose free list is a circle.
  expectConfined(confined({"info", hostile("v73_heap_no_progress.mat")}, 20), 3,
                 "the global heap /settings's attribute MATLAB_fields points into holds an object that reaches past "
                 "its end or does not advance",
                 100);
  expectConfined(confined({"info", hostile("v73_free_list_cycle.mat")}, 20), 3,
                 "the name heap of / has a free list that leaves the heap or runs in a circle", 100);
}

TEST(HostileTwo, V73LogOpensAndNamesTheVariablesItSkips) {
  const MeasuredRun r = confined({"info", hostile("v73_good.mat")});
  expectConfined(r, 0, "", 100);
  EXPECT_NE(r.out.find("400 samples at 2000 Hz"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("torque_ref_nm [N m] input"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("skipped: notes (cell), settings (struct)"), std::string::npos) << r.out;
  // The same log in HDF5's newest format (superblock 3, version-2 object headers).
  const MeasuredRun latest = confined({"info", hostile("v73_good_latest.mat")});
  expectConfined(latest, 0, "", 100);
  EXPECT_NE(latest.out.find("motor_angle_rad [rad] output"), std::string::npos) << latest.out;
}

// --- 3: work sized by the request is checked against a budget before it starts ----------------

TEST(HostileTwo, CalibrationRunsBeyondTheBudgetAreRefusedBeforeSettingUp) {
  // --runs 100000 (in the documented range) took 4 GB in 2.6 s and 20 GB by 60 s.
  expectConfined(confined({"diagnose", kHealthy, "--model", "three-mass", "--reference-log", kHealthy,
                           "--calibrate", "--runs", "100000"}, 120),
                 2, "runs of 24 s would hold", 600);
  expectConfined(confined({"diagnose", kHealthy, "--model", "three-mass", "--calibrate", "--runs", "1000000"}), 2,
                 "--runs expects a whole number from 1 to 100000, got '1000000'", 100);
}

TEST(HostileTwo, SessionCalibrationRunsBeyondTheBudgetWarnInsteadOfExhaustingMemory) {
  // calibration_runs of a session's diagnosis part go through the same budget.
  const fs::path session = flexarm::test::scratchDir() / "calibration_runs.json";
  writeSession(session, "healthy", kHealthy,
               R"({"diagnosis": {"request": {"log": "healthy", "reference_log": "healthy", "structure": "three-mass",
                                             "seed_fault": null, "calibrate": true, "calibration_runs": 100000}}})");
  const MeasuredRun r = confined({"run", session.string(), "--json"}, 120);
  expectConfined(r, 0, "flexarm run: warning: diagnosis: could not run: the calibration is refused: ", 600);
  EXPECT_NE(r.err.find("runs of 24 s would hold"), std::string::npos) << r.err;
}

TEST(HostileTwo, ResampleRateBeyondTheBudgetIsRefusedBeforeAllocating) {
  // 1e7 Hz built 2.86 GB before the rate was refused.
  const auto out = (flexarm::test::scratchDir() / "fine.csv").string();
  expectConfined(confined({"preprocess", kSample, "--resample", "1e7", "--out", out}), 3,
                 "resampling to 1e+07 Hz would make", 300);
  EXPECT_FALSE(fs::exists(out));
}

TEST(HostileTwo, HugeTimeStepEndsInsteadOfLooping) {
  // A time step of 1e6 s made ExtendedZoh::advance take billions of sub-steps a sample.
  // The recursive estimator forgets with a memory of one second, so a step of 1e6 s is refused
  // before its pre-run for P(0) (ExtendedZoh's own refusal is tested in
  // tests/core/recursive/test_extended_zoh.cpp).
  expectConfined(confined({"recursive", hostile("time_step_1e6.csv"), "--model", "two-mass"}), 3,
                 "time_step_1e6.csv: The sample time of 1e+06 s is longer than the recursive estimator's memory of 1 s",
                 200);
  // Given per sample, the forgetting factor keeps its memory of 200 samples; the pre-run then
  // finds nothing to tell apart at that step.
  expectConfined(confined({"recursive", hostile("time_step_1e6.csv"), "--model", "two-mass", "--per-sample"}), 3,
                 "time_step_1e6.csv: The data cannot tell the estimated parameters apart", 200);
  const MeasuredRun d = confined({"diagnose", hostile("time_step_1e6.csv"), "--model", "three-mass"});
  EXPECT_FALSE(d.timedOut);
  EXPECT_TRUE(d.code == 3 || d.code == 4) << d.err;
  EXPECT_EQ(d.err.find("forgetting factor must lie"), std::string::npos) << d.err;  // no option was wrong
  EXPECT_TRUE(d.outsideAccess.empty()) << joined(d.outsideAccess);
}

TEST(HostileTwo, ManyStartsShowProgress) {
  // --starts 1000 ran over a minute without a word; now it says how far it is.
  RunLimits limits;
  limits.timeoutSeconds = kUnderAddressSanitizer ? 30 : 8;
  const MeasuredRun r = runFlexarmMeasured({"fit", kSample, "--model", "two-mass", "--starts", "1000"}, limits);
  EXPECT_NE(r.err.find("flexarm fit: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" % (start "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" of 1003: "), std::string::npos) << r.err;  // 1000 random, 3 from the SPA estimate
  EXPECT_LT(r.maxRssMb, ceilingMb(300));
}

// --- 4: every file is written through one writer that follows no link --------------------------

TEST(HostileTwo, WritersDoNotFollowPlantedLinks) {
  const fs::path dir = flexarm::test::scratchDir() / "links";
  fs::create_directories(dir);
  const fs::path victim = dir / "victim.txt";
  { std::ofstream(victim) << "keep me\n"; }
  // The PDF report was written to the predictable REPORT.pdf.part: a link planted there had its
  // target overwritten. The simulated log and the session report go through the same writer.
  fs::create_symlink(victim, dir / "log.csv.part");
  fs::create_symlink(victim, dir / "log.csv.tmp-0");
  const MeasuredRun ok = confined({"simulate", "--duration", "0.2", "--out", (dir / "log.csv").string()});
  expectConfined(ok, 0, "", 200);
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / "log.csv")));
  // A link at the target itself is refused, not followed and not replaced.
  fs::create_symlink(victim, dir / "linked.csv");
  expectConfined(confined({"simulate", "--duration", "0.2", "--out", (dir / "linked.csv").string()}), 3,
                 "linked.csv is a symbolic link; FlexArm writes only regular files", 200);
  EXPECT_TRUE(fs::is_symlink(dir / "linked.csv"));
  EXPECT_EQ(flexarm::test::readAll(victim.string()), "keep me\n");
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name != "log.csv.tmp-0") {
      EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "left behind: " << e.path();
    }
  }
  // The files it created: exclusively (O_EXCL), refusing a link (O_NOFOLLOW), under a name with
  // 16 random hex digits beside the target.
  ASSERT_EQ(ok.creations.size(), 2u) << joined(ok.creations);  // the log and its truth
  for (const std::string& c : ok.creations) {
    EXPECT_NE(c.find("O_EXCL"), std::string::npos) << c;
    EXPECT_NE(c.find("O_NOFOLLOW"), std::string::npos) << c;
  }
  EXPECT_EQ(ok.creations[0].find((dir / ".log.csv.tmp-").string()), 0u) << ok.creations[0];
  EXPECT_EQ(ok.creations[0].find(' '), (dir / ".log.csv.tmp-").string().size() + 16) << ok.creations[0];
}

TEST(HostileTwo, FleetStoreDoesNotFollowPlantedLinks) {
  // The fleet's SQLite store is written in place, not replaced: a link at its name or at its
  // writer lock would send those writes to the link's target.
  const fs::path dir = flexarm::test::scratchDir() / "store_links";
  fs::create_directories(dir);
  const fs::path victim = dir / "victim.txt";
  { std::ofstream(victim) << "keep me\n"; }
  const fs::path manifest = dir / "fleet.csv";
  { std::ofstream(manifest) << "# flexarm-fleet: 1\nrobot,axis,time,log\nR01,1,2026-03-01T06:00:00Z," << kHealthy << "\n"; }
  fs::create_symlink(victim, dir / "linked.sqlite");
  // (The log is the sample's, outside this folder: --allow-logs-outside.)
  expectConfined(confined({"fleet", manifest.string(), "--allow-logs-outside", "--db", (dir / "linked.sqlite").string()}), 3,
                 "linked.sqlite: is a symbolic link; FlexArm writes only regular files", 100);
  fs::create_symlink(victim, dir / "locked.sqlite.writer");
  expectConfined(confined({"fleet", manifest.string(), "--allow-logs-outside", "--db", (dir / "locked.sqlite").string()}), 3,
                 "the writer lock " + (dir / "locked.sqlite.writer").string() + " is a symbolic link", 100);
  EXPECT_FALSE(fs::exists(dir / "locked.sqlite"));
  EXPECT_EQ(flexarm::test::readAll(victim.string()), "keep me\n");
}

#if FLEXARM_GUI_BUILD
TEST(HostileTwo, ReportIsWrittenExclusivelyUnderAnUnpredictableName) {
  const fs::path dir = flexarm::test::scratchDir() / "report_links";
  fs::create_directories(dir);
  const fs::path victim = dir / "victim.txt";
  { std::ofstream(victim) << "keep me\n"; }
  fs::create_symlink(victim, dir / "report.pdf.part");
  const fs::path session = dir / "session.json";
  writeSession(session, "estimation", kSample, R"({"models": []})");
  RunLimits limits;
  limits.timeoutSeconds = 120;
  limits.traceFiles = true;
  const MeasuredRun r = runFlexarmMeasured({"run", session.string(), "--report", (dir / "report.pdf").string()}, limits);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / "report.pdf")));
  EXPECT_EQ(flexarm::test::readAll(victim.string()), "keep me\n");
  EXPECT_TRUE(fs::is_symlink(dir / "report.pdf.part"));
  EXPECT_NE(flexarm::test::pdfText((dir / "report.pdf").string()).find("FlexArm"), std::string::npos);
}
#endif

// --- 6: messages name the file, the line or key, and the problem ------------------------------

TEST(HostileTwo, TextThatIsNotUtf8IsNamedNotPassedToJson) {
  // Both gave exit 4 with "[json.exception.type_error.316] invalid UTF-8 byte".
  expectConfined(confined({"info", hostile("metadata_latin1.csv"), "--json"}), 3,
                 "metadata_latin1.csv:3: description: the metadata line is not UTF-8 text: byte 0xe4", 100);
  const MeasuredRun r = confined({"info", hostile("column_invalid_utf8.csv"), "--json"});
  expectConfined(r, 3, "column_invalid_utf8.csv:3: column 4: the column name is not UTF-8 text: byte 0xb0", 100);
  EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
}

TEST(HostileTwo, ControllerMetadataOutOfRangeIsNamedByKey) {
  const MeasuredRun kp = confined({"diagnose", hostile("controller_kp_1e308.csv"), "--model", "two-mass",
                                   "--predictor", "loop"});
  expectConfined(kp, 3, "controller_kp is 1e+308, beyond any controller", 200);
  EXPECT_EQ(kp.err.find("non-finite entry"), std::string::npos) << kp.err;
  const MeasuredRun rate = confined({"fit", hostile("controller_rate_1e300.csv"), "--model", "two-mass",
                                     "--max-iterations", "3"});
  EXPECT_EQ(rate.err.find("-9223372036854775808"), std::string::npos) << rate.err;
  EXPECT_FALSE(rate.timedOut);
  EXPECT_TRUE(rate.outsideAccess.empty()) << joined(rate.outsideAccess);
}

TEST(HostileTwo, TimeStampsThatOverflowAreRefused) {
  // +-1.7e308: the step overflowed to inf and the log opened at 0 Hz.
  expectConfined(confined({"info", hostile("time_1.7e308.csv")}), 3,
                 "a time step of inf s, longer than the 1e+06 s FlexArm reads", 100);
}

TEST(HostileTwo, CarriageReturnLineEndsAreNamed) {
  expectConfined(confined({"info", hostile("cr_only.csv")}), 3,
                 "the file's lines end in a carriage return alone (CR", 100);
}

TEST(HostileTwo, SessionPartNamingAnUnknownLogWarnsWithThePartsName) {
  const MeasuredRun r = confined({"run", hostile("session_discovery_unknown_log.json"), "--json"});
  expectConfined(r, 0, "flexarm run: warning: discovery: could not run: estimation data: the session has no "
                       "log named 'no_such_log'",
                 300);
}

TEST(HostileTwo, NominalModelThatIsAPipeIsRefusedBeforeReading) {
  const fs::path fifo = flexarm::test::scratchDir() / "nominal.json";
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expectConfined(confined({"recursive", kSample, "--model", "two-mass", "--nominal", fifo.string()}, 30), 3,
                 "nominal.json: is a pipe, not a regular file", 100);
}
