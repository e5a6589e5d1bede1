// Headerless numeric tables (whitespace or comma separated, '#' and '%' comments) with the
// user's column mapping, as the DaISy files come.
#include <algorithm>
#include <filesystem>
#include <tuple>

#include "core/io/input_file.h"
#include "core/io/log_io.h"
#include "core/io/reader_support.h"

namespace flexarm {

using io::failure;
using io::FieldStatus;

namespace {

// A column a mapping names in a headerless table: "column 3", "3" (1-based); 0 for empty.
bool columnOf(const std::string& text, int& column, std::string* why) {
  std::string t = io::trim(text);
  if (t.empty()) return true;
  if (t.rfind("column", 0) == 0) t = io::trim(std::string_view(t).substr(6));
  double v = 0.0;
  if (io::parseNumber(t, v) != FieldStatus::Ok || v != static_cast<int>(v) || v < 1 ||
      v > LogReadOptions::kMaxColumns) {
    if (why) *why = "'" + text + "' is not a column of a headerless table (write column 3, or 3)";
    return false;
  }
  column = static_cast<int>(v);
  return true;
}

}  // namespace

LogReadResult readTableText(std::string_view text, const std::string& path,
                            const LogReadOptions& given) {
  std::string why;
  // Columns the mapping names ("column 3") take the place of the column numbers.
  LogReadOptions options = given;
  int armColumn = 0, refColumn = 0;
  const LogMapping& m = given.mapping;
  if (!columnOf(m.input, options.inputColumn, &why) || !columnOf(m.output, options.outputColumn, &why) ||
      !columnOf(m.time, options.timeColumn, &why) || !columnOf(m.arm, armColumn, &why) ||
      !columnOf(m.reference, refColumn, &why))
    return failure(path, 0, 0, {}, "bad column mapping: " + why);
  for (const int extra : {armColumn, refColumn})
    if (extra && (extra == options.inputColumn || extra == options.outputColumn || extra == options.timeColumn ||
                  armColumn == refColumn))
      return failure(path, 0, 0, {}, "bad column mapping: the arm angle's or the reference's column is already used");
  if (!options.isValid(&why)) return failure(path, 0, 0, {}, "bad column mapping: " + why);
  if (std::string enc = textEncodingProblem(text); !enc.empty()) return failure(path, 1, 0, {}, enc);
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    return failure(path, 1, 0, {}, "the file is empty");

  io::LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> fields;
  std::vector<std::vector<double>> cols;
  std::size_t rows = 0, firstRowOffset = 0;
  int firstRowLine = 0;
  char delimiter = 0;
  const auto maxColumns = static_cast<std::size_t>(LogReadOptions::kMaxColumns);
  while (true) {
    const std::size_t lineOffset = cursor.offset();
    if (!cursor.next(line)) break;
    if (io::isBlank(line)) continue;
    std::size_t b = 0;
    while (b < line.size() && (line[b] == ' ' || line[b] == '\t')) ++b;
    if (line[b] == '#' || line[b] == '%') continue;
    if (rows == 0) delimiter = line.find(',') != std::string_view::npos ? ',' : 0;
    std::string_view body = line.substr(b);
    while (!body.empty() && (body.back() == ' ' || body.back() == '\t' || body.back() == '\r'))
      body.remove_suffix(1);
    // A trailing delimiter (as in the DaISy files' trailing tab) adds no field.
    io::splitFields(body, delimiter, fields, maxColumns);
    if (delimiter && !fields.empty() && io::trim(fields.back()).empty()) fields.pop_back();
    if (rows == 0) {
      if (fields.size() > maxColumns)
        return failure(path, cursor.number(), 0, {},
                       "the table has more than " + std::to_string(maxColumns) +
                           " columns, more than FlexArm reads");
      const int needed =
          std::max({options.inputColumn, options.outputColumn, options.timeColumn, armColumn, refColumn});
      if (static_cast<int>(fields.size()) < needed)
        return failure(path, cursor.number(), 0, {},
                       "the table has " + std::to_string(fields.size()) +
                           " columns but the mapping uses column " + std::to_string(needed));
      cols.resize(fields.size());
      // Rows take at least two bytes per column: reserve no more than the file can hold.
      const std::size_t bound = (text.size() - lineOffset) / (2 * fields.size()) + 1;
      const std::size_t lines = static_cast<std::size_t>(
          std::count(text.begin() + static_cast<std::ptrdiff_t>(lineOffset), text.end(), '\n')) + 1;
      for (auto& c : cols) c.reserve(std::min(bound, lines));
      firstRowLine = cursor.number();
      firstRowOffset = lineOffset;
    }
    if (fields.size() != cols.size())
      return failure(path, cursor.number(), 0, {},
                     "the line has " + std::string(fields.size() > maxColumns ? "more than " : "") +
                         std::to_string(std::min(fields.size(), maxColumns)) +
                         " fields, the first data line has " + std::to_string(cols.size()));
    for (std::size_t i = 0; i < fields.size(); ++i) {
      double v = 0;
      FieldStatus s = io::parseNumber(fields[i], v);
      if (s != FieldStatus::Ok) {
        if (rows == 0 && s == FieldStatus::NotNumber)
          return failure(path, cursor.number(), static_cast<int>(i + 1), {},
                         io::fieldProblem(s, fields[i]) +
                             "; a headerless table must hold numbers only (a file with a "
                             "header line should be a FlexArm CSV log)");
        return failure(path, cursor.number(), static_cast<int>(i + 1), {},
                       io::fieldProblem(s, fields[i]));
      }
      cols[i].push_back(v);
    }
    ++rows;
  }
  if (rows < 2)
    return failure(path, rows == 0 ? 1 : firstRowLine, 0, {}, "at least two rows of numbers are needed");
  IdData data;
  data.sampleTime = options.sampleTime > 0.0 ? options.sampleTime : 1.0;
  if (options.timeColumn == 0 && !(options.sampleTime > 0.0))
    data.setMeta("sample_time", "assumed 1 s: the table has no time column and no sample time was given");
  if (options.timeColumn > 0) {
    auto lineOf = [&](std::size_t row) {
      return io::lineOfRow(text, firstRowOffset, firstRowLine, row, "#%");
    };
    auto allLines = [&] { return io::linesOfRows(text, firstRowOffset, firstRowLine, "#%"); };
    LogReadResult fail;
    if (!io::checkTime(path, cols[static_cast<std::size_t>(options.timeColumn - 1)], lineOf,
                       allLines, options.timeColumn, "time", options, data, fail))
      return fail;
  }
  MappedChannels found;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const int col = static_cast<int>(i + 1);
    if (col == options.timeColumn) continue;
    const int index = static_cast<int>(data.channels.size());
    const std::string source = "column " + std::to_string(col);
    for (auto [column, slot, named] : {std::tuple<int, int*, std::string*>{options.inputColumn, &found.input, &found.inputSource},
                                      {options.outputColumn, &found.output, &found.outputSource},
                                      {armColumn, &found.arm, &found.armSource},
                                      {refColumn, &found.reference, &found.referenceSource}})
      if (col == column) {
        *slot = index;
        *named = source;
      }
    Channel c;
    if (col == options.inputColumn) {
      c.name = options.inputName;
      c.role = ChannelRole::Input;
    } else if (col == options.outputColumn) {
      c.name = options.outputName;
      c.role = ChannelRole::Output;
    } else {
      c.name = "column" + std::to_string(col);
    }
    c.unit = unitFromColumnName(c.name);
    c.values = std::move(cols[i]);
    data.channels.push_back(std::move(c));
  }
  data.setMeta("source", std::filesystem::path(path).filename().string());
  data.setMeta("format", "headerless table");
  LogReadResult ok;
  if (m != LogMapping{} && !applyMapping(data, found, m, true, ok.warnings, &why))
    return failure(path, 0, 0, {}, why);
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

LogReadResult readTable(const std::string& path, const LogReadOptions& options) {
  std::string why;
  if (!options.isValid(&why)) return failure(path, 0, 0, {}, "bad column mapping: " + why);
  InputFile file;
  if (!file.open(path, options.maxFileBytes, &why)) return failure(path, 0, 0, {}, why);
  return io::readTableFile(file, path, options);
}

LogReadResult io::readTableFile(const InputFile& file, const std::string& path, const LogReadOptions& options) {
  std::string why;
  FileBytes bytes;
  if (!file.readAll(bytes, &why)) return failure(path, 0, 0, {}, why);
  return readTableText(bytes.view(), path, options);
}

}  // namespace flexarm
