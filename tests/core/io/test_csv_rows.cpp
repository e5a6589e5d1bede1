// The rows of a FlexArm CSV log large enough to be parsed in chunks by several threads
// (core/io/csv_log_reader.cpp), with the lines only the careful path reads ('+', blanks around
// numbers, "\r\n", blank lines and comments) all through it: an empty field is a hole (NaN)
// only when irregular logs are kept, and never in the time; otherwise it is named at its line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/io/log_io.h"

namespace flexarm {
namespace {

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

// Rows enough for 4.5 MiB of text: more than one chunk of the threaded reader (over 4 MB).
// A large log's bad row and its mixed lines: tests/core/io/test_csv_fast_path.cpp.
constexpr int kRows = 150000;

TEST(CsvRows, EmptyFieldsAreHolesOnlyWhenAskedAndNeverInTheTime) {
  std::string text = logText(kRows);
  const int holeRow = kRows - 1000;  // in the last chunk
  char row[128];
  std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g\n", holeRow * 0.5, holeRow / 7.0,
                -static_cast<double>(holeRow));
  const auto at = text.find(row);
  ASSERT_NE(at, std::string::npos);
  std::snprintf(row, sizeof row, "%.17g,,%.17g\n", holeRow * 0.5, -static_cast<double>(holeRow));
  std::string withHole = text;
  withHole = text.substr(0, at) + row + text.substr(text.find('\n', at) + 1);
  const int line = 1 + static_cast<int>(std::count(withHole.begin(), withHole.begin() + static_cast<long>(at), '\n'));

  LogReadOptions keep;
  keep.keepIrregularTime = true;
  const LogReadResult holes = readFlexArmCsvText(withHole, "holes.csv", keep);
  ASSERT_TRUE(holes.ok) << holes.error.toString();
  const Channel* torque = holes.data.channel("torque_ref_nm");
  ASSERT_NE(torque, nullptr);
  EXPECT_TRUE(std::isnan(torque->values[static_cast<std::size_t>(holeRow)]));
  EXPECT_EQ(torque->values[static_cast<std::size_t>(holeRow - 1)], (holeRow - 1) / 7.0);
  EXPECT_EQ(holes.data.channel("motor_angle_rad")->values[static_cast<std::size_t>(holeRow)], -holeRow);
  EXPECT_EQ(holes.data.timeStamps.size(), static_cast<std::size_t>(kRows));

  const LogReadResult refused = readFlexArmCsvText(withHole, "holes.csv");  // holes not asked for
  ASSERT_FALSE(refused.ok);
  EXPECT_EQ(refused.error.line, line);
  EXPECT_EQ(refused.error.column, 2);
  EXPECT_EQ(refused.error.problem, "the field is empty");

  // An empty time is never a hole.
  std::snprintf(row, sizeof row, ",%.17g,%.17g\n", holeRow / 7.0, -static_cast<double>(holeRow));
  const std::string noTime = text.substr(0, at) + row + text.substr(text.find('\n', at) + 1);
  const LogReadResult timeless = readFlexArmCsvText(noTime, "holes.csv", keep);
  ASSERT_FALSE(timeless.ok);
  EXPECT_EQ(timeless.error.line, line);
  EXPECT_EQ(timeless.error.column, 1);
  EXPECT_EQ(timeless.error.problem, "the field is empty");
}

}  // namespace
}  // namespace flexarm
