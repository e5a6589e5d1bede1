#include "core/io/log_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/io/input_file.h"
#include "core/io/reader_support.h"

namespace flexarm {
namespace {

bool hasExtension(const std::string& path, const char* ext) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e == ext;
}

enum class Sniffed { FlexArmCsv, Table, Undecided };

// The format text names on its first lines (up to 1000): '# flexarm-log' or a first
// non-comment line of names means a FlexArm log, numbers a table. Undecided when only
// comments come before the end of the first bytes (whole: text is the whole file, and then
// a file of comments only is a FlexArm log, whose reader names the problem).
Sniffed sniffText(std::string_view text, bool whole) {
  io::LineCursor cursor(text);
  std::string_view line;
  for (int count = 0; count < 1000 && cursor.next(line); ++count) {
    if (!whole && cursor.offset() > text.size()) return Sniffed::Undecided;  // a cut line
    const std::string t = io::trim(line.substr(0, std::min<std::size_t>(line.size(), 4096)));
    if (t.empty()) continue;
    if (t[0] == '#') {
      if (t.find("flexarm-log") != std::string::npos) return Sniffed::FlexArmCsv;
      continue;
    }
    if (t[0] == '%') continue;
    const char c = t[0];
    const bool numeric = (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
    return numeric ? Sniffed::Table : Sniffed::FlexArmCsv;
  }
  return whole || cursor.offset() < text.size() ? Sniffed::FlexArmCsv : Sniffed::Undecided;
}

}  // namespace

std::string ReadError::toString() const {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": ";
  if (column > 0) {
    s += "column " + std::to_string(column);
    if (!columnName.empty()) s += " (" + columnName + ")";
    s += ": ";
  } else if (!columnName.empty()) {
    s += columnName + ": ";
  }
  return s + problem;
}

const char* toString(LogFormat f) {
  switch (f) {
    case LogFormat::Auto: return "auto";
    case LogFormat::FlexArmCsv: return "flexarm-csv";
    case LogFormat::Table: return "table";
    case LogFormat::Mat: return "mat";
  }
  return "auto";
}

bool LogReadOptions::isValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (inputColumn < 1 || outputColumn < 1) return fail("column numbers start at 1");
  if (inputColumn > kMaxColumns || outputColumn > kMaxColumns || timeColumn > kMaxColumns)
    return fail("column numbers go up to 65536");
  if (inputColumn == outputColumn) return fail("input and output must be different columns");
  if (timeColumn < 0) return fail("the time column number must be 1 or more (0 for none)");
  if (sampleTime != 0.0 && (!(sampleTime >= IdData::kMinSampleTime) || !(sampleTime <= 1e6)))
    return fail("the sample time must lie between 1e-06 s (1 MHz) and 1e+06 s");
  if (!(maxSampleJitter > 0.0)) return fail("the sampling tolerance must be positive");
  return mapping.isValid(why);
}

LogReadResult readLog(const std::string& path, const LogReadOptions& options) {
  switch (options.format) {
    case LogFormat::FlexArmCsv: return readFlexArmCsv(path, options);
    case LogFormat::Table: return readTable(path, options);
    case LogFormat::Mat: return readMat(path, options);
    case LogFormat::Auto: break;
  }
  // The file is opened once and handed to its reader. The format is sniffed from the first
  // bytes: the MATLAB magic means .mat, names on the first non-comment line a FlexArm log,
  // numbers a table; each reader then reads the file its own way (a large FlexArm log
  // straight from the file in parts, a .mat file where its structure says).
  InputFile file;
  std::string problem;
  if (!file.open(path, options.maxFileBytes, &problem)) return io::failure(path, 0, 0, {}, problem);
  if (hasExtension(path, ".mat")) return io::readMatFile(file, path, options);
  constexpr std::size_t kSniff = 64u << 10;
  std::string head(static_cast<std::size_t>(std::min<std::uint64_t>(file.size(), kSniff)), '\0');
  head.resize(file.readFully(0, head.data(), head.size()));
  if (head.compare(0, 6, "MATLAB") == 0) return io::readMatFile(file, path, options);
  switch (sniffText(head, head.size() >= file.size())) {
    case Sniffed::FlexArmCsv: return io::readFlexArmCsvFile(file, path, options);
    case Sniffed::Table: return io::readTableFile(file, path, options);
    case Sniffed::Undecided: break;
  }
  // Comments beyond the first bytes: decided on the whole text.
  FileBytes bytes;
  if (!file.readAll(bytes, &problem)) return io::failure(path, 0, 0, {}, problem);
  const std::string_view text = bytes.view();
  if (sniffText(text, true) == Sniffed::Table) return readTableText(text, path, options);
  return readFlexArmCsvText(text, path, options);  // also reports the empty or comment-only file
}

}  // namespace flexarm
