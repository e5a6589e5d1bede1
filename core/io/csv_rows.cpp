#include "core/io/csv_rows.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <system_error>
#include <thread>

#include "core/io/huge_pages.h"

namespace flexarm::textio {

namespace {

// A stretch is read by a thread of its own when the file has at least this many bytes a thread.
constexpr std::uint64_t kBytesPerThread = std::uint64_t{8} << 20;
constexpr unsigned kMaxThreads = 4;

// The rows of the lines that start before byte `end`, numbered from 1 after the line the
// reader returned last.
void readStretch(LineReader& reader, std::uint64_t end, std::size_t nCols, std::size_t estimate,
                 int holesExcept, CsvRows& out) {
  out.columns.resize(nCols);
  for (auto& c : out.columns) reserveOnHugePages(c, estimate);
  reserveOnHugePages(out.lines, estimate);
  std::vector<double> row(nCols);
  std::vector<std::string_view> fields;
  const int first = reader.number();
  std::string_view line;
  while (reader.offset() < end && reader.next(line)) {
    const int number = reader.number() - first;
    if (parsePlainRow(line, row)) {  // the rows as FlexArm writes them
      for (std::size_t i = 0; i < nCols; ++i) out.columns[i].push_back(row[i]);
      out.lines.push_back(number);
      continue;
    }
    // Anything else (blanks, comments, '+' signs, errors) field by field, as the format says.
    if (isBlank(line)) continue;
    if (trim(line)[0] == '#') continue;
    splitFields(line, ',', fields);
    if (fields.size() != nCols) {
      out.ok = false;
      out.errorLine = number;
      out.problem = "the line has " + std::to_string(fields.size()) + " fields, the header has " +
                    std::to_string(nCols);
      return;
    }
    for (std::size_t i = 0; i < nCols; ++i) {
      const FieldStatus s = parseNumber(fields[i], row[i]);
      if (s == FieldStatus::Empty && holesExcept >= 0 && static_cast<int>(i) != holesExcept) {
        row[i] = std::nan("");  // this channel has no sample at this time
        out.holes = true;
      } else if (s != FieldStatus::Ok) {
        out.ok = false;
        out.errorLine = number;
        out.errorColumn = static_cast<int>(i + 1);
        out.problem = fieldProblem(s, fields[i]);
        return;
      }
    }
    for (std::size_t i = 0; i < nCols; ++i) out.columns[i].push_back(row[i]);
    out.lines.push_back(number);
  }
  const std::string why = reader.error();
  if (!why.empty()) {
    out.ok = false;
    out.errorLine = reader.number() - first;
    out.problem = "the file could not be read completely: " + why;
  }
}

}  // namespace

CsvRows readCsvRows(const std::string& path, LineReader& reader, std::size_t nCols,
                    unsigned threads, int holesExcept) {
  const std::uint64_t start = reader.offset();
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  const std::uint64_t bytes = !ec && size > start ? size - start : 0;
  if (threads == 0)
    threads = static_cast<unsigned>(std::min<std::uint64_t>(
        std::min(std::max(1u, std::thread::hardware_concurrency()), kMaxThreads),
        std::max<std::uint64_t>(1, bytes / kBytesPerThread)));
  // Stretch k holds the lines that start in [cut[k], cut[k + 1]).
  std::vector<std::uint64_t> cut(threads + 1);
  for (unsigned k = 0; k < threads; ++k) cut[k] = start + bytes * k / threads;
  cut[threads] = std::numeric_limits<std::uint64_t>::max();
  const std::size_t estimate = (bytes / threads) / (nCols * 8 + 1) + 16;  // more rows reallocate
  std::vector<CsvRows> part(threads);
  std::vector<int> lineCount(threads, 0);
  const auto read = [&](unsigned k, LineReader& r) {
    try {
      const int first = r.number();
      readStretch(r, cut[k + 1], nCols, estimate, holesExcept, part[k]);
      lineCount[k] = r.number() - first;
    } catch (const std::exception& e) {  // out of memory in a thread
      part[k] = CsvRows{};
      part[k].ok = false;
      part[k].problem = std::string("the rows could not be read: ") + e.what();
    }
  };
  std::vector<std::thread> workers;
  const auto readAgain = [&](unsigned k) {
    LineReader r;
    std::string_view rest;
    if (!r.open(path, cut[k] - 1)) {
      part[k].ok = false;
      part[k].problem = std::string("cannot open the file again: ") + std::strerror(errno);
      return;
    }
    r.next(rest);  // the end of the last line of the stretch before
    read(k, r);
  };
  std::vector<unsigned> inline_;  // stretches no thread could be started for
  for (unsigned k = 1; k < threads; ++k) {
    try {
      workers.emplace_back(readAgain, k);
    } catch (const std::system_error&) {
      inline_.push_back(k);
    }
  }
  read(0, reader);
  for (unsigned k : inline_) readAgain(k);
  for (auto& w : workers) w.join();

  // The first bad row in the file is the first in the first stretch that has one.
  CsvRows rows;
  int lineBase = reader.number() - lineCount[0];  // the header's line
  std::size_t total = 0;
  for (unsigned k = 0; k < threads; ++k) {
    if (!part[k].ok) {
      rows.ok = false;
      rows.errorLine = part[k].errorLine > 0 ? lineBase + part[k].errorLine : 0;
      rows.errorColumn = part[k].errorColumn;
      rows.problem = std::move(part[k].problem);
      return rows;
    }
    for (int& line : part[k].lines) line += lineBase;
    rows.holes = rows.holes || part[k].holes;
    lineBase += lineCount[k];
    total += part[k].lines.size();
  }
  rows.columns = std::move(part[0].columns);
  rows.lines = std::move(part[0].lines);
  for (unsigned k = 1; k < threads; ++k) {
    for (std::size_t i = 0; i < nCols; ++i) {
      rows.columns[i].reserve(total);
      rows.columns[i].insert(rows.columns[i].end(), part[k].columns[i].begin(),
                             part[k].columns[i].end());
    }
    rows.lines.reserve(total);
    rows.lines.insert(rows.lines.end(), part[k].lines.begin(), part[k].lines.end());
  }
  return rows;
}

}  // namespace flexarm::textio
