// The CSV log reader's fast path and its split over threads give exactly what the careful
// line-by-line path gives: the same values, and for a bad line the same line, column and
// problem, wherever in a large file it is.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/io/log_io.h"

using namespace flexarm;

namespace {

struct Expected {
  std::string text;
  std::vector<double> t, u, y;
  std::vector<int> lineOfRow;
};

// A log of n rows (several MB for n = 200 000, so the reader splits it over threads) with the
// variants a user's file may hold: blanks around fields, '+', CRLF, blank and comment lines.
Expected makeLog(std::size_t n) {
  Expected e;
  e.text = "# flexarm-log: 1\n# sample_rate_hz: 1000\ntime_s,torque_ref_nm,motor_angle_rad\n";
  int line = 3;
  char buf[160];
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.001 * static_cast<double>(i);
    const double u = std::sin(0.001 * static_cast<double>(i)) * 1e3;
    const double y = -1.0 / (1.0 + static_cast<double>(i));
    if (i % 997 == 5) {
      e.text += "\n";
      ++line;
    }
    if (i % 1499 == 7) {
      e.text += "  # a comment among the rows\n";
      ++line;
    }
    switch (i % 5) {
      case 0: std::snprintf(buf, sizeof buf, "%.3f,%.17g,%.17g\n", t, u, y); break;
      case 1: std::snprintf(buf, sizeof buf, "%.3f, %.17g ,%.17g\r\n", t, u, y); break;
      case 2: std::snprintf(buf, sizeof buf, "%.3f,+%.17g,%.6e\n", t, std::abs(u), y); break;
      case 3: std::snprintf(buf, sizeof buf, "%.3f,%.17g,%.17g\t\n", t, u, y); break;
      default: std::snprintf(buf, sizeof buf, "%.3f,%.17g,%.17g\r\n", t, u, y); break;
    }
    e.text += buf;
    ++line;
    double tv, uv, yv;
    std::sscanf(buf, "%lf , %lf , %lf", &tv, &uv, &yv);
    e.t.push_back(tv);
    e.u.push_back(uv);
    e.y.push_back(yv);
    e.lineOfRow.push_back(line);
  }
  return e;
}

// A folder of this test process's own, removed at the end.
struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& stem)
      : path(std::filesystem::temp_directory_path() / (stem + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string f = (path / name).string();
    std::ofstream(f, std::ios::binary) << text;
    return f;
  }
};

// What reading the file gives equals what reading its text gives: values, or the error.
void expectSameAsText(const std::string& file, const std::string& text) {
  const LogReadResult fromFile = readLog(file);
  bool readWhole = false;
  EXPECT_EQ(readFlexArmCsv(file, {}, &readWhole).ok, fromFile.ok);
  EXPECT_TRUE(readWhole) << "line numbers come from the whole text";
  const LogReadResult fromText = readFlexArmCsvText(text, file);
  ASSERT_EQ(fromFile.ok, fromText.ok) << fromFile.error.toString() << " / " << fromText.error.toString();
  if (!fromText.ok) {
    EXPECT_EQ(fromFile.error.toString(), fromText.error.toString());
    return;
  }
  ASSERT_EQ(fromFile.data.samples(), fromText.data.samples());
  for (const char* name : {columns::kTorqueRef, columns::kMotorAngle})
    EXPECT_EQ(fromFile.data.channel(name)->values, fromText.data.channel(name)->values) << name;
  EXPECT_EQ(fromFile.data.sampleTime, fromText.data.sampleTime);
  EXPECT_EQ(fromFile.data.timeStamps, fromText.data.timeStamps);
}

}  // namespace

// A large log is read from the file in parts, one per thread, in pieces of a fixed size: the
// lines cut by those borders are read once and whole wherever a border falls in a line
// (before, in or after a '\r\n', in a number), and the result is the text path's.
TEST(CsvFastPath, ReadingALargeFileInPartsGivesWhatItsTextGives) {
  const Expected e = makeLog(150000);
  ASSERT_GT(e.text.size(), 4u << 20) << "large enough to be split over threads";
  const std::size_t firstRow = e.text.find("0.000,");
  ASSERT_NE(firstRow, std::string::npos);
  ScratchDir dir("flexarm_csv_parts");
  // Zeros appended to the first time stamp shift every later border by one byte: 60 shifts
  // move the borders across a whole line (about 50 bytes).
  for (int shift = 0; shift < 60; shift += 1) {
    SCOPED_TRACE(shift);
    std::string text = e.text;
    text.insert(firstRow + 5, static_cast<std::size_t>(shift), '0');
    const std::string file = dir.write("log.csv", text);
    const LogReadResult r = readLog(file);
    ASSERT_TRUE(r.ok) << r.error.toString();
    bool readWhole = true;
    ASSERT_TRUE(readFlexArmCsv(file, {}, &readWhole).ok);
    ASSERT_FALSE(readWhole) << "read from the file in parts, not again as a whole";
    ASSERT_EQ(r.data.samples(), e.t.size());
    ASSERT_EQ(r.data.channel(columns::kTorqueRef)->values, e.u);
    ASSERT_EQ(r.data.channel(columns::kMotorAngle)->values, e.y);
  }
}

// Whatever needs the whole text (a bad line's number, a sampling gap, a comment line longer
// than a piece) gives the same answer from a file as from its text.
TEST(CsvFastPath, BadLinesGapsAndLongLinesInALargeFileAnswerAsTheText) {
  const Expected e = makeLog(150000);
  ScratchDir dir("flexarm_csv_parts_bad");
  auto lineStart = [&](const std::string& text, int line) {
    std::size_t p = 0;
    for (int l = 1; l < line; ++l) p = text.find('\n', p) + 1;
    return p;
  };
  std::string bad = e.text;
  const std::size_t p1 = lineStart(bad, e.lineOfRow[120000]);
  bad.insert(bad.find(',', p1) + 1, "x");
  expectSameAsText(dir.write("bad.csv", bad), bad);

  std::string gap = e.text;
  const std::size_t p2 = lineStart(gap, e.lineOfRow[140000]);
  gap.replace(p2, gap.find(',', p2) - p2, "140.0005");
  expectSameAsText(dir.write("gap.csv", gap), gap);

  std::string longLine = e.text;
  longLine.insert(lineStart(longLine, e.lineOfRow[100000]), "# " + std::string(700000, 'c') + "\n");
  const std::string longFile = dir.write("long.csv", longLine);
  const LogReadResult r = readLog(longFile);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.samples(), e.t.size());
  EXPECT_EQ(r.data.channel(columns::kMotorAngle)->values, e.y);
  bool readWhole = true;
  ASSERT_TRUE(readFlexArmCsv(longFile, {}, &readWhole).ok);
  EXPECT_FALSE(readWhole) << "a line longer than a piece is read in parts too";
}

TEST(CsvFastPath, LargeMixedLogReadsExactlyAsWritten) {
  const Expected e = makeLog(200000);
  ASSERT_GT(e.text.size(), 6u << 20) << "large enough to be split over threads";
  const LogReadResult r = readFlexArmCsvText(e.text, "mixed.csv");
  ASSERT_TRUE(r.ok) << r.error.toString();
  ASSERT_EQ(r.data.samples(), e.t.size());
  EXPECT_EQ(r.data.channel(columns::kTorqueRef)->values, e.u);
  EXPECT_EQ(r.data.channel(columns::kMotorAngle)->values, e.y);
  EXPECT_NEAR(r.data.sampleTime, 0.001, 1e-12);
}

TEST(CsvFastPath, BadLineDeepInALargeFileIsNamedExactly) {
  Expected e = makeLog(200000);
  // Breaks row 150 000 (in a later chunk) and, separately, row 20 (in the first).
  const std::size_t row = 150000;
  const int line = e.lineOfRow[row];
  std::size_t pos = 0;
  for (int l = 1; l < line; ++l) pos = e.text.find('\n', pos) + 1;
  const std::size_t comma = e.text.find(',', pos);
  std::string late = e.text;
  late.replace(comma + 1, 0, "x");
  LogReadResult r = readFlexArmCsvText(late, "late.csv");
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.line, line) << r.error.toString();
  EXPECT_EQ(r.error.column, 2) << r.error.toString();
  EXPECT_EQ(r.error.columnName, columns::kTorqueRef);
  EXPECT_NE(r.error.problem.find("is not a number"), std::string::npos) << r.error.toString();

  // An earlier bad line wins over a later one, as in a reading from the top.
  const int early = e.lineOfRow[20];
  std::size_t p2 = 0;
  for (int l = 1; l < early; ++l) p2 = late.find('\n', p2) + 1;
  std::string both = late;
  both.insert(p2, "1,2\n");
  r = readFlexArmCsvText(both, "both.csv");
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.line, early) << r.error.toString();
  EXPECT_NE(r.error.problem.find("has 2 fields, the header has 3"), std::string::npos)
      << r.error.toString();

  // A time step that breaks the sampling late in the file names its line too.
  std::string gap = e.text;
  const int gapLine = e.lineOfRow[180000];
  std::size_t p3 = 0;
  for (int l = 1; l < gapLine; ++l) p3 = gap.find('\n', p3) + 1;
  gap.replace(p3, gap.find(',', p3) - p3, "180.0005");
  r = readFlexArmCsvText(gap, "gap.csv");
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.line, gapLine) << r.error.toString();
  EXPECT_NE(r.error.problem.find("irregular sampling"), std::string::npos) << r.error.toString();
}

TEST(CsvFastPath, NonFiniteAndOverflowingNumbersAreRefusedOnTheFastPathToo) {
  for (const char* bad : {"nan", "inf", "-inf", "1e999", "0x10", "1e", "--1", "1..2"}) {
    SCOPED_TRACE(bad);
    const std::string text = std::string("time_s,torque_ref_nm,motor_angle_rad\n0,1,2\n0.001,") +
                             bad + ",2\n0.002,1,2\n";
    const LogReadResult r = readFlexArmCsvText(text, "x.csv");
    ASSERT_FALSE(r.ok);
    EXPECT_EQ(r.error.line, 3);
    EXPECT_EQ(r.error.column, 2);
  }
}

TEST(CsvFastPath, DuplicateColumnNamesAreFoundInAWideHeader) {
  std::string header = "time_s,torque_ref_nm,motor_angle_rad";
  for (int i = 0; i < 50000; ++i) header += ",c" + std::to_string(i);
  header += ",c49999\n";
  const LogReadResult r = readFlexArmCsvText(header + "0\n", "wide.csv");
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.column, 50004);
  EXPECT_NE(r.error.problem.find("appears twice"), std::string::npos) << r.error.toString();
}

TEST(CsvFastPath, TooManyColumnsAndMetadataLinesAreRefused) {
  std::string header = "time_s,torque_ref_nm,motor_angle_rad";
  for (int i = 0; i < LogReadOptions::kMaxColumns; ++i) header += ",c" + std::to_string(i);
  LogReadResult r = readFlexArmCsvText(header + "\n", "wide.csv");
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.error.problem.find("more than 65536 columns"), std::string::npos) << r.error.toString();

  std::string meta;
  for (int i = 0; i <= LogReadOptions::kMaxMetadata; ++i) meta += "# k" + std::to_string(i) + ": v\n";
  r = readFlexArmCsvText(meta + "time_s,torque_ref_nm,motor_angle_rad\n0,1,2\n1,1,2\n", "meta.csv");
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.line, LogReadOptions::kMaxMetadata + 1);
  EXPECT_NE(r.error.problem.find("metadata lines"), std::string::npos) << r.error.toString();
}
