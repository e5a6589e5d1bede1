// The rows of a FlexArm CSV log read in stretches by several threads (core/io/csv_rows.h):
// the same rows, values, line numbers and first bad row as one thread reading them all, with
// the lines that are not plain rows (blank, comments, '+' signs, blanks around numbers, "\r\n")
// falling on and around the stretches' edges. And readLog on a log large enough for threads.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/io/csv_rows.h"
#include "core/io/log_io.h"

namespace flexarm {
namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  fs::path p = fs::temp_directory_path() / ("flexarm_csv_rows_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

// A log of `rows` rows of three columns (time, torque, angle), row i holding i * 0.5, i / 7
// and -i; every 37th line
// is one that only the field-by-field path reads. Returns the file's text.
std::string logText(int rows, int badRow = -1) {
  std::string text = "# flexarm-log: 1\n# sample_rate_hz: 2\ntime_s,torque_ref_nm,motor_angle_rad\n";
  char buf[128];
  for (int i = 0; i < rows; ++i) {
    switch (i % 37) {
      case 5: text += "\n"; break;                  // a blank line, then the row
      case 11: text += "  # a comment\n"; break;
      default: break;
    }
    if (i == badRow) {
      text += std::to_string(i * 0.5) + ",x" + std::to_string(i) + ",1\n";
      continue;
    }
    if (i % 37 == 17)
      std::snprintf(buf, sizeof buf, " %.17g , +%.17g,%.17g\r\n", i * 0.5, i / 7.0,
                    -static_cast<double>(i));
    else
      std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g\n", i * 0.5, i / 7.0,
                    -static_cast<double>(i));
    text += buf;
  }
  return text;
}

textio::CsvRows readRows(const fs::path& file, unsigned threads) {
  textio::LineReader reader;
  EXPECT_TRUE(reader.open(file.string()));
  std::string_view line;
  for (int i = 0; i < 3; ++i) reader.next(line);  // two comments and the header
  EXPECT_EQ(line, "time_s,torque_ref_nm,motor_angle_rad");
  return textio::readCsvRows(file.string(), reader, 3, threads);
}

TEST(CsvRows, AnyNumberOfThreadsReadsTheRowsOneThreadReads) {
  const fs::path file = tempDir() / "rows.csv";
  const int rows = 3000;
  std::ofstream(file, std::ios::binary) << logText(rows);
  const auto one = readRows(file, 1);
  ASSERT_TRUE(one.ok) << one.problem;
  ASSERT_EQ(one.lines.size(), static_cast<std::size_t>(rows));
  // Against the values written: row 17 (the one with blanks and '+'), the last row.
  EXPECT_EQ(one.columns[1][17], 17 / 7.0);
  EXPECT_EQ(one.columns[2][rows - 1], -(rows - 1.0));
  EXPECT_EQ(one.lines[0], 4);   // after two comments and the header
  EXPECT_EQ(one.lines[6], 11);  // row 5 follows a blank line
  for (unsigned threads : {2u, 3u, 7u, 64u}) {
    const auto many = readRows(file, threads);
    ASSERT_TRUE(many.ok) << many.problem;
    EXPECT_EQ(many.columns, one.columns) << threads << " threads";
    EXPECT_EQ(many.lines, one.lines) << threads << " threads";
  }
  fs::remove_all(tempDir());
}

TEST(CsvRows, TheFirstBadRowIsNamedAtItsLineWhateverTheThreads) {
  const fs::path file = tempDir() / "bad.csv";
  for (int badRow : {0, 1234, 2999}) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << logText(3000, badRow);
    const auto one = readRows(file, 1);
    ASSERT_FALSE(one.ok);
    EXPECT_EQ(one.errorColumn, 2);
    EXPECT_EQ(one.problem, "'x" + std::to_string(badRow) + "' is not a number");
    for (unsigned threads : {2u, 5u, 64u}) {
      const auto many = readRows(file, threads);
      ASSERT_FALSE(many.ok);
      EXPECT_EQ(many.errorLine, one.errorLine) << threads << " threads, row " << badRow;
      EXPECT_EQ(many.errorColumn, 2);
      EXPECT_EQ(many.problem, one.problem);
    }
    // The line number against the text itself.
    const std::string text = logText(3000, badRow);
    const auto at = text.find(",x" + std::to_string(badRow) + ",");
    EXPECT_EQ(one.errorLine, 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
  }
  fs::remove_all(tempDir());
}

TEST(CsvRows, EmptyFieldsAreHolesOnlyWhenAskedAndNeverInTheTime) {
  const fs::path file = tempDir() / "holes.csv";
  std::string text = logText(400);
  const std::string row200 = "100,28.571428571428573,-200\n";
  const auto at = text.find(row200);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, row200.size(), "100,,-200\n");  // no torque at row 200
  std::ofstream(file, std::ios::binary) << text;
  for (unsigned threads : {1u, 3u}) {
    textio::LineReader reader;
    ASSERT_TRUE(reader.open(file.string()));
    std::string_view line;
    for (int i = 0; i < 3; ++i) reader.next(line);
    const auto holes = textio::readCsvRows(file.string(), reader, 3, threads, 0);
    ASSERT_TRUE(holes.ok) << holes.problem;
    EXPECT_TRUE(holes.holes);
    EXPECT_TRUE(std::isnan(holes.columns[1][200]));
    EXPECT_EQ(holes.columns[2][200], -200.0);
    const auto refused = readRows(file, threads);  // holes not asked for
    ASSERT_FALSE(refused.ok);
    EXPECT_EQ(refused.errorColumn, 2);
    EXPECT_EQ(refused.problem, "the field is empty");
  }
  fs::remove_all(tempDir());
}

TEST(CsvRows, ALogLargeEnoughForThreadsReadsCompletely) {
  // 18 MB: two stretches of 8 MB or more (when the machine has two cores).
  const fs::path file = tempDir() / "large.csv";
  const int rows = 300000;
  const std::string badText = logText(rows, rows - 10);
  std::ofstream(file, std::ios::binary) << badText;
  LogReadResult bad = readLog(file.string());
  ASSERT_FALSE(bad.ok);
  const auto at = badText.find(",x" + std::to_string(rows - 10) + ",");
  EXPECT_EQ(bad.error.line, 1 + std::count(badText.begin(), badText.begin() + static_cast<long>(at), '\n'));
  EXPECT_EQ(bad.error.column, 2);
  EXPECT_EQ(bad.error.columnName, "torque_ref_nm");
  std::ofstream(file, std::ios::binary | std::ios::trunc) << logText(rows);
  LogReadResult r = readLog(file.string());
  ASSERT_TRUE(r.ok) << r.error.toString();
  ASSERT_EQ(r.data.samples(), static_cast<std::size_t>(rows));
  const Channel* angle = r.data.channel("motor_angle_rad");
  ASSERT_NE(angle, nullptr);
  for (int i = 0; i < rows; i += 997) EXPECT_EQ(angle->values[static_cast<std::size_t>(i)], -i);
  EXPECT_DOUBLE_EQ(r.data.sampleTime, 0.5);
  fs::remove_all(tempDir());
}

}  // namespace
}  // namespace flexarm
