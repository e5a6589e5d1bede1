// Logs as real robots store them: .mat structs of axis rows named by MATLAB expressions, with
// an object FlexArm cannot read beside them; CSV files with other column names; units, sides
// and the gear ratio said once and converted. The KUKA KR300 axes (sample_logs/kuka_kr300) are
// checked against numbers read from the file by hand.
#include <gtest/gtest.h>
#include <matio.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/io/log_io.h"
#include "core/io/log_source.h"
#include "core/io/mat_expression.h"

using namespace flexarm;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kN = 400;

fs::path tempDir() {
  fs::path p = fs::temp_directory_path() / ("flexarm_log_mapping_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

// Axis k's torque, motor position (degrees, arm side) and arm position (degrees) at sample i.
double torque(int k, std::size_t i) { return k + std::sin(0.05 * static_cast<double>(i) * k); }
double motorDeg(int k, std::size_t i) { return 10.0 * k + 0.01 * static_cast<double>(i) * k; }
double armDeg(int k, std::size_t i) { return motorDeg(k, i) - 0.001 * k; }

// Bytes of one level-5 element: tag, data, padding to 8.
void element(std::vector<unsigned char>& out, std::uint32_t type, const void* data, std::uint32_t n) {
  const auto put = [&](std::uint32_t v) {
    const auto* b = reinterpret_cast<const unsigned char*>(&v);
    out.insert(out.end(), b, b + 4);
  };
  put(type);
  put(n);
  const auto* b = static_cast<const unsigned char*>(data);
  out.insert(out.end(), b, b + n);
  while (out.size() % 8) out.push_back(0);
}

// An opaque MATLAB object as MATLAB stores a classdef object (class 17): name, "MCOS", the
// class name, then an array of what it holds; appended to a level-5 file.
void appendOpaque(const fs::path& p, const char* name, const char* className) {
  std::vector<unsigned char> body;
  const std::uint32_t flags[2] = {17, 0};
  element(body, 6, flags, 8);
  element(body, 1, name, static_cast<std::uint32_t>(std::strlen(name)));
  element(body, 1, "MCOS", 4);
  element(body, 1, className, static_cast<std::uint32_t>(std::strlen(className)));
  std::vector<unsigned char> inner;  // a 1 x 2 uint32 array
  const std::uint32_t innerFlags[2] = {13, 0};
  const std::int32_t dims[2] = {1, 2};
  const std::uint32_t values[2] = {0xdd000000u, 2};
  element(inner, 6, innerFlags, 8);
  element(inner, 5, dims, 8);
  element(inner, 1, "", 0);
  element(inner, 6, values, 8);
  element(body, 14, inner.data(), static_cast<std::uint32_t>(inner.size()));
  std::vector<unsigned char> whole;
  element(whole, 14, body.data(), static_cast<std::uint32_t>(body.size()));
  std::ofstream f(p, std::ios::binary | std::ios::app);
  f.write(reinterpret_cast<const char*>(whole.data()), static_cast<std::streamsize>(whole.size()));
}

matvar_t* doubles(const char* name, std::size_t rows, std::size_t cols, const std::vector<double>& v) {
  std::size_t dims[2] = {rows, cols};
  return Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(v.data()), 0);
}

// A log as a MATLAB user stores it: struct `rec` with time_cont (1 x N) and 3 x N axis rows,
// a N x 3 matrix `data`, a struct array `runs` and a cell `c`, and the opaque object KR300.
fs::path writeRobotMat(matio_compression compression) {
  const fs::path p = tempDir() / (compression == MAT_COMPRESSION_NONE ? "robot.mat" : "robot_z.mat");
  mat_t* mat = Mat_CreateVer(p.string().c_str(), nullptr, MAT_FT_MAT5);
  EXPECT_NE(mat, nullptr);
  std::vector<double> t(kN), tau(3 * kN), mot(3 * kN), arm(3 * kN), data(3 * kN);
  for (std::size_t i = 0; i < kN; ++i) {
    t[i] = 0.004 * static_cast<double>(i);
    for (int k = 1; k <= 3; ++k) {
      const std::size_t at = (i * 3) + static_cast<std::size_t>(k - 1);  // column-major, 3 rows
      tau[at] = torque(k, i);
      mot[at] = motorDeg(k, i);
      arm[at] = armDeg(k, i);
      data[static_cast<std::size_t>(k - 1) * kN + i] = 100.0 * k + static_cast<double>(i);  // N x 3
    }
  }
  const char* recFields[] = {"time_cont", "act_torque_abs_nm", "act_pos_mot_deg", "act_pos_se_deg"};
  std::size_t one[2] = {1, 1};
  matvar_t* rec = Mat_VarCreateStruct("rec", 2, one, recFields, 4);
  Mat_VarSetStructFieldByName(rec, "time_cont", 0, doubles(nullptr, 1, kN, t));
  Mat_VarSetStructFieldByName(rec, "act_torque_abs_nm", 0, doubles(nullptr, 3, kN, tau));
  Mat_VarSetStructFieldByName(rec, "act_pos_mot_deg", 0, doubles(nullptr, 3, kN, mot));
  Mat_VarSetStructFieldByName(rec, "act_pos_se_deg", 0, doubles(nullptr, 3, kN, arm));
  EXPECT_EQ(Mat_VarWrite(mat, rec, compression), 0);
  Mat_VarFree(rec);
  matvar_t* m = doubles("data", kN, 3, data);
  EXPECT_EQ(Mat_VarWrite(mat, m, compression), 0);
  Mat_VarFree(m);
  const char* runFields[] = {"q"};
  std::size_t two[2] = {1, 2};
  matvar_t* runs = Mat_VarCreateStruct("runs", 2, two, runFields, 1);
  std::vector<double> q1(kN, 1.0), q2(kN);
  for (std::size_t i = 0; i < kN; ++i) q2[i] = -static_cast<double>(i);
  Mat_VarSetStructFieldByName(runs, "q", 0, doubles(nullptr, kN, 1, q1));
  Mat_VarSetStructFieldByName(runs, "q", 1, doubles(nullptr, kN, 1, q2));
  EXPECT_EQ(Mat_VarWrite(mat, runs, compression), 0);
  Mat_VarFree(runs);
  matvar_t* cells[2] = {doubles(nullptr, 1, 3, {1, 2, 3}), doubles(nullptr, kN, 1, q2)};
  matvar_t* c = Mat_VarCreate("c", MAT_C_CELL, MAT_T_CELL, 2, two, cells, 0);
  EXPECT_EQ(Mat_VarWrite(mat, c, compression), 0);
  Mat_VarFree(c);
  Mat_Close(mat);
  appendOpaque(p, "KR300", "SerialLink");
  return p;
}

LogReadOptions axis(int k) {
  LogReadOptions o;
  const std::string row = "(" + std::to_string(k) + ",:)";
  o.mapping.time = "rec.time_cont";
  o.mapping.input = "rec.act_torque_abs_nm" + row;
  o.mapping.output = "rec.act_pos_mot_deg" + row;
  o.mapping.arm = "rec.act_pos_se_deg" + row;
  return o;
}

bool anyContains(const std::vector<std::string>& list, const std::string& text) {
  for (const auto& s : list)
    if (s.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(MatExpression, ParsesFieldsSubscriptsAndEnd) {
  std::string why;
  auto e = parseMatExpression(" rec.act_torque_abs_nm(1,:) ", &why);
  ASSERT_TRUE(e) << why;
  EXPECT_EQ(e->variable, "rec");
  ASSERT_EQ(e->steps.size(), 2u);
  EXPECT_EQ(e->steps[0].field, "act_torque_abs_nm");
  ASSERT_EQ(e->steps[1].subscripts.size(), 2u);
  EXPECT_EQ(e->steps[1].subscripts[0].first, 1);
  EXPECT_TRUE(e->steps[1].subscripts[1].all);
  e = parseMatExpression("q(end-9:end, 3)", &why);
  ASSERT_TRUE(e) << why;
  EXPECT_TRUE(e->steps[0].subscripts[0].firstFromEnd);
  EXPECT_EQ(e->steps[0].subscripts[0].first, 9);
  EXPECT_EQ(channelNameFor("rec.act_torque_abs_nm(1,:)"), "rec_act_torque_abs_nm_1");
  EXPECT_EQ(channelNameFor("data(:,2)"), "data_2");
  for (const char* bad : {"rec.(1)", "rec.tau(1,:", "1rec", "rec.tau(1.5,:)", "rec..x", "rec.tau(1:2:9)"})
    EXPECT_FALSE(parseMatExpression(bad, &why)) << bad;
  EXPECT_FALSE(parseMatExpression("rec.tau(1,:", &why));
  EXPECT_NE(why.find("expected ')' at character 12"), std::string::npos) << why;
}

TEST(LogMapping, StructRowsColumnsElementsAndCellsReadByExpressions) {
  for (matio_compression z : {MAT_COMPRESSION_NONE, MAT_COMPRESSION_ZLIB}) {
    SCOPED_TRACE(z == MAT_COMPRESSION_NONE ? "uncompressed" : "compressed");
    const fs::path p = writeRobotMat(z);
    for (int k = 1; k <= 3; ++k) {
      const LogReadResult r = readLog(p.string(), axis(k));
      ASSERT_TRUE(r.ok) << r.error.toString();
      ASSERT_EQ(r.data.samples(), kN);
      EXPECT_NEAR(r.data.sampleTime, 0.004, 1e-12);
      ASSERT_TRUE(r.data.input() && r.data.output());
      EXPECT_EQ(r.data.input()->values[123], torque(k, 123));
      EXPECT_EQ(r.data.output()->values[kN - 1], motorDeg(k, kN - 1));
      const Channel* arm = r.data.channel(columns::kArmAngle);
      ASSERT_NE(arm, nullptr);
      EXPECT_EQ(arm->values[7], armDeg(k, 7));  // --arm-unit not said: taken in rad, as stored
      // The object beside the signals is skipped and named, the file is not refused.
      EXPECT_TRUE(anyContains(r.warnings, "skipped KR300 (a MATLAB object of class SerialLink)"));
      EXPECT_TRUE(anyContains(r.warnings, "the output rec.act_pos_mot_deg(" + std::to_string(k) + ",:) is read as stored"));
      EXPECT_TRUE(anyContains(r.warnings, "the arm angle rec.act_pos_se_deg(" + std::to_string(k) + ",:) is taken in rad"));
      EXPECT_EQ(r.data.meta("skipped"), "KR300 (a MATLAB object of class SerialLink)");
    }
    // A column of a matrix, an element of a struct array, a cell, `end`.
    LogReadOptions o;
    o.sampleTime = 0.001;
    o.mapping.input = "data(:,2)";
    o.mapping.output = "runs(2).q";
    LogReadResult r = readLog(p.string(), o);
    ASSERT_TRUE(r.ok) << r.error.toString();
    EXPECT_EQ(r.data.input()->name, "data_2");
    EXPECT_EQ(r.data.input()->values[5], 205.0);
    EXPECT_EQ(r.data.output()->values[5], -5.0);
    o.mapping.input = "data(end-99:end, 3)";
    o.mapping.output = "c{2}(end-99:end)";
    r = readLog(p.string(), o);
    ASSERT_TRUE(r.ok) << r.error.toString();
    ASSERT_EQ(r.data.samples(), 100u);
    EXPECT_EQ(r.data.input()->values[0], 300.0 + kN - 100);
    EXPECT_EQ(r.data.output()->values[99], -static_cast<double>(kN - 1));
  }
  fs::remove_all(tempDir());
}

TEST(LogMapping, BadExpressionsNameTheFileTheExpressionAndTheProblem) {
  const fs::path p = writeRobotMat(MAT_COMPRESSION_NONE);
  struct Case {
    std::string output, expected;
  };
  const Case cases[] = {
      {"rec.act_pos_mot_deg(4,:)", "'rec.act_pos_mot_deg' row 4 is outside 1..3"},
      {"rec.act_pos_mot_deg", "is a 3 x 400 array: name a row or a column, e.g. rec.act_pos_mot_deg(1,:)"},
      {"rec.nope", "'rec' has no field 'nope'; its fields are time_cont, act_torque_abs_nm, act_pos_mot_deg, act_pos_se_deg"},
      {"rec.act_pos_mot_deg(1,:", "not an expression FlexArm reads (expected ')' at character 24)"},
      {"KR300.links", "'KR300' is a MATLAB object of class SerialLink, which FlexArm does not read"},
      {"runs.q", "'runs' is a 1 x 2 struct array: name one element, e.g. runs(1).q"},
      {"c(2)", "'c' is a cell array: name a cell with braces, e.g. c{1}"},
      {"data(1:2,1:2)", "names a block of data, not one signal"},
      {"rec", "'rec' is a struct: name one of its fields"},
      {"missing(1,:)", "the variable 'missing' is missing; the file holds rec, data, runs, c"},
  };
  for (const Case& c : cases) {
    LogReadOptions o = axis(1);
    o.mapping.output = c.output;
    const LogReadResult r = readLog(p.string(), o);
    ASSERT_FALSE(r.ok) << c.output;
    const std::string text = r.error.toString();
    EXPECT_EQ(text.rfind(p.string() + ": ", 0), 0u) << text;
    EXPECT_NE(text.find(c.expected), std::string::npos) << text;
  }
  fs::remove_all(tempDir());
}

// Units, the side and the gear ratio: the motor angle is the arm-side degrees times u in rad,
// the arm angle stays on the arm side, the input is scaled; all recorded in the metadata.
TEST(LogMapping, UnitsSidesAndGearRatioAreConvertedAndRecorded) {
  const fs::path p = writeRobotMat(MAT_COMPRESSION_NONE);
  LogReadOptions o = axis(2);
  o.mapping.outputUnit = SignalUnit::Deg;
  o.mapping.outputSide = EncoderSide::Arm;
  o.mapping.armUnit = SignalUnit::Deg;
  o.mapping.gearRatio = "1/50";
  o.mapping.inputScale = 2.0;
  LogReadResult r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  const Channel* motor = r.data.channel(columns::kMotorAngle);
  const Channel* arm = r.data.channel(columns::kArmAngle);
  const Channel* in = r.data.channel(columns::kTorqueRef);
  ASSERT_TRUE(motor && arm && in);
  EXPECT_EQ(r.data.output(), motor);
  EXPECT_EQ(r.data.input(), in);
  EXPECT_EQ(motor->unit, "rad");
  for (std::size_t i : {std::size_t{0}, std::size_t{250}}) {
    EXPECT_NEAR(motor->values[i], motorDeg(2, i) * 50.0 * kPi / 180.0, 1e-12 * std::abs(motor->values[i]));
    EXPECT_NEAR(arm->values[i], armDeg(2, i) * kPi / 180.0, 1e-15);
    EXPECT_EQ(in->values[i], 2.0 * torque(2, i));
  }
  EXPECT_NEAR(std::stod(r.data.meta("gear_ratio")), 0.02, 1e-15);
  EXPECT_EQ(r.data.meta("axis"), "rotary");
  EXPECT_NE(r.data.meta("import").find("in deg on the arm side, times 50 (gear ratio 1/50)"), std::string::npos)
      << r.data.meta("import");
  EXPECT_FALSE(anyContains(r.warnings, "is taken"));
  EXPECT_FALSE(anyContains(r.warnings, "no gear ratio"));

  // An arm side without a gear ratio is refused; a unit without a gear ratio is a warning.
  o.mapping.gearRatio.clear();
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.error.problem.find("needs the gear ratio"), std::string::npos) << r.error.problem;
  o.mapping.outputSide = EncoderSide::Motor;
  r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_TRUE(anyContains(r.warnings, "no gear ratio was given"));
  EXPECT_EQ(r.data.output()->values[3], motorDeg(2, 3) * kPi / 180.0);

  // A prismatic axis: millimetres to metres, the input a force.
  o.mapping.outputUnit = SignalUnit::Mm;
  o.mapping.outputSide.reset();
  o.mapping.arm.clear();
  o.mapping.armUnit.reset();
  r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  ASSERT_NE(r.data.channel(columns::kMotorPosition), nullptr);
  EXPECT_EQ(r.data.output()->name, columns::kMotorPosition);
  EXPECT_EQ(r.data.input()->name, columns::kForceRef);
  EXPECT_EQ(r.data.input()->unit, "N");
  EXPECT_NEAR(r.data.output()->values[9], motorDeg(2, 9) * 1e-3, 1e-15);
  EXPECT_EQ(r.data.meta("axis"), "prismatic");
  EXPECT_FALSE(anyContains(r.warnings, "gear ratio"));

  // Gear ratios as the user writes them.
  std::string why;
  EXPECT_NEAR(parseGearRatio("1/256.86", &why).value_or(0), 1 / 256.86, 1e-18);
  EXPECT_NEAR(parseGearRatio(" 0.0085 ", &why).value_or(0), 0.0085, 1e-18);
  for (const char* bad : {"", "0", "-1/3", "1/0", "abc", "1/2/3"}) EXPECT_FALSE(parseGearRatio(bad, &why)) << bad;
  // Motor turns per arm turn, as datasheets write it, is refused by the mapping with its inverse.
  EXPECT_EQ(invertedGearRatio("256.86"), "1/256.86");
  EXPECT_EQ(invertedGearRatio(" 1/118 "), "118");
  EXPECT_EQ(invertedGearRatio("10/3"), "3/10");
  EXPECT_EQ(invertedGearRatio("-2"), "");
  LogMapping m;
  m.gearRatio = "256.86";
  EXPECT_FALSE(m.isValid(&why));
  EXPECT_NE(why.find("above 1"), std::string::npos) << why;
  EXPECT_NE(why.find("1/256.86"), std::string::npos) << why;
  m.gearRatio = "1";  // a direct drive
  EXPECT_TRUE(m.isValid(&why)) << why;
  m.gearRatio = invertedGearRatio("256.86");
  EXPECT_TRUE(m.isValid(&why)) << why;
  fs::remove_all(tempDir());
}

// The KUKA KR300 file as published, axes 1-3 (rows of rec), with the gear ratios u of its
// README: motor angle = arm-side degrees x u in rad. The numbers at sample 1001 were read
// from the file independently of FlexArm.
TEST(LogMapping, KukaAxesReadWithUnitsSidesAndGearRatio) {
  const std::string path = std::string(FLEXARM_SAMPLE_DIR) + "/kuka_kr300/rec_B_data.mat";
  const double u[3] = {256.86, 267.43, 252.33};
  const double motDeg[3] = {-28.563801687531093, -6.402619697648896, -22.265377777092645};
  const double seDeg[3] = {-28.631050656665067, -6.331509595658599, -22.06368389539161};
  const double tauNm[3] = {1.6193037033081055, -13.719049453735352, -15.823418617248535};
  const double refDeg[3] = {-28.40386962890625, -6.26862907409668, -21.86353874206543};
  for (int k = 1; k <= 3; ++k) {
    SCOPED_TRACE("axis " + std::to_string(k));
    LogReadOptions o = axis(k);
    o.mapping.outputUnit = SignalUnit::Deg;
    o.mapping.outputSide = EncoderSide::Arm;
    o.mapping.armUnit = SignalUnit::Deg;
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "1/%.2f", u[k - 1]);
    o.mapping.gearRatio = ratio;
    o.mapping.reference = "rec.ref_pos_deg(" + std::to_string(k) + ",:)";
    const LogReadResult r = readLog(path, o);
    ASSERT_TRUE(r.ok) << r.error.toString();
    EXPECT_EQ(r.data.samples(), 2501u);
    EXPECT_NEAR(r.data.sampleTime, 0.004, 1e-9);
    const std::size_t i = 1000;
    EXPECT_NEAR(r.data.channel(columns::kMotorAngle)->values[i], motDeg[k - 1] * u[k - 1] * kPi / 180.0, 1e-9);
    EXPECT_NEAR(r.data.channel(columns::kArmAngle)->values[i], seDeg[k - 1] * kPi / 180.0, 1e-14);
    EXPECT_EQ(r.data.channel(columns::kTorqueRef)->values[i], tauNm[k - 1]);
    // The reference takes the output's unit and side: motor side in rad, and the log is closed loop.
    ASSERT_NE(r.data.channel(columns::kAngleRef), nullptr);
    EXPECT_NEAR(r.data.channel(columns::kAngleRef)->values[i], refDeg[k - 1] * u[k - 1] * kPi / 180.0, 1e-9);
    EXPECT_TRUE(r.data.isClosedLoop());
    EXPECT_NEAR(std::stod(r.data.meta("gear_ratio")), 1.0 / u[k - 1], 1e-12);
    EXPECT_TRUE(anyContains(r.warnings, "skipped KR300 (a MATLAB object of class SerialLink)"));
  }
  // Axis 1 at sample 1001: -28.5638 deg on the arm side is -128.05 rad at the motor.
  LogReadOptions o = axis(1);
  o.mapping.outputUnit = SignalUnit::Deg;
  o.mapping.outputSide = EncoderSide::Arm;
  o.mapping.gearRatio = "1/256.86";
  const LogReadResult r = readLog(path, o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_NEAR(r.data.output()->values[1000], -128.05, 0.01);
  // The file's listing: the struct's fields with their shapes, the object marked skipped.
  const SourceListing listing = listLogSource(path);
  ASSERT_TRUE(listing.ok) << listing.error.toString();
  const SourceEntry* rec = nullptr;
  const SourceEntry* object = nullptr;
  for (const auto& e : listing.entries) {
    if (e.label == "rec") rec = &e;
    if (e.label == "KR300") object = &e;
  }
  ASSERT_TRUE(rec && object);
  EXPECT_EQ(object->unreadable, "a MATLAB object of class SerialLink");
  bool torqueListed = false;
  for (const auto& f : rec->children)
    if (f.expression == "rec.act_torque_abs_nm") {
      torqueListed = true;
      EXPECT_EQ(f.shape, "6 x 2501");
      EXPECT_EQ(f.kind, "double");
      EXPECT_TRUE(f.numeric);
      EXPECT_EQ(f.rows, 6u);
    }
  EXPECT_TRUE(torqueListed);
  const SeriesRead row = readSourceSeries(path, listing, "rec.act_pos_se_deg(2,:)");
  ASSERT_TRUE(row.ok) << row.error.toString();
  EXPECT_EQ(row.values[1000], seDeg[1]);
}

// A CSV file with other column names is mapped by header name, converted, and without a
// mapping refused with the names it has (and marked for the import dialog).
TEST(LogMapping, CsvWithOtherColumnNamesIsMappedByHeaderName) {
  const fs::path p = tempDir() / "other_names.csv";
  {
    std::ofstream f(p);
    f << "# robot: test bench\nt_s,torque_motor_Nm,pos_motor_deg_linkside,pos_link_deg,pos_cmd_deg_linkside\n";
    for (int i = 0; i < 50; ++i)
      f << 0.001 * i << "," << 0.5 * i << "," << 0.1 * i << "," << 0.1 * i - 0.002 << "," << 0.1 * i + 0.01 << "\n";
  }
  LogReadResult r = readLog(p.string());
  ASSERT_FALSE(r.ok);
  EXPECT_TRUE(r.needsMapping);
  EXPECT_NE(r.error.toString().find("the header has t_s, torque_motor_Nm, pos_motor_deg_linkside, pos_link_deg, "
                                    "pos_cmd_deg_linkside"),
            std::string::npos)
      << r.error.toString();
  LogReadOptions o;
  o.mapping.time = "t_s";
  o.mapping.input = "torque_motor_Nm";
  o.mapping.output = "pos_motor_deg_linkside";
  o.mapping.arm = "pos_link_deg";
  o.mapping.outputUnit = SignalUnit::Deg;
  o.mapping.outputSide = EncoderSide::Arm;
  o.mapping.armUnit = SignalUnit::Deg;
  o.mapping.gearRatio = "1/100";
  o.mapping.reference = "pos_cmd_deg_linkside";
  r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_NEAR(r.data.sampleTime, 0.001, 1e-12);
  ASSERT_TRUE(r.data.isClosedLoop());
  EXPECT_EQ(r.data.withRole(ChannelRole::Reference)->name, columns::kAngleRef);
  EXPECT_NEAR(r.data.channel(columns::kAngleRef)->values[10], (1.0 + 0.01) * 100 * kPi / 180, 1e-12);
  EXPECT_EQ(r.data.input()->name, columns::kTorqueRef);
  EXPECT_EQ(r.data.input()->values[4], 2.0);
  EXPECT_EQ(r.data.output()->name, columns::kMotorAngle);
  EXPECT_NEAR(r.data.output()->values[10], 1.0 * 100 * kPi / 180, 1e-12);
  EXPECT_NEAR(r.data.channel(columns::kArmAngle)->values[10], (1.0 - 0.002) * kPi / 180, 1e-15);
  EXPECT_EQ(r.data.meta("robot"), "test bench");
  EXPECT_TRUE(r.warnings.empty());
  // One column cannot be two signals.
  LogReadOptions twice = o;
  twice.mapping.reference = twice.mapping.output;
  r = readLog(p.string(), twice);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.error.problem.find("pos_motor_deg_linkside is named for two parts"), std::string::npos) << r.error.problem;
  // A name that is not in the header is named.
  o.mapping.arm = "pos_arm_deg";
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.error.toString().find("the column 'pos_arm_deg' that --arm-var names is not in the header"),
            std::string::npos)
      << r.error.toString();
  // The listing gives the header names and every column's values.
  const SourceListing listing = listLogSource(p.string());
  ASSERT_TRUE(listing.ok) << listing.error.toString();
  ASSERT_EQ(listing.entries.size(), 5u);
  EXPECT_EQ(listing.entries[2].expression, "pos_motor_deg_linkside");
  EXPECT_EQ(listing.columns[3][10], 1.0 - 0.002);
  fs::remove_all(tempDir());
}

// A headerless table's columns are named "column N" by the same mapping.
TEST(LogMapping, TableColumnsMappedByNumberWithUnits) {
  const fs::path p = tempDir() / "table.dat";
  {
    std::ofstream f(p);
    for (int i = 0; i < 20; ++i) f << 0.01 * i << " " << 2.0 * i << " " << 1.0 * i << " " << 0.5 * i << "\n";
  }
  LogReadOptions o;
  o.mapping.time = "column 1";
  o.mapping.input = "column 3";
  o.mapping.output = "4";
  o.mapping.outputUnit = SignalUnit::Rev;
  const LogReadResult r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_NEAR(r.data.sampleTime, 0.01, 1e-12);
  EXPECT_EQ(r.data.input()->values[6], 6.0);
  EXPECT_NEAR(r.data.output()->values[6], 3.0 * 2 * kPi, 1e-12);
  EXPECT_EQ(r.data.output()->name, columns::kMotorAngle);
  fs::remove_all(tempDir());
}
