// The FlexArm CSV log reader (shared/notes/log-format.md). Metadata and header are read line
// by line with every check; the data rows, nearly all of the file, go through a fast path
// that only parses numbers and finds the expected delimiters, split over threads. A line the
// fast path does not recognise (blanks, '+', a comment, anything wrong) is handed to the
// careful path, which accepts it or names the exact problem, so both give the same result.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>
#include <unordered_set>

#include "core/io/input_file.h"
#include "core/io/log_io.h"
#include "core/io/reader_support.h"

namespace flexarm {
namespace {

using io::failure;
using io::FieldStatus;

struct RowError {
  std::size_t lineStart = 0;  // byte offset of the line
  int column = 0;
  std::string problem;
};

// The careful path for one line: skips blank and comment lines (returns false with no error),
// else parses nCols numbers into values. False with err.problem set on a bad line.
// With holesAt >= 0 (a log read for resampling), an empty field in any column but that one
// (the time) is "not sampled here": NaN, and holes is set.
bool parseLineCarefully(std::string_view line, std::size_t nCols, std::vector<std::string_view>& fields,
                        double* values, RowError& err, bool& isRow, long holesAt, bool& holes) {
  isRow = false;
  if (io::isBlank(line)) return true;
  std::size_t b = 0;
  while (b < line.size() && (line[b] == ' ' || line[b] == '\t')) ++b;
  if (line[b] == '#') return true;
  isRow = true;
  const auto cap = static_cast<std::size_t>(LogReadOptions::kMaxColumns);
  io::splitFields(line, ',', fields, cap);
  if (fields.size() != nCols) {
    err.problem = "the line has " + std::string(fields.size() > cap ? "more than " : "") +
                  std::to_string(std::min(fields.size(), cap)) + " fields, the header has " +
                  std::to_string(nCols);
    return false;
  }
  for (std::size_t i = 0; i < nCols; ++i) {
    FieldStatus s = io::parseNumber(fields[i], values[i]);
    if (s == FieldStatus::Empty && holesAt >= 0 && static_cast<long>(i) != holesAt) {
      values[i] = std::nan("");
      holes = true;
      continue;
    }
    if (s != FieldStatus::Ok) {
      err.column = static_cast<int>(i + 1);
      err.problem = io::fieldProblem(s, fields[i]);
      return false;
    }
  }
  return true;
}

// Parses the data lines of [begin, end) (whole lines) into its own columns.
struct Chunk {
  const char* begin = nullptr;
  const char* end = nullptr;
  std::vector<std::vector<double>> cols;
  bool failed = false;
  bool holes = false;  // a channel not sampled on some row (NaN there)
  RowError error;
};

void parseChunk(Chunk& c, const char* textStart, std::size_t nCols, std::size_t reserve,
                long holesAt) {
  c.cols.resize(nCols);
  for (auto& col : c.cols) {
    col.reserve(reserve);  // address space only: pages come on use
    preferHugePages(col.data(), reserve * sizeof(double));
  }
  std::vector<double> row(nCols);
  std::vector<std::string_view> fields;
  const char* p = c.begin;
  const char* const end = c.end;
  while (p < end) {
    const char* const lineStart = p;
    // Fast path: number, ',', number, ..., number, end of line. No blanks, no '+'.
    bool fast = true;
    for (std::size_t i = 0; i < nCols; ++i) {
      const char* q = io::parseDouble(p, end, row[i]);
      if (!q || !std::isfinite(row[i])) {
        fast = false;
        break;
      }
      p = q;
      if (i + 1 < nCols) {
        if (p < end && *p == ',') {
          ++p;
          continue;
        }
      } else if (p == end || *p == '\n') {
        p += p == end ? 0 : 1;
        continue;
      } else if (*p == '\r' && (p + 1 == end || p[1] == '\n')) {
        p += p + 1 == end ? 1 : 2;
        continue;
      }
      fast = false;
      break;
    }
    if (!fast) {  // the careful path for this line
      const char* nl = static_cast<const char*>(std::memchr(lineStart, '\n', static_cast<std::size_t>(end - lineStart)));
      std::string_view line(lineStart, static_cast<std::size_t>((nl ? nl : end) - lineStart));
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      p = nl ? nl + 1 : end;
      bool isRow = false;
      if (!parseLineCarefully(line, nCols, fields, row.data(), c.error, isRow, holesAt, c.holes)) {
        c.failed = true;
        c.error.lineStart = static_cast<std::size_t>(lineStart - textStart);
        return;
      }
      if (!isRow) continue;
    }
    for (std::size_t i = 0; i < nCols; ++i) c.cols[i].push_back(row[i]);
  }
}

// Rows expected in `bytes` of data from the mean length of the first lines (each row takes
// at least 2 nCols bytes: a digit and a delimiter per field), with a small margin.
std::size_t expectedRows(const char* b, const char* e, std::size_t bytes, std::size_t nCols) {
  std::size_t lines = 0;
  const char* p = b;
  while (p < e && lines < 64) {
    const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(e - p));
    p = nl ? static_cast<const char*>(nl) + 1 : e;
    ++lines;
  }
  const double mean = std::max<double>(2.0 * static_cast<double>(nCols),
                                        lines ? static_cast<double>(p - b) / static_cast<double>(lines) : 1.0);
  return static_cast<std::size_t>(1.05 * static_cast<double>(bytes) / mean) + 16;
}

// Runs work(0..n-1), each on its own thread (the last on the calling one).
template <class Work>
void inParallel(unsigned n, Work work) {
  std::vector<std::thread> pool;
  for (unsigned k = 0; k + 1 < n; ++k) pool.emplace_back(work, k);
  work(n - 1);
  for (auto& t : pool) t.join();
}

}  // namespace

LogReadResult readFlexArmCsvText(std::string_view text, const std::string& path,
                                 const LogReadOptions& options) {
  if (std::string enc = textEncodingProblem(text); !enc.empty()) return failure(path, 1, 0, {}, enc);
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    return failure(path, 1, 0, {}, "the file is empty");

  IdData data;
  io::LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> fields;
  std::vector<std::string> header;
  int headerLine = 0;
  int rateLine = 0;
  double declaredRate = 0.0;
  int metadataLines = 0;
  while (cursor.next(line)) {
    if (io::isBlank(line)) continue;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (line[first] == '#') {
      std::string body = io::trim(line.substr(first + 1));
      std::size_t colon = body.find(':');
      if (colon != std::string::npos) {
        if (++metadataLines > LogReadOptions::kMaxMetadata)
          return failure(path, cursor.number(), 0, {},
                         "more than " + std::to_string(LogReadOptions::kMaxMetadata) +
                             " metadata lines ('# key: value'); a FlexArm log has a few");
        std::string key = io::trim(std::string_view(body).substr(0, colon));
        std::string value = io::trim(std::string_view(body).substr(colon + 1));
        if (!key.empty()) data.setMeta(key, value);
        if (key == "sample_rate_hz") {
          double v = 0;
          if (io::parseNumber(value, v) != FieldStatus::Ok || !(v > 0))
            return failure(path, cursor.number(), 0, "sample_rate_hz",
                           "'" + value + "' is not a positive sample rate");
          declaredRate = v;
          rateLine = cursor.number();
        }
      }
      continue;
    }
    headerLine = cursor.number();
    io::splitFields(line, ',', fields);
    if (fields.size() > static_cast<std::size_t>(LogReadOptions::kMaxColumns))
      return failure(path, headerLine, 0, {},
                     "the header has more than " + std::to_string(LogReadOptions::kMaxColumns) +
                         " columns, more than FlexArm reads");
    std::unordered_set<std::string> seen;
    seen.reserve(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      std::string name = io::trim(fields[i]);
      if (name.empty())
        return failure(path, headerLine, static_cast<int>(i + 1), {},
                       "the header has an empty column name");
      if (!seen.insert(name).second)
        return failure(path, headerLine, static_cast<int>(i + 1), name,
                       "the column name appears twice in the header");
      header.push_back(std::move(name));
    }
    break;
  }
  if (headerLine == 0)
    return failure(path, cursor.number(), 0, {}, "no header line: the file holds only comments");
  double probe = 0;
  if (io::parseNumber(header[0], probe) == FieldStatus::Ok)
    return failure(path, headerLine, 1, {},
                   "expected a header of column names (time_s,torque_ref_nm,motor_angle_rad,"
                   "...) but found numbers; open it as a headerless table instead");
  for (const char* required : {columns::kTime, columns::kTorqueRef, columns::kMotorAngle})
    if (std::find(header.begin(), header.end(), required) == header.end())
      return failure(path, headerLine, 0, required,
                     std::string("the required column '") + required + "' is missing");
  const auto timeIndex = static_cast<std::size_t>(
      std::find(header.begin(), header.end(), columns::kTime) - header.begin());

  // Data rows: split into chunks of whole lines, one per thread for large logs.
  const std::size_t nCols = header.size();
  const std::size_t dataStart = std::min(cursor.offset(), text.size());
  const char* const textStart = text.data();
  const char* const dataBegin = textStart + dataStart;
  const char* const dataEnd = textStart + text.size();
  const std::size_t dataBytes = text.size() - dataStart;
  unsigned threads = 1;
  if (dataBytes > (4u << 20))
    threads = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
  std::vector<Chunk> chunks(threads);
  const char* b = dataBegin;
  for (unsigned k = 0; k < threads; ++k) {
    const char* e = k + 1 == threads ? dataEnd : dataBegin + dataBytes * (k + 1) / threads;
    if (e < b) e = b;
    if (e < dataEnd) {
      const void* nl = std::memchr(e, '\n', static_cast<std::size_t>(dataEnd - e));
      e = nl ? static_cast<const char*>(nl) + 1 : dataEnd;
    }
    chunks[k].begin = b;
    chunks[k].end = e;
    b = e;
  }
  // Every chunk parses into its own columns; the first reserves room for the whole log, so
  // the others are appended to it without moving it.
  inParallel(threads, [&](unsigned k) {
    const auto bytes = static_cast<std::size_t>(k == 0 ? dataBytes : chunks[k].end - chunks[k].begin);
    parseChunk(chunks[k], textStart, nCols, expectedRows(dataBegin, dataEnd, bytes, nCols),
               options.keepIrregularTime ? static_cast<long>(timeIndex) : -1L);
  });
  for (const auto& c : chunks)
    if (c.failed)
      return failure(path, io::lineAt(text, c.error.lineStart), c.error.column,
                     c.error.column > 0 ? header[static_cast<std::size_t>(c.error.column - 1)]
                                        : std::string(),
                     c.error.problem);
  std::vector<std::vector<double>> cols = std::move(chunks[0].cols);
  for (unsigned k = 1; k < threads; ++k)
    for (std::size_t i = 0; i < nCols; ++i) {
      cols[i].insert(cols[i].end(), chunks[k].cols[i].begin(), chunks[k].cols[i].end());
      std::vector<double>().swap(chunks[k].cols[i]);
    }
  const std::size_t rows = cols[0].size();

  auto lineOf = [&](std::size_t row) { return io::lineOfRow(text, dataStart, headerLine + 1, row, "#"); };
  if (rows == 0)
    return failure(path, headerLine, 0, {}, "the header is not followed by any data rows");
  if (rows < 2)
    return failure(path, lineOf(0), 0, {}, "only one data row: at least two samples are needed");

  auto allLines = [&] { return io::linesOfRows(text, dataStart, headerLine + 1, "#"); };
  bool holes = false;
  for (const auto& c : chunks) holes = holes || c.holes;
  LogReadResult fail;
  if (!io::checkTime(path, cols[timeIndex], lineOf, allLines, static_cast<int>(timeIndex + 1),
                     columns::kTime, options, data, fail))
    return fail;
  if (holes && data.timeStamps.empty()) {  // channels at different rates: stamps and NaN holes
    data.timeStamps = cols[timeIndex];
    data.sourceLines = allLines();
  }
  if (declaredRate > 0 && data.timeStamps.empty()) {
    const double measured = 1.0 / data.sampleTime;
    if (std::abs(measured - declaredRate) > options.maxSampleJitter * declaredRate) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "the header says %.6g Hz but the time column is sampled at %.6g Hz",
                    declaredRate, measured);
      return failure(path, rateLine, 0, "sample_rate_hz", buf);
    }
  }
  for (std::size_t i = 0; i < nCols; ++i) {
    if (i == timeIndex) continue;
    Channel c;
    c.name = header[i];
    c.unit = unitFromColumnName(c.name);
    c.values = std::move(cols[i]);
    data.channels.push_back(std::move(c));
  }
  io::assignDefaultRoles(data);
  if (data.meta("source").empty())
    data.setMeta("source", std::filesystem::path(path).filename().string());
  LogReadResult ok;
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

LogReadResult readFlexArmCsv(const std::string& path, const LogReadOptions& options) {
  FileBytes bytes;
  std::string problem;
  if (!readInputFile(path, options.maxFileBytes, bytes, &problem))
    return failure(path, 0, 0, {}, problem);
  return readFlexArmCsvText(bytes.view(), path, options);
}

}  // namespace flexarm
