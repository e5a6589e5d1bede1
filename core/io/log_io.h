#pragma once
// Reading and writing robot logs: the FlexArm CSV log (shared/notes/log-format.md),
// headerless numeric tables with a user column mapping, and MATLAB .mat files.
// Bad input never throws and never yields partial data: the result carries a ReadError
// naming the file, the line and column (or variable) and the problem.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/signal/id_data.h"

namespace flexarm {

struct ReadError {
  std::string file;
  int line = 0;             // 1-based; 0 when the problem is not on one line
  int column = 0;           // 1-based field number; 0 when not about one field
  std::string columnName;   // header name or .mat variable, when known
  std::string problem;      // a sentence, e.g. "'abc' is not a number"
  // "file:line: column 3 (torque_ref_nm): 'abc' is not a number"
  std::string toString() const;
};

struct LogReadResult {
  bool ok = false;
  IdData data;
  ReadError error;
  // Refused for its time stamps (jitter, gaps, duplicates, reversals) alone: read with
  // LogReadOptions::keepIrregularTime, the log opens for an explicit resampling step.
  bool irregularTime = false;
  // Refused because the file stores no time and no sample time was given (a .mat file
  // without time_s or a scalar Ts/dt/sample_time): read again with LogReadOptions::sampleTime.
  bool needsSampleTime = false;
};

enum class LogFormat { Auto, FlexArmCsv, Table, Mat };
const char* toString(LogFormat f);

struct LogReadOptions {
  static constexpr int kMaxColumns = 65536;    // columns of a CSV log or table
  static constexpr int kMaxMetadata = 1000;    // "# key: value" lines of a CSV log
  LogFormat format = LogFormat::Auto;  // Auto: .mat by extension or magic, CSV with header
                                       // when the first data line is not numeric, else Table
  std::uint64_t maxFileBytes = 2ull << 30;  // larger files are refused with a clear message
  double maxSampleJitter = 0.01;            // relative deviation from the mean interval
  // Keep irregular time stamps (IdData::timeStamps) instead of refusing them, and read an
  // empty field of a FlexArm CSV log as "not sampled here" (NaN): for resampling onto a
  // uniform grid (core/signal/uniform_grid.h), the step such data need before analysis.
  bool keepIrregularTime = false;

  // Headerless tables and .mat files without FlexArm names: which column (1-based) or
  // variable is the input u and the output y, an optional time column, and the sample time
  // used when there is no time column. sampleTime 0: not given; a table then takes 1 s (and
  // says so in its "sample_time" metadata), a .mat file without time is refused with a
  // sentence asking for it (LogReadResult::needsSampleTime).
  int inputColumn = 1;
  int outputColumn = 2;
  int timeColumn = 0;  // 0: none, use sampleTime
  double sampleTime = 0.0;
  // Channel names of the input and output; a .mat file's channels keep their variable names
  // unless these differ from the defaults u and y, and a .mat variable named like outputName
  // (inputName) is the output (input) when outputVariable (inputVariable) is empty.
  std::string inputName = "u";
  std::string outputName = "y";
  std::string inputVariable;   // .mat: variable holding u (default: torque_ref_nm or u)
  std::string outputVariable;  // .mat: variable holding y (default: motor_angle_rad or y)

  bool isValid(std::string* why) const;
};

// Reads any supported log; see LogReadOptions::format. Only regular files are read (a device
// or pipe is refused before reading), never more than options.maxFileBytes, and memory stays
// within a few times the file's size.
LogReadResult readLog(const std::string& path, const LogReadOptions& options = {});
// A large FlexArm log is parsed straight from the file in parts; whatever needs the text
// whole (a small file, a bad line's number, irregular time) reads it whole. readWhole, when
// given, says which way was taken.
LogReadResult readFlexArmCsv(const std::string& path, const LogReadOptions& options = {},
                             bool* readWhole = nullptr);
LogReadResult readTable(const std::string& path, const LogReadOptions& options = {});
LogReadResult readMat(const std::string& path, const LogReadOptions& options = {});
// The same readers on text already in memory; `name` is what messages call the file.
LogReadResult readFlexArmCsvText(std::string_view text, const std::string& name,
                                 const LogReadOptions& options = {});
LogReadResult readTableText(std::string_view text, const std::string& name,
                            const LogReadOptions& options = {});

// Writes data in the FlexArm CSV format (metadata, header, time column, every channel).
// The file is written to a temporary sibling and renamed, so a failure leaves any previous
// file untouched. Returns false and fills error on failure.
bool writeFlexArmCsv(const IdData& data, const std::string& path, ReadError* error = nullptr);

// Writes text to path atomically, the one way FlexArm writes any file: a temporary sibling
// created exclusively (O_EXCL | O_NOFOLLOW) under an unpredictable name in path's folder,
// written, flushed to the disk and then renamed over path. Refuses to replace anything but a
// regular file (a symbolic link, a device such as /dev/full, a pipe, a directory), and
// reports every write error (disk full, quota) with the previous file left as it was.
bool writeFileAtomically(const std::string& path, const std::string& text, std::string* why);
// The same with the text produced piecewise: produce(sink) calls sink(bytes) any number of
// times, so a large file never has to be held in memory whole.
bool writeFileAtomically(const std::string& path,
                         const std::function<void(const std::function<void(std::string_view)>&)>& produce,
                         std::string* why);

}  // namespace flexarm
