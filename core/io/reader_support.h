#pragma once
// Pieces the log readers share (internal to core/io): failures as ReadError, numbers and
// fields of a text line, line counting, and the checks of the time column.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/log_io.h"

#if __has_include(<fast_float/fast_float.h>)
#include <fast_float/fast_float.h>
#define FLEXARM_HAVE_FAST_FLOAT 1
#else
#define FLEXARM_HAVE_FAST_FLOAT 0
#endif

namespace flexarm {
class InputFile;
}

namespace flexarm::io {

// The readers on a file already open and checked: readLog opens a file once, sniffs its first
// bytes and hands it to one of these; readFlexArmCsv, readTable and readMat open and call them.
LogReadResult readFlexArmCsvFile(const InputFile& file, const std::string& path,
                                 const LogReadOptions& options, bool* readWhole = nullptr);
LogReadResult readTableFile(const InputFile& file, const std::string& path, const LogReadOptions& options);
LogReadResult readMatFile(const InputFile& file, const std::string& path, const LogReadOptions& options);

LogReadResult failure(const std::string& file, int line, int column, std::string columnName,
                      std::string problem);

std::string trim(std::string_view s);
bool isBlank(std::string_view s);
// Empty when s is UTF-8 text; otherwise where it is not, e.g. "byte 0xe9 at character 7 is
// not UTF-8 (Latin-1 text?)": names and metadata reach JSON, which holds only UTF-8.
std::string utf8Problem(std::string_view s);

// One decimal number at [first, last): the end of what was read, or nullptr when nothing
// there is a number. Every reader parses through this one primitive (fast_float when the
// build has it, std::from_chars otherwise), so the fast and the careful path agree on every
// input; an overflow gives an infinite value, which the callers refuse.
inline const char* parseDouble(const char* first, const char* last, double& value) {
#if FLEXARM_HAVE_FAST_FLOAT
  const auto r = fast_float::from_chars(first, last, value);
  return r.ec == std::errc() ? r.ptr : nullptr;
#else
  const auto r = std::from_chars(first, last, value);
  if (r.ec == std::errc::result_out_of_range) {
    value = HUGE_VAL;  // the magnitude does not matter: it is refused as not finite
    return r.ptr;
  }
  return r.ec == std::errc() ? r.ptr : nullptr;
#endif
}

enum class FieldStatus { Ok, Empty, NotNumber, NotFinite };
// A C-locale decimal, blanks around it allowed, a leading '+' allowed; finite only.
FieldStatus parseNumber(std::string_view field, double& value);
std::string fieldProblem(FieldStatus s, std::string_view field);

// Splits on the delimiter (',' for CSV) or on runs of blanks (delimiter 0). Stops after
// maxFields + 1 fields, so a hostile line costs no more than the cap.
void splitFields(std::string_view line, char delimiter, std::vector<std::string_view>& out,
                 std::size_t maxFields = LogReadOptions::kMaxColumns);

// Iterates over the lines of a text buffer, counting them from 1 ('\r' before '\n' dropped).
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}
  bool next(std::string_view& line);
  int number() const { return number_; }
  std::size_t offset() const { return pos_; }  // of the next line

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

// 1-based line number of the byte at offset.
int lineAt(std::string_view text, std::size_t offset);

// The line of data row `row` (0-based) among the lines from `offset` on (the first of them is
// line firstLine); blank lines and lines starting with one of `comments` are not rows.
int lineOfRow(std::string_view text, std::size_t offset, int firstLine, std::size_t row,
              std::string_view comments);

// Checks that times increase, are uniformly spaced within options.maxSampleJitter and are at
// least IdData::kMinSampleTime apart; fills data's sampleTime and startTime. lineOf maps a
// sample index to the line (or sample number) reported; allLines() gives them all at once
// (asked for only when the stamps are irregular). With options.keepIrregularTime, irregular
// stamps are kept in data (timeStamps, sourceLines) for a resampling step instead of refused;
// a refusal for the stamps alone sets fail.irregularTime and counts every irregularity.
template <class LineOf, class AllLines>
bool checkTime(const std::string& path, const std::vector<double>& t, LineOf lineOf,
               AllLines allLines, int timeColumn, const std::string& timeName,
               const LogReadOptions& options, IdData& data, LogReadResult& fail);

// The lines of every data row from `offset` on, in one pass (see lineOfRow).
std::vector<int> linesOfRows(std::string_view text, std::size_t offset, int firstLine,
                             std::string_view comments);

// The channel roles a FlexArm log implies: torque reference in, motor velocity (else angle)
// out, angle reference as the reference.
void assignDefaultRoles(IdData& data);

// Non-template core of checkTime: index of the first bad sample (or -1) with the problem;
// for a time that does not increase the problem is left empty (the caller names the line).
long long firstTimeProblem(const std::vector<double>& t, double jitter, std::string& problem);
std::string notIncreasingProblem(double t, int previousLine, double previous);
// With keepIrregularTime: true when t is irregular, its stamps and lines then kept in data.
bool keepIrregularTime(const std::vector<double>& t, const std::vector<int>& lines,
                       double jitter, IdData& data);
// Marks fail as refused for its time stamps and appends every irregularity, counted.
void describeTimeFailure(LogReadResult& fail, const std::vector<double>& t,
                         const std::vector<int>& lines, double jitter);

template <class LineOf, class AllLines>
bool checkTime(const std::string& path, const std::vector<double>& t, LineOf lineOf,
               AllLines allLines, int timeColumn, const std::string& timeName,
               const LogReadOptions& options, IdData& data, LogReadResult& fail) {
  const double jitter = options.maxSampleJitter;
  std::string problem;
  const long long bad = firstTimeProblem(t, jitter, problem);
  if (bad >= 0) {
    std::vector<int> lines = allLines();
    if (lines.size() != t.size()) {  // never expected: sample numbers rather than a wrong pairing
      lines.resize(t.size());
      for (std::size_t i = 0; i < lines.size(); ++i) lines[i] = static_cast<int>(std::min<std::size_t>(i + 1, 2147483647u));
    }
    if (options.keepIrregularTime && keepIrregularTime(t, lines, jitter, data)) return true;
    const auto i = static_cast<std::size_t>(bad);
    if (problem.empty()) problem = notIncreasingProblem(t[i], lineOf(i - 1), t[i - 1]);
    fail = failure(path, lineOf(i), timeColumn, timeName, problem);
    describeTimeFailure(fail, t, lines, jitter);
    return false;
  }
  const std::size_t n = t.size();
  data.startTime = n ? t[0] : 0.0;
  if (n >= 2) data.sampleTime = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  return true;
}

}  // namespace flexarm::io
