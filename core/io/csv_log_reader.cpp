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
#include <unordered_set>

#include "core/common/parallel.h"
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

// The rows of one part of the log, parsed into its own columns.
struct Chunk {
  std::vector<std::vector<double>> cols;
  bool failed = false;
  bool holes = false;  // a channel not sampled on some row (NaN there)
  RowError error;      // lineStart: byte offset in the file
  std::vector<double> row;
  std::vector<std::string_view> fields;
};

void prepareColumns(Chunk& c, std::size_t nCols, std::size_t reserve) {
  c.cols.resize(nCols);
  for (auto& col : c.cols) {
    col.reserve(reserve);  // address space only: pages come on use
    preferHugePages(col.data(), reserve * sizeof(double));
  }
  c.row.resize(nCols);
}

// Parses the whole lines of [begin, end), which start at byte `offset` of the file, appending
// to the chunk's columns. Stops at the first bad line (c.failed, c.error).
void parseLines(Chunk& c, const char* begin, const char* end, std::size_t offset, std::size_t nCols,
                long holesAt) {
  double* const row = c.row.data();
  const char* p = begin;
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
      if (!parseLineCarefully(line, nCols, c.fields, row, c.error, isRow, holesAt, c.holes)) {
        c.failed = true;
        c.error.lineStart = offset + static_cast<std::size_t>(lineStart - begin);
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

// What the lines before the data rows say: metadata, the header, where the rows start.
struct Head {
  IdData data;  // metadata only
  std::vector<std::string> header;
  int headerLine = 0;
  int rateLine = 0;
  double declaredRate = 0.0;
  std::size_t dataStart = 0;  // byte offset of the first line after the header
  std::size_t timeIndex = 0;
  // Header indices of the columns the mapping names (-1: not named).
  long inputIndex = -1, outputIndex = -1, armIndex = -1, referenceIndex = -1;
};

enum class HeadStatus { Ok, Failed, NeedMore };

// Reads metadata and header from text, the whole file (whole) or its first bytes. NeedMore
// when the first bytes end before the header does.
HeadStatus parseHead(std::string_view text, bool whole, const std::string& path,
                     const LogReadOptions& options, Head& h, LogReadResult& fail) {
  if (std::string enc = textEncodingProblem(text); !enc.empty()) {
    fail = failure(path, 1, 0, {}, enc);
    return HeadStatus::Failed;
  }
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    if (!whole) return HeadStatus::NeedMore;
    fail = failure(path, 1, 0, {}, "the file is empty");
    return HeadStatus::Failed;
  }
  auto fails = [&](LogReadResult r) {
    fail = std::move(r);
    return HeadStatus::Failed;
  };
  io::LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> fields;
  int metadataLines = 0;
  while (cursor.next(line)) {
    if (!whole && cursor.offset() > text.size()) return HeadStatus::NeedMore;  // a cut line
    if (io::isBlank(line)) continue;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (line[first] == '#') {
      std::string body = io::trim(line.substr(first + 1));
      std::size_t colon = body.find(':');
      if (colon != std::string::npos) {
        if (++metadataLines > LogReadOptions::kMaxMetadata)
          return fails(failure(path, cursor.number(), 0, {},
                               "more than " + std::to_string(LogReadOptions::kMaxMetadata) +
                                   " metadata lines ('# key: value'); a FlexArm log has a few"));
        std::string key = io::trim(std::string_view(body).substr(0, colon));
        std::string value = io::trim(std::string_view(body).substr(colon + 1));
        if (std::string bad = io::utf8Problem(key + ": " + value); !bad.empty())
          return fails(failure(path, cursor.number(), 0, io::utf8Problem(key).empty() ? key : std::string(),
                               "the metadata line is not UTF-8 text: " + bad));
        if (!key.empty()) h.data.setMeta(key, value);
        if (key == "sample_rate_hz") {
          double v = 0;
          if (io::parseNumber(value, v) != FieldStatus::Ok || !(v > 0))
            return fails(failure(path, cursor.number(), 0, "sample_rate_hz",
                                 "'" + value + "' is not a positive sample rate"));
          h.declaredRate = v;
          h.rateLine = cursor.number();
        }
      }
      continue;
    }
    h.headerLine = cursor.number();
    io::splitFields(line, ',', fields);
    if (fields.size() > static_cast<std::size_t>(LogReadOptions::kMaxColumns))
      return fails(failure(path, h.headerLine, 0, {},
                           "the header has more than " + std::to_string(LogReadOptions::kMaxColumns) +
                               " columns, more than FlexArm reads"));
    std::unordered_set<std::string> seen;
    seen.reserve(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      std::string name = io::trim(fields[i]);
      if (name.empty())
        return fails(failure(path, h.headerLine, static_cast<int>(i + 1), {},
                             "the header has an empty column name"));
      if (std::string bad = io::utf8Problem(name); !bad.empty())
        return fails(failure(path, h.headerLine, static_cast<int>(i + 1), {},
                             "the column name is not UTF-8 text: " + bad));
      if (!seen.insert(name).second)
        return fails(failure(path, h.headerLine, static_cast<int>(i + 1), name,
                             "the column name appears twice in the header"));
      h.header.push_back(std::move(name));
    }
    break;
  }
  if (h.headerLine == 0) {
    if (!whole) return HeadStatus::NeedMore;
    return fails(failure(path, cursor.number(), 0, {}, "no header line: the file holds only comments"));
  }
  double probe = 0;
  if (io::parseNumber(h.header[0], probe) == FieldStatus::Ok)
    return fails(failure(path, h.headerLine, 1, {},
                         "expected a header of column names (time_s,torque_ref_nm,motor_angle_rad,"
                         "...) but found numbers; open it as a headerless table instead"));
  // The columns the mapping names (a CSV with other names), else FlexArm's.
  const LogMapping& m = options.mapping;
  const auto indexOf = [&](const std::string& name) {
    const auto it = std::find(h.header.begin(), h.header.end(), name);
    return it == h.header.end() ? -1L : static_cast<long>(it - h.header.begin());
  };
  // The header is listed to help map a real log's columns; a first line without separated
  // columns is not a log's header, and is not echoed (it may be the first line of any file).
  std::string headerList;
  if (h.header.size() < 2 && (h.header.empty() || h.header[0].size() > 40 ||
                              h.header[0].find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                            "0123456789_ .()[]/-") != std::string::npos)) {
    headerList = "no separated columns (the first line is not a CSV log's header)";
  } else {
    for (std::size_t i = 0; i < h.header.size() && i < 40 && headerList.size() < 300; ++i)
      headerList += (i ? ", " : "") + (h.header[i].size() > 40 ? h.header[i].substr(0, 40) + "..." : h.header[i]);
    if (h.header.size() > 40 || headerList.size() >= 300) headerList += ", ...";
  }
  const bool mapped = !m.time.empty() || !m.input.empty() || !m.output.empty();
  struct Need {
    const std::string& given;
    const char* flexArmName;
    const char* option;
    long* index;
  };
  long timeIndex = -1;
  for (const Need& n : {Need{m.time, columns::kTime, "--time-var", &timeIndex},
                        Need{m.input, columns::kTorqueRef, "--input-var", &h.inputIndex},
                        Need{m.output, columns::kMotorAngle, "--output-var", &h.outputIndex},
                        Need{m.arm, nullptr, "--arm-var", &h.armIndex},
                        Need{m.reference, nullptr, "--ref-var", &h.referenceIndex}}) {
    if (!n.flexArmName && n.given.empty()) continue;
    const std::string name = n.given.empty() ? std::string(n.flexArmName) : n.given;
    *n.index = indexOf(name);
    if (*n.index >= 0) continue;
    LogReadResult r = failure(path, h.headerLine, 0, name,
                              n.given.empty()
                                  ? "the required column '" + name + "' is missing; the header has " + headerList +
                                        (mapped ? "" : ": say which column is which (--time-var, --input-var, "
                                                       "--output-var with their units) or use the import dialog")
                                  : "the column '" + name + "' that " + n.option + " names is not in the header; it has " +
                                        headerList);
    r.needsMapping = !mapped;
    return fails(std::move(r));
  }
  h.timeIndex = static_cast<std::size_t>(timeIndex);
  if (m.arm.empty()) h.armIndex = indexOf(columns::kArmAngle);
  h.dataStart = std::min(cursor.offset(), text.size());
  return HeadStatus::Ok;
}

// Threads for `bytes` of data rows: one per core for large logs.
unsigned rowThreads(std::size_t bytes) { return bytes > (4u << 20) ? threadsFor(bytes, 1) : 1u; }

long holesColumn(const Head& h, const LogReadOptions& options) {
  return options.keepIrregularTime ? static_cast<long>(h.timeIndex) : -1L;
}

// Parses the rows of text (the whole file) from h.dataStart, in parts of whole lines.
std::vector<Chunk> parseRowsInMemory(std::string_view text, const Head& h, const LogReadOptions& options) {
  const std::size_t nCols = h.header.size();
  const char* const dataBegin = text.data() + h.dataStart;
  const char* const dataEnd = text.data() + text.size();
  const std::size_t dataBytes = text.size() - h.dataStart;
  const unsigned threads = rowThreads(dataBytes);
  std::vector<Chunk> chunks(threads);
  std::vector<std::pair<const char*, const char*>> parts(threads);
  const char* b = dataBegin;
  for (unsigned k = 0; k < threads; ++k) {
    const char* e = k + 1 == threads ? dataEnd : dataBegin + dataBytes * (k + 1) / threads;
    if (e < b) e = b;
    if (e < dataEnd) {
      const void* nl = std::memchr(e, '\n', static_cast<std::size_t>(dataEnd - e));
      e = nl ? static_cast<const char*>(nl) + 1 : dataEnd;
    }
    parts[k] = {b, e};
    b = e;
  }
  // The first part reserves room for the whole log, so the others are appended to it
  // without moving it.
  inParallel(threads, [&](unsigned k) {
    const auto bytes = static_cast<std::size_t>(k == 0 ? dataBytes : parts[k].second - parts[k].first);
    prepareColumns(chunks[k], nCols, expectedRows(dataBegin, dataEnd, bytes, nCols));
    parseLines(chunks[k], parts[k].first, parts[k].second,
               static_cast<std::size_t>(parts[k].first - text.data()), nCols, holesColumn(h, options));
  });
  return chunks;
}

// Parses the rows straight from the file, each thread its part, in pieces small enough to
// stay in the processor's cache: a large log is never copied whole into fresh memory (which
// the kernel zeroes page by page before it can be filled). `head` holds the file's first
// bytes (for the row-length estimate). False when the file must be read whole after all: it
// shrank meanwhile or a read failed.
bool parseRowsFromFile(const InputFile& file, std::string_view head, const Head& h,
                       const LogReadOptions& options, std::vector<Chunk>& chunks) {
  constexpr std::size_t kPiece = 256u << 10;
  const std::size_t nCols = h.header.size();
  const std::size_t size = static_cast<std::size_t>(file.size());
  const std::size_t dataBytes = size - h.dataStart;
  const unsigned threads = rowThreads(dataBytes);
  chunks.assign(threads, Chunk{});
  std::vector<char> trouble(threads, 0);
  const char* const sampleBegin = head.data() + std::min(h.dataStart, head.size());
  const char* const sampleEnd = head.data() + head.size();
  inParallel(threads, [&](unsigned k) {
    Chunk& c = chunks[k];
    // This thread parses the lines that start in [from, to).
    const std::size_t from = h.dataStart + dataBytes * k / threads;
    const std::size_t to = k + 1 == threads ? size : h.dataStart + dataBytes * (k + 1) / threads;
    prepareColumns(c, nCols, expectedRows(sampleBegin, sampleEnd, k == 0 ? dataBytes : to - from, nCols));
    std::vector<char> buf(kPiece);
    std::size_t bufOffset = k == 0 ? from : from - 1;  // file offset of buf[0]
    std::size_t have = 0;                               // bytes in buf
    bool skipping = k > 0;  // to the end of the line before `from` (the previous thread's)
    for (;;) {
      if (buf.size() - have < kPiece / 2) buf.resize(buf.size() * 2);  // a line longer than a piece
      const std::size_t at = bufOffset + have;
      const long long r = at < size ? file.readAt(at, buf.data() + have, std::min(buf.size() - have, size - at)) : 0;
      if (r < 0 || (r == 0 && at < size)) {  // a failed read, or the file shrank
        trouble[k] = 1;
        return;
      }
      have += static_cast<std::size_t>(r);
      const bool atEnd = bufOffset + have >= size;
      const char* p = buf.data();
      const char* const end = buf.data() + have;
      if (skipping) {
        const char* nl = static_cast<const char*>(std::memchr(p, '\n', have));
        if (!nl) {
          if (atEnd) return;
          bufOffset += have;
          have = 0;
          continue;
        }
        p = nl + 1;
        skipping = false;
      }
      // Whole lines that start before `to`: up to the newline ending the line at to - 1.
      const std::size_t pAt = bufOffset + static_cast<std::size_t>(p - buf.data());
      if (pAt >= to) return;
      const char* stop = end;
      bool last = atEnd;
      const std::size_t limit = to - 1 - bufOffset;  // index in buf of the byte at to - 1
      if (limit < have) {
        const char* nl = static_cast<const char*>(std::memchr(buf.data() + limit, '\n', have - limit));
        if (nl) {
          stop = nl + 1;
          last = true;
        }
      }
      if (!last) {  // parse up to the last whole line, keep the rest for the next piece
        const char* nl = static_cast<const char*>(::memrchr(p, '\n', static_cast<std::size_t>(end - p)));
        stop = nl ? nl + 1 : p;
      }
      parseLines(c, p, stop, pAt, nCols, holesColumn(h, options));
      if (c.failed || last) return;
      const std::size_t rest = static_cast<std::size_t>(end - stop);
      std::memmove(buf.data(), stop, rest);
      bufOffset += have - rest;
      have = rest;
    }
  });
  return std::none_of(trouble.begin(), trouble.end(), [](char t) { return t != 0; });
}

// Turns parsed rows into the log, with every check. With haveText, text is the whole file,
// for line numbers; without (the rows were read from the file in parts), a result that needs
// line numbers (a bad line, an irregular time column) sets needText instead.
LogReadResult finishLog(Head& h, std::vector<Chunk>& chunks, bool haveText, std::string_view text,
                        const std::string& path, const LogReadOptions& options, bool& needText) {
  needText = false;
  auto wantText = [&] {
    needText = true;
    return LogReadResult{};
  };
  for (const auto& c : chunks)
    if (c.failed) {
      if (!haveText) return wantText();
      return failure(path, io::lineAt(text, c.error.lineStart), c.error.column,
                     c.error.column > 0 ? h.header[static_cast<std::size_t>(c.error.column - 1)]
                                        : std::string(),
                     c.error.problem);
    }
  const std::size_t nCols = h.header.size();
  std::vector<std::vector<double>> cols = std::move(chunks[0].cols);
  for (std::size_t k = 1; k < chunks.size(); ++k)
    for (std::size_t i = 0; i < nCols; ++i) {
      cols[i].insert(cols[i].end(), chunks[k].cols[i].begin(), chunks[k].cols[i].end());
      std::vector<double>().swap(chunks[k].cols[i]);
    }
  const std::size_t rows = cols[0].size();
  if (rows < 2 && !haveText) return wantText();
  const int firstLine = h.headerLine + 1;
  auto lineOf = [&](std::size_t row) { return io::lineOfRow(text, h.dataStart, firstLine, row, "#"); };
  if (rows == 0)
    return failure(path, h.headerLine, 0, {}, "the header is not followed by any data rows");
  if (rows < 2)
    return failure(path, lineOf(0), 0, {}, "only one data row: at least two samples are needed");

  bool lineless = false;  // line numbers were asked for without the text
  auto allLines = [&] {
    if (!haveText) {
      lineless = true;
      return std::vector<int>(rows, 0);
    }
    return io::linesOfRows(text, h.dataStart, firstLine, "#");
  };
  auto lineOfChecked = [&](std::size_t row) {
    if (!haveText) {
      lineless = true;
      return 0;
    }
    return lineOf(row);
  };
  bool holes = false;
  for (const auto& c : chunks) holes = holes || c.holes;
  IdData& data = h.data;
  LogReadResult fail;
  const bool timeOk = io::checkTime(path, cols[h.timeIndex], lineOfChecked, allLines,
                                    static_cast<int>(h.timeIndex + 1), h.header[h.timeIndex], options, data, fail);
  if (lineless) return wantText();
  if (!timeOk) return fail;
  if (holes && data.timeStamps.empty()) {  // channels at different rates: stamps and NaN holes
    if (!haveText) return wantText();
    data.timeStamps = cols[h.timeIndex];
    data.sourceLines = allLines();
  }
  if (h.declaredRate > 0 && data.timeStamps.empty()) {
    const double measured = 1.0 / data.sampleTime;
    if (std::abs(measured - h.declaredRate) > options.maxSampleJitter * h.declaredRate) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "the header says %.6g Hz but the time column is sampled at %.6g Hz",
                    h.declaredRate, measured);
      return failure(path, h.rateLine, 0, "sample_rate_hz", buf);
    }
  }
  for (std::size_t i = 0; i < nCols; ++i) {
    if (i == h.timeIndex) continue;
    Channel c;
    c.name = h.header[i];
    c.unit = unitFromColumnName(c.name);
    c.values = std::move(cols[i]);
    data.channels.push_back(std::move(c));
  }
  io::assignDefaultRoles(data);
  if (data.meta("source").empty())
    data.setMeta("source", std::filesystem::path(path).filename().string());
  LogReadResult ok;
  if (options.mapping != LogMapping{}) {
    // Header indices to channel indices (the time is no channel).
    const auto channelOf = [&](long i) {
      return i < 0 ? -1 : static_cast<int>(i - (static_cast<std::size_t>(i) > h.timeIndex ? 1 : 0));
    };
    const LogMapping& m = options.mapping;
    MappedChannels found;
    if (!m.input.empty() || m.inputScale != 1.0 || m.convertsOutput()) found.input = channelOf(h.inputIndex);
    if (!m.output.empty() || m.convertsOutput()) found.output = channelOf(h.outputIndex);
    if (!m.arm.empty() || m.armUnit) found.arm = channelOf(h.armIndex);
    if (!m.reference.empty()) found.reference = channelOf(h.referenceIndex);
    for (const auto& [index, source] : {std::pair<long, std::string*>{h.inputIndex, &found.inputSource},
                                        {h.outputIndex, &found.outputSource},
                                        {h.armIndex, &found.armSource},
                                        {h.referenceIndex, &found.referenceSource}})
      if (index >= 0) *source = h.header[static_cast<std::size_t>(index)];
    std::string why;
    if (!applyMapping(data, found, m, !m.output.empty(), ok.warnings, &why))
      return failure(path, h.headerLine, 0, {}, why);
  }
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

// The file read whole and parsed as text.
LogReadResult readWholeFile(const InputFile& file, const std::string& path, const LogReadOptions& options) {
  FileBytes bytes;
  std::string problem;
  if (!file.readAll(bytes, &problem)) return failure(path, 0, 0, {}, problem);
  return readFlexArmCsvText(bytes.view(), path, options);
}

}  // namespace

LogReadResult readFlexArmCsvText(std::string_view text, const std::string& path,
                                 const LogReadOptions& options) {
  Head h;
  LogReadResult fail;
  if (parseHead(text, true, path, options, h, fail) != HeadStatus::Ok) return fail;
  std::vector<Chunk> chunks = parseRowsInMemory(text, h, options);
  bool needText = false;
  return finishLog(h, chunks, true, text, path, options, needText);
}

LogReadResult readFlexArmCsv(const std::string& path, const LogReadOptions& options, bool* readWhole) {
  InputFile file;
  std::string problem;
  if (!file.open(path, options.maxFileBytes, &problem)) return failure(path, 0, 0, {}, problem);
  return io::readFlexArmCsvFile(file, path, options, readWhole);
}

LogReadResult io::readFlexArmCsvFile(const InputFile& file, const std::string& path,
                                     const LogReadOptions& options, bool* readWhole) {
  // The first bytes give metadata and header; a small file is then parsed in memory, a large
  // one straight from the file. Whatever needs the text as a whole (a bad line's number, an
  // irregular time column, a header beyond the first bytes, a file that changed while read)
  // is read again the simple way, so both ways give the same result.
  constexpr std::size_t kHead = 64u << 10;
  if (readWhole) *readWhole = true;
  const auto size = static_cast<std::size_t>(file.size());
  if (size <= kHead) return readWholeFile(file, path, options);
  std::string head(kHead, '\0');
  if (file.readFully(0, head.data(), kHead) < kHead) return readWholeFile(file, path, options);
  Head h;
  LogReadResult fail;
  switch (parseHead(head, false, path, options, h, fail)) {
    case HeadStatus::Failed: return fail;
    case HeadStatus::NeedMore: return readWholeFile(file, path, options);
    case HeadStatus::Ok: break;
  }
  std::vector<Chunk> chunks;
  if (!parseRowsFromFile(file, head, h, options, chunks)) return readWholeFile(file, path, options);
  bool needText = false;
  LogReadResult r = finishLog(h, chunks, false, {}, path, options, needText);
  if (needText) return readWholeFile(file, path, options);
  if (readWhole) *readWhole = false;
  return r;
}

}  // namespace flexarm
