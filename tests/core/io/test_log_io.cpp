// Reading and writing logs: good files round-trip, every malformed file is refused with a
// message naming file, line, column and problem.
#include <gtest/gtest.h>
#include <matio.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/io/log_io.h"
#include "core/io/ranges.h"

using namespace flexarm;
namespace fs = std::filesystem;

namespace {

std::string bad(const std::string& name) { return std::string(FLEXARM_TEST_DATA_DIR) + "/bad/" + name; }

fs::path tempDir() {
  fs::path p = fs::temp_directory_path() / ("flexarm_io_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

IdData makeData(std::size_t n, double dt) {
  IdData d;
  d.sampleTime = dt;
  d.startTime = 0.0;
  Channel angle{columns::kMotorAngle, "", ChannelRole::Output, {}};
  Channel torque{columns::kTorqueRef, "", ChannelRole::Input, {}};
  for (std::size_t i = 0; i < n; ++i) {
    angle.values.push_back(std::sin(0.01 * i) * 1e-3 + 1e-17 * i);
    torque.values.push_back(0.1 * std::cos(0.02 * i) - 3.0e-7);
  }
  d.setChannel(angle);
  d.setChannel(torque);
  d.setMeta("description", "unit test");
  return d;
}

struct BadCase {
  const char* file;
  int line;
  int column;
  const char* needle;  // a word the problem must contain
};

}  // namespace

TEST(LogIo, WritesAndReadsBackExactly) {
  const IdData d = makeData(500, 0.0005);
  const std::string path = (tempDir() / "roundtrip.csv").string();
  ReadError err;
  ASSERT_TRUE(writeFlexArmCsv(d, path, &err)) << err.toString();
  LogReadResult r = readLog(path);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.samples(), 500u);
  EXPECT_NEAR(r.data.sampleTime, 0.0005, 1e-12);
  for (const auto& c : d.channels) {
    const Channel* back = r.data.channel(c.name);
    ASSERT_NE(back, nullptr) << c.name;
    EXPECT_EQ(back->values, c.values) << "values must round-trip bit for bit: " << c.name;
  }
  EXPECT_EQ(r.data.meta("description"), "unit test");
  EXPECT_EQ(r.data.input()->name, columns::kTorqueRef);
  EXPECT_EQ(r.data.output()->name, columns::kMotorAngle);
  EXPECT_EQ(r.data.channel(columns::kMotorAngle)->unit, "rad");
  EXPECT_EQ(r.data.channel(columns::kTorqueRef)->unit, "N m");
}

TEST(LogIo, RangesSurviveWriteAndRead) {
  IdData d = makeData(2001, 0.001);
  d.estimationRange = SampleRange{100, 1101};
  d.validationRange = SampleRange{1200, 2001};
  storeRanges(d);
  const std::string path = (tempDir() / "ranges.csv").string();
  ASSERT_TRUE(writeFlexArmCsv(d, path));
  LogReadResult r = readLog(path);
  ASSERT_TRUE(r.ok);
  std::string why;
  ASSERT_TRUE(applyStoredRanges(r.data, &why)) << why;
  ASSERT_TRUE(r.data.estimationRange && r.data.validationRange);
  EXPECT_EQ(*r.data.estimationRange, (SampleRange{100, 1101}));
  EXPECT_EQ(*r.data.validationRange, (SampleRange{1200, 2001}));
}

TEST(LogIo, FailedWriteKeepsThePreviousFile) {
  const IdData good = makeData(10, 0.01);
  const std::string path = (tempDir() / "keep.csv").string();
  ASSERT_TRUE(writeFlexArmCsv(good, path));
  const auto sizeBefore = fs::file_size(path);
  IdData broken = good;
  broken.channels[0].values[3] = std::nan("");
  ReadError err;
  EXPECT_FALSE(writeFlexArmCsv(broken, path, &err));
  EXPECT_NE(err.problem.find("non-finite"), std::string::npos) << err.problem;
  EXPECT_EQ(fs::file_size(path), sizeBefore);
  EXPECT_TRUE(readLog(path).ok);
  // Writing into a folder that does not exist fails cleanly, leaving no temporary file.
  EXPECT_FALSE(writeFlexArmCsv(good, (tempDir() / "no/such/dir/x.csv").string(), &err));
  EXPECT_NE(err.problem.find("cannot create"), std::string::npos) << err.problem;
}

TEST(LogIo, EveryMalformedFileIsRefusedWithFileLineColumnAndProblem) {
  const BadCase cases[] = {
      {"empty.csv", 1, 0, "empty"},
      {"comments_only.csv", 2, 0, "no header"},
      {"header_only.csv", 3, 0, "not followed by any data"},
      {"missing_column.csv", 2, 0, "torque_ref_nm"},
      {"non_numeric.csv", 5, 3, "'abc' is not a number"},
      {"empty_field.csv", 4, 2, "empty"},
      {"nan_value.csv", 4, 2, "not a finite number"},
      {"inf_value.csv", 5, 3, "not a finite number"},
      {"wrong_field_count.csv", 5, 0, "has 2 fields, the header has 3"},
      {"non_increasing_time.csv", 6, 1, "does not increase"},
      {"irregular_sampling.csv", 6, 1, "irregular sampling"},
      {"rate_mismatch.csv", 2, 0, "1000 Hz"},
      {"table_non_numeric.dat", 3, 2, "'x7' is not a number"},
      {"table_ragged.dat", 2, 0, "3 fields"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    LogReadResult r = readLog(bad(c.file));
    ASSERT_FALSE(r.ok);
    EXPECT_EQ(r.error.file, bad(c.file));
    EXPECT_EQ(r.error.line, c.line) << r.error.toString();
    EXPECT_EQ(r.error.column, c.column) << r.error.toString();
    EXPECT_NE(r.error.problem.find(c.needle), std::string::npos) << r.error.toString();
    EXPECT_EQ(r.data.samples(), 0u) << "no partial data";
    const std::string text = r.error.toString();
    EXPECT_EQ(text.rfind(bad(c.file), 0), 0u) << text;
  }
}

TEST(LogIo, UnreadableMatFilesAreRefused) {
  for (const char* f : {"truncated.mat", "garbage.mat"}) {
    SCOPED_TRACE(f);
    LogReadResult r = readLog(bad(f));
    ASSERT_FALSE(r.ok);
    EXPECT_NE(r.error.problem.find("not a readable MATLAB .mat file"), std::string::npos)
        << r.error.toString();
  }
}

TEST(LogIo, MissingFileAndMultiGigabyteFileAreRefused) {
  LogReadResult missing = readLog("/nonexistent/robot.csv");
  ASSERT_FALSE(missing.ok);
  EXPECT_NE(missing.error.problem.find("does not exist"), std::string::npos);

  // A sparse 3 GiB file: refused from its size before anything is read.
  const fs::path big = tempDir() / "huge.csv";
  { std::ofstream(big) << "# flexarm-log: 1\n"; }
  fs::resize_file(big, 3ull << 30);
  LogReadResult r = readLog(big.string());
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.error.problem.find("3.0 GiB"), std::string::npos) << r.error.toString();
  EXPECT_NE(r.error.problem.find("larger than"), std::string::npos) << r.error.toString();
  fs::remove(big);
}

TEST(LogIo, HeaderlessTableWithMappingAndSampleTime) {
  LogReadOptions o;
  o.inputColumn = 1;
  o.outputColumn = 2;
  o.sampleTime = 0.01;
  LogReadResult r = readLog(std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat", o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.samples(), 1024u);
  EXPECT_DOUBLE_EQ(r.data.sampleTime, 0.01);
  ASSERT_NE(r.data.input(), nullptr);
  EXPECT_DOUBLE_EQ(r.data.input()->values[0], 2.2183165e-01);
  EXPECT_DOUBLE_EQ(r.data.output()->values[0], -1.7703630e-01);
  EXPECT_DOUBLE_EQ(r.data.output()->values[1023], -1.6716420e-01);
  // Swapping the mapping swaps the roles.
  o.inputColumn = 2;
  o.outputColumn = 1;
  LogReadResult s = readLog(std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat", o);
  ASSERT_TRUE(s.ok);
  EXPECT_DOUBLE_EQ(s.data.input()->values[0], -1.7703630e-01);
  // A mapping beyond the table's columns is refused.
  o.inputColumn = 3;
  LogReadResult t = readLog(std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat", o);
  ASSERT_FALSE(t.ok);
  EXPECT_NE(t.error.problem.find("uses column 3"), std::string::npos) << t.error.toString();
}

TEST(LogIo, TableWithTimeColumnChecksSampling) {
  const fs::path p = tempDir() / "timed.txt";
  {
    std::ofstream f(p);
    for (int i = 0; i < 50; ++i) f << 0.002 * i << ", " << i << ", " << -i << "\n";
  }
  LogReadOptions o;
  o.timeColumn = 1;
  o.inputColumn = 2;
  o.outputColumn = 3;
  LogReadResult r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_NEAR(r.data.sampleTime, 0.002, 1e-12);
  EXPECT_EQ(r.data.channels.size(), 2u);
}

TEST(LogIo, MatFileWithFlexArmNames) {
  const fs::path p = tempDir() / "log.mat";
  const std::size_t n = 64;
  std::vector<double> t(n), u(n), y(n), ref(n);
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = 0.0005 * i;
    u[i] = std::sin(0.1 * i);
    y[i] = 0.01 * i;
    ref[i] = 0.5;
  }
  mat_t* mat = Mat_CreateVer(p.string().c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  size_t dims[2] = {n, 1};
  auto put = [&](const char* name, std::vector<double>& v) {
    matvar_t* var = Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, v.data(), 0);
    Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
    Mat_VarFree(var);
  };
  put("time_s", t);
  put("torque_ref_nm", u);
  put("motor_angle_rad", y);
  put("angle_ref_rad", ref);
  Mat_Close(mat);
  LogReadResult r = readLog(p.string());
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.samples(), n);
  EXPECT_NEAR(r.data.sampleTime, 0.0005, 1e-12);
  EXPECT_EQ(r.data.input()->name, "torque_ref_nm");
  EXPECT_EQ(r.data.output()->values, y);
  EXPECT_TRUE(r.data.isClosedLoop());
  // The same file with the user naming a variable that is not there.
  LogReadOptions o;
  o.mapping.output = "arm_angle";
  LogReadResult m = readLog(p.string(), o);
  ASSERT_FALSE(m.ok);
  EXPECT_EQ(m.error.columnName, "arm_angle");
  EXPECT_NE(m.error.toString().find("'arm_angle' is missing"), std::string::npos);
}

// Writes double vectors (n x 1) and scalars into a new .mat file.
static void writeMat(const fs::path& p, const std::vector<std::pair<std::string, std::vector<double>>>& vars) {
  mat_t* mat = Mat_CreateVer(p.string().c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  for (const auto& [name, values] : vars) {
    std::vector<double> v = values;
    size_t dims[2] = {v.size(), 1};
    matvar_t* var = Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, v.data(), 0);
    Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
    Mat_VarFree(var);
  }
  Mat_Close(mat);
}

// Issue 14's .mat papercuts: a file without time asks for the sample time (never 1 Hz
// silently), a missing variable lists those that exist, and --output-name is honoured.
TEST(LogIo, MatFileWithoutTimeAsksForTheSampleTimeAndNamesItsVariables) {
  const fs::path p = tempDir() / "velocity.mat";
  const std::size_t n = 50;
  std::vector<double> u(n), v(n);
  for (std::size_t i = 0; i < n; ++i) {
    u[i] = std::sin(0.2 * i);
    v[i] = std::cos(0.3 * i);
  }
  const fs::path uy = tempDir() / "uy.mat";
  writeMat(uy, {{"u", u}, {"y", v}});
  LogReadResult r = readLog(uy.string());
  ASSERT_FALSE(r.ok);
  EXPECT_TRUE(r.needsSampleTime);
  EXPECT_NE(r.error.problem.find("--sample-time"), std::string::npos) << r.error.problem;

  writeMat(p, {{"tau", u}, {"motor_speed", v}});
  LogReadOptions o;
  o.sampleTime = 0.0005;
  o.mapping.input = "tau";
  o.mapping.output = "velocity";  // not in the file
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_FALSE(r.needsSampleTime);
  EXPECT_NE(r.error.problem.find("the file holds tau, motor_speed"), std::string::npos) << r.error.problem;

  // --output-name picks the variable of that name and names the channel; --input-name renames.
  o.mapping.output.clear();
  o.outputName = "motor_speed";
  o.inputName = columns::kTorqueRef;
  r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_NEAR(r.data.sampleTime, 0.0005, 1e-15);
  ASSERT_NE(r.data.output(), nullptr);
  EXPECT_EQ(r.data.output()->name, "motor_speed");
  EXPECT_EQ(r.data.output()->values, v);
  EXPECT_EQ(r.data.input()->name, columns::kTorqueRef);
  EXPECT_EQ(r.data.channels.size(), 2u);
  // A variable and a channel name of the user's choice.
  o.mapping.output = "motor_speed";
  o.outputName = columns::kMotorVelocity;
  r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.output()->name, columns::kMotorVelocity);
  EXPECT_EQ(r.data.output()->unit, "rad/s");

  // A scalar Ts in the file is its sample time.
  const fs::path q = tempDir() / "with_ts.mat";
  writeMat(q, {{"u", u}, {"y", v}, {"Ts", {0.002}}});
  r = readLog(q.string());
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_NEAR(r.data.sampleTime, 0.002, 1e-15);
  EXPECT_EQ(r.data.channels.size(), 2u);  // Ts is no channel
}
