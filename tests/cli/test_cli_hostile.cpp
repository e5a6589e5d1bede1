// Hostile inputs, as a new user or an attacker would try them (tests/data/hostile/README.md):
// each ends in exit 2 (usage) or 3 (bad input) with a sentence naming the problem, within a
// memory ceiling, and never replaces what it must not.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cli_test_support.h"

using flexarm::test::MeasuredRun;
using flexarm::test::runFlexarmMeasured;
namespace fs = std::filesystem;

namespace {

const std::string kSample = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const std::string kDaisy = std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat";

std::string hostile(const std::string& name) {
  return std::string(FLEXARM_TEST_DATA_DIR) + "/hostile/" + name;
}

using flexarm::test::ceilingMb;

std::string bigFile(const std::string& name, const std::string& extension) {
  std::string file = flexarm::test::bigHostileFile(name, extension);
  if (file.empty()) ADD_FAILURE() << "scripts/make_hostile_data.py --big could not make " << name;
  return file;
}

void expectRefused(const MeasuredRun& r, int code, const std::string& needle, long memoryMb) {
  EXPECT_EQ(r.code, code) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
  EXPECT_LT(r.maxRssMb, ceilingMb(memoryMb)) << r.err;
}

}  // namespace

TEST(Hostile, MatClaimingTwoBillionElementsIsRefusedFromItsSize) {
  expectRefused(runFlexarmMeasured({"info", hostile("mat_claims_2g_elements.mat")}), 3,
                "claims 2147483647 elements but its data hold 6000", 100);
}

TEST(Hostile, MatWithHugeVariableNameIsRefused) {
  expectRefused(runFlexarmMeasured({"info", hostile("mat_huge_name.mat")}), 3,
                "an element claims 2147483640 bytes", 100);
}

TEST(Hostile, MatCompressedVariableClaimingGigabytesIsRefused) {
  expectRefused(runFlexarmMeasured({"info", hostile("mat_compressed_claims_4g.mat")}), 3,
                "claims to inflate to 4294967295 bytes", 100);
}

TEST(Hostile, Level4MatClaimingHugeMatrixIsRefused) {
  expectRefused(runFlexarmMeasured({"info", hostile("mat_v4_claims_huge.mat")}), 3,
                "damaged or cut short", 100);
}

TEST(Hostile, CsvHeaderOfTenMillionColumnsIsRefusedQuickly) {
  const auto file = bigFile("header_1e7_columns", ".csv");
  // The file is 90 MB; it is read once and the header split stops at the column limit.
  expectRefused(runFlexarmMeasured({"info", file}), 3, "more than 65536 columns", 250);
  fs::remove(file);
}

TEST(Hostile, TableOfOneHundredMegabyteLineStaysWithinTwiceItsSize) {
  const auto file = bigFile("table_one_100mb_line", ".dat");
  expectRefused(runFlexarmMeasured({"info", file}), 3, "more than 65536 columns", 250);
  fs::remove(file);
}

TEST(Hostile, ValidationLogThatIsADeviceIsRefusedBeforeReading) {
  expectRefused(runFlexarmMeasured({"fit", kDaisy, "--model", "arx:2,2,1", "--validation-log",
                                    "/dev/zero"}),
                3, "/dev/zero: is a character device, not a regular file", 100);
  expectRefused(runFlexarmMeasured({"info", "/dev/stdin"}), 3, "not a regular file", 100);
  expectRefused(runFlexarmMeasured({"info", "/tmp"}), 3, "is a directory", 100);
}

TEST(Hostile, SessionWhoseLogIsADeviceIsRefusedNotHashedForever) {
  for (const char* dev : {"zero", "urandom"}) {
    SCOPED_TRACE(dev);
    expectRefused(runFlexarmMeasured({"run", hostile(std::string("session_log_dev_") + dev + ".json"),
                                      "--json"}),
                  3, std::string("/dev/") + dev + ": is a character device", 100);
  }
}

TEST(Hostile, SessionRepeatingOneParameterAMillionTimesIsRefused) {
  const auto file = bigFile("session_1e6_parameters", ".json");
  expectRefused(runFlexarmMeasured({"run", file, "--json"}), 3,
                "a list or object holds more than 100000 items", 200);
  fs::remove(file);
}

TEST(Hostile, SessionOfTwentyThousandModelsIsRefused) {
  const auto file = bigFile("session_20000_models", ".json");
  expectRefused(runFlexarmMeasured({"run", file, "--json"}), 3, "more than 100 models", 300);
  fs::remove(file);
}

TEST(Hostile, PolynomialOrdersBeyondWhatTheDataAllowAreRefused) {
  // Each of these ran for minutes or crashed (Eigen QR with a negative row count).
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "oe:1000,1000,1"}), 2,
                "operations per iteration", 200);
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "arx:1000,1000,1"}), 2,
                "least-squares problem of", 200);
  expectRefused(runFlexarmMeasured({"fit", kDaisy, "--model", "armax:2,2,2,9000"}), 2,
                "too few samples (1024)", 100);
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "armax:2,2,2,100000"}), 2,
                "with the delay nk = 100000", 200);
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "oe:2,2,100000"}), 2,
                "too few samples", 200);
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "bj:2,2,2,2,100000"}), 2,
                "too few samples", 200);
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "arx:2147483647,1,1"}), 2,
                "more than 2000 parameters", 100);
  expectRefused(runFlexarmMeasured({"fit", kSample, "--model", "armax:2,2,2,2147483647"}), 2,
                "delay nk is more than 1000000", 100);
}

TEST(Hostile, LongDelayIsCheapNow) {
  // armax:2,2,2,9000 on 35 000 samples ran for minutes filtering 9000 leading zeros.
  const MeasuredRun r = runFlexarmMeasured({"fit", kSample, "--model", "armax:2,2,2,9000", "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("armax[2 2 2 9000]"), std::string::npos) << r.out;
  EXPECT_LT(r.maxRssMb, ceilingMb(200));
}

TEST(Hostile, SimulationLongerThanTheSampleLimitIsRefusedBeforeAllocating) {
  const auto out = (flexarm::test::scratchDir() / "long.csv").string();
  expectRefused(runFlexarmMeasured({"simulate", "--duration", "1e5", "--out", out}), 2,
                "200000000 samples (duration x log rate), more than the 4000000", 100);
  EXPECT_FALSE(fs::exists(out));
}

TEST(Hostile, WritingOverADeviceIsRefusedAndTheDeviceStays) {
  expectRefused(runFlexarmMeasured({"simulate", "--duration", "0.5", "--out", "/dev/full"}), 3,
                "/dev/full is a character device, not a regular file", 100);
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST(Hostile, FullDiskIsReportedAndThePreviousFileKept) {
  const auto dir = flexarm::test::scratchDir() / "diskfull";
  fs::create_directories(dir);
  const auto out = (dir / "log.csv").string();
  ASSERT_EQ(runFlexarmMeasured({"simulate", "--duration", "0.2", "--out", out}).code, 0);
  const auto before = flexarm::test::readAll(out);
  ASSERT_GT(before.size(), 1000u);
  // A file-size limit of 8 KiB makes write() fail as a full disk does.
  flexarm::test::RunLimits limits;
  limits.fileSizeBlocks = 16;
  const MeasuredRun r =
      runFlexarmMeasured({"simulate", "--duration", "2", "--seed", "7", "--out", out}, limits);
  expectRefused(r, 3, "writing " + out + " failed", 100);
  EXPECT_NE(r.err.find("the previous file, if any, is unchanged"), std::string::npos) << r.err;
  EXPECT_EQ(flexarm::test::readAll(out), before);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << "left behind: " << e.path();
}

TEST(Hostile, SubnormalTimeStepsAndSampleTimesAreRefused) {
  expectRefused(runFlexarmMeasured({"info", hostile("time_step_1e-310.csv")}), 3,
                "shorter than 1e-06 s", 100);
  expectRefused(runFlexarmMeasured({"info", kDaisy, "--sample-time", "1e-320"}), 2,
                "the sample time must lie between 1e-06 s", 100);
}

TEST(Hostile, ColumnNumbersThatOverflowAreRefusedNotWrapped) {
  expectRefused(runFlexarmMeasured({"info", kDaisy, "--input-column", "99999999999"}), 2,
                "--input-column expects a whole number from 1 to 65536, got '99999999999'", 100);
  expectRefused(runFlexarmMeasured({"info", kDaisy, "--output-column", "-1"}), 2,
                "--output-column expects a whole number", 100);
}

TEST(Hostile, Utf16AndByteOrderMarksAreNamed) {
  expectRefused(runFlexarmMeasured({"info", hostile("utf16le_bom.csv")}), 3,
                "UTF-16 text (it starts with a UTF-16 byte-order mark)", 100);
  expectRefused(runFlexarmMeasured({"info", hostile("utf16be_bom.csv")}), 3,
                "UTF-16 text (it starts with a UTF-16 byte-order mark)", 100);
  expectRefused(runFlexarmMeasured({"info", hostile("utf16le_no_bom.csv")}), 3,
                "looks like UTF-16 text", 100);
  expectRefused(runFlexarmMeasured({"info", hostile("utf8_bom.csv")}), 3,
                "UTF-8 byte-order mark (BOM)", 100);
}

TEST(Hostile, IterationAndStartCountsOutOfRangeAreUsageErrorsInWords) {
  const MeasuredRun a = runFlexarmMeasured({"fit", kSample, "--model", "two-mass",
                                            "--max-iterations", "1e12"});
  expectRefused(a, 2, "--max-iterations expects a whole number from 1 to 100000, got '1e12'", 100);
  const MeasuredRun b = runFlexarmMeasured({"fit", kSample, "--model", "two-mass",
                                            "--max-iterations", "1000000000000"});
  expectRefused(b, 2, "--max-iterations expects a whole number from 1 to 100000", 100);
  const MeasuredRun c = runFlexarmMeasured({"fit", kSample, "--model", "two-mass", "--starts",
                                            "1000000"});
  expectRefused(c, 2, "--starts expects a whole number from 0 to 1000, got '1000000'", 100);
  for (const auto* r : {&a, &b, &c}) EXPECT_EQ(r->err.find("Options"), std::string::npos) << r->err;
}
