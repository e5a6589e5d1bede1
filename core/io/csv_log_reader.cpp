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
bool parseLineCarefully(std::string_view line, std::size_t nCols, std::vector<std::string_view>& fields,
                        double* values, RowError& err, bool& isRow) {
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
    if (s != FieldStatus::Ok) {
      err.column = static_cast<int>(i + 1);
      err.problem = io::fieldProblem(s, fields[i]);
      return false;
    }
  }
  return true;
}

// Parses the data lines of [begin, end) (whole lines) into cols at rows [base, base + cap).
struct Chunk {
  const char* begin = nullptr;
  const char* end = nullptr;
  std::size_t base = 0;
  std::size_t cap = 0;
  std::size_t rows = 0;
  bool failed = false;
  RowError error;
};

void parseChunk(Chunk& c, const char* textStart, std::size_t nCols, std::vector<std::vector<double>>& cols) {
  std::vector<double*> out(nCols);
  for (std::size_t i = 0; i < nCols; ++i) out[i] = cols[i].data() + c.base;
  std::vector<double> row(nCols);  // the careful path's values
  std::vector<std::string_view> fields;
  const char* p = c.begin;
  const char* const end = c.end;
  std::size_t r = 0;
  while (p < end) {
    const char* const lineStart = p;
    // Fast path: number, ',', number, ..., number, end of line. No blanks, no '+'. Values
    // go straight to their column; a line that leaves the fast path is parsed again.
    bool fast = r < c.cap;
    for (std::size_t i = 0; fast && i < nCols; ++i) {
      double& v = out[i][r];
      const auto res = std::from_chars(p, end, v);
      if (res.ec != std::errc() || !std::isfinite(v)) {
        fast = false;
        break;
      }
      p = res.ptr;
      const char want = i + 1 < nCols ? ',' : '\n';
      if (p < end && *p == want) {
        ++p;
      } else if (i + 1 == nCols && (p == end || (*p == '\r' && p + 1 < end && p[1] == '\n'))) {
        p += p == end ? 0 : 2;
      } else if (i + 1 == nCols && *p == '\r' && p + 1 == end) {
        ++p;
      } else {
        fast = false;
        break;
      }
    }
    if (fast) {
      ++r;
      continue;
    }
    // Careful path for this line.
    const char* nl = static_cast<const char*>(std::memchr(lineStart, '\n', static_cast<std::size_t>(end - lineStart)));
    const char* lineEnd = nl ? nl : end;
    std::string_view line(lineStart, static_cast<std::size_t>(lineEnd - lineStart));
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    p = nl ? nl + 1 : end;
    bool isRow = false;
    if (!parseLineCarefully(line, nCols, fields, row.data(), c.error, isRow)) {
      c.failed = true;
      c.error.lineStart = static_cast<std::size_t>(lineStart - textStart);
      break;
    }
    if (!isRow) continue;
    if (r >= c.cap) {  // cannot happen: every row takes at least 2 nCols bytes
      c.failed = true;
      c.error = {static_cast<std::size_t>(lineStart - textStart), 0, "internal: row estimate exceeded"};
      break;
    }
    for (std::size_t i = 0; i < nCols; ++i) out[i][r] = row[i];
    ++r;
  }
  c.rows = r;
}

// Upper bound on the data rows in [b, e): lines, and bytes / (2 nCols) (a row of nCols
// numbers takes at least nCols digits and nCols - 1 commas and a line end).
std::size_t rowBound(const char* b, const char* e, std::size_t nCols) {
  const auto lines = static_cast<std::size_t>(std::count(b, e, '\n')) + 1;
  return std::min(lines, static_cast<std::size_t>(e - b) / (2 * nCols) + 1);
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
    std::string t = io::trim(line);
    if (t[0] == '#') {
      std::string body = io::trim(std::string_view(t).substr(1));
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
  // Each chunk's rows are bounded (counted in parallel), the columns sized once, then every
  // chunk parses into its own stretch of them.
  inParallel(threads, [&](unsigned k) { chunks[k].cap = rowBound(chunks[k].begin, chunks[k].end, nCols); });
  std::size_t base = 0;
  for (auto& c : chunks) {
    c.base = base;
    base += c.cap;
  }
  std::vector<std::vector<double>> cols(nCols);
  for (auto& c : cols) c.resize(base);
  inParallel(threads, [&](unsigned k) { parseChunk(chunks[k], textStart, nCols, cols); });
  for (const auto& c : chunks)
    if (c.failed)
      return failure(path, io::lineAt(text, c.error.lineStart), c.error.column,
                     c.error.column > 0 ? header[static_cast<std::size_t>(c.error.column - 1)]
                                        : std::string(),
                     c.error.problem);
  // Close the gaps left by chunks that held fewer rows than their bound.
  std::size_t rows = 0;
  for (const auto& c : chunks) {
    if (c.base != rows)
      for (auto& col : cols)
        std::copy(col.begin() + static_cast<std::ptrdiff_t>(c.base),
                  col.begin() + static_cast<std::ptrdiff_t>(c.base + c.rows),
                  col.begin() + static_cast<std::ptrdiff_t>(rows));
    rows += c.rows;
  }
  for (auto& col : cols) col.resize(rows);

  auto lineOf = [&](std::size_t row) { return io::lineOfRow(text, dataStart, headerLine + 1, row, "#"); };
  if (rows == 0)
    return failure(path, headerLine, 0, {}, "the header is not followed by any data rows");
  if (rows < 2)
    return failure(path, lineOf(0), 0, {}, "only one data row: at least two samples are needed");

  LogReadResult fail;
  if (!io::checkTime(path, cols[timeIndex], lineOf, static_cast<int>(timeIndex + 1), columns::kTime,
                     options.maxSampleJitter, data, fail))
    return fail;
  if (declaredRate > 0) {
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
