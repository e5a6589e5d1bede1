#include "core/io/log_io.h"

#include <matio.h>

#include <Eigen/Core>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <system_error>
#include <type_traits>
#include <unistd.h>

#include "core/io/csv_rows.h"
#include "core/io/huge_pages.h"
#include "core/io/text_lines.h"
#include "core/signal/timing.h"

namespace flexarm {
namespace {

namespace fs = std::filesystem;
using namespace textio;

std::string humanBytes(std::uint64_t n) {
  char buf[64];
  if (n >= (1ull << 30))
    std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(n) / (1ull << 30));
  else if (n >= (1ull << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(n) / (1ull << 20));
  else
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(n));
  return buf;
}

LogReadResult failure(const std::string& file, int line, int column, std::string columnName,
                      std::string problem) {
  LogReadResult r;
  r.ok = false;
  r.error = ReadError{file, line, column, std::move(columnName), std::move(problem)};
  return r;
}

// Opens the file for reading line by line after checking that it exists, is a regular file
// and is not larger than the limit. Returns false with the error filled otherwise.
bool openText(const std::string& path, std::uint64_t maxBytes, LineReader& reader,
              LogReadResult& fail) {
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    fail = failure(path, 0, 0, {}, "the file does not exist");
    return false;
  }
  if (!fs::is_regular_file(path, ec)) {
    fail = failure(path, 0, 0, {}, "not a regular file");
    return false;
  }
  const std::uint64_t size = fs::file_size(path, ec);
  if (ec) {
    fail = failure(path, 0, 0, {}, "cannot read the file size: " + ec.message());
    return false;
  }
  if (size > maxBytes) {
    fail = failure(path, 0, 0, {},
                   "the file is " + humanBytes(size) + ", larger than the " +
                       humanBytes(maxBytes) +
                       " FlexArm reads at once; cut it into shorter logs or decimate it first");
    return false;
  }
  if (!reader.open(path)) {
    fail = failure(path, 0, 0, {}, std::string("cannot open the file: ") + std::strerror(errno));
    return false;
  }
  return true;
}

// Whether reading stopped on an error (then fail names it).
bool readFailed(const std::string& path, const LineReader& reader, LogReadResult& fail) {
  const std::string why = reader.error();
  if (why.empty()) return false;
  fail = failure(path, reader.number(), 0, {}, "the file could not be read completely: " + why);
  return true;
}

// A refusal for the time stamps: marked as such, with every irregularity counted.
void timeFailure(LogReadResult& fail, const std::vector<double>& t, const std::vector<int>& lines,
                 double jitter) {
  fail.irregularTime = true;
  TimingOptions o;
  o.jitterTolerance = std::min(jitter, 0.49);
  fail.error.problem += ". The time stamps have " + analyzeTiming(t, lines, o).summary() +
                        "; resampling puts them on a uniform grid (flexarm preprocess --resample, "
                        "or Resample in the Preprocess panel)";
}

// Checks that times increase and are uniformly spaced; fills sampleTime and startTime. With
// keepIrregularTime, stamps that are not keep their times for a resampling step instead.
bool checkTime(const std::string& path, const std::vector<double>& t, const std::vector<int>& lines,
               int timeColumn, const std::string& timeName, const LogReadOptions& options,
               IdData& data, LogReadResult& fail) {
  const double jitter = options.maxSampleJitter;
  const std::size_t n = t.size();
  if (options.keepIrregularTime && n >= 2) {
    TimingOptions o;
    o.jitterTolerance = std::min(jitter, 0.49);
    const TimingReport report = analyzeTiming(t, lines, o);
    if (!report.regular()) {
      data.timeStamps = t;
      data.sourceLines = lines;
      data.startTime = t[0];
      data.sampleTime = report.interval > 0.0 ? report.interval : 1.0;
      return true;
    }
  }
  for (std::size_t i = 1; i < n; ++i)
    if (!(t[i] > t[i - 1])) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "time %.9g does not increase (line %d has %.9g)", t[i],
                    lines[i - 1], t[i - 1]);
      fail = failure(path, lines[i], timeColumn, timeName, buf);
      timeFailure(fail, t, lines, jitter);
      return false;
    }
  data.startTime = n ? t[0] : 0.0;
  if (n < 2) return true;
  const double dt = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  for (std::size_t i = 1; i < n; ++i) {
    const double step = t[i] - t[i - 1];
    if (std::abs(step - dt) > jitter * dt) {
      char buf[220];
      std::snprintf(buf, sizeof buf,
                    "irregular sampling: the step from %.9g s to %.9g s is %.6g s, %.1f %% off "
                    "the mean interval %.6g s (uniform within %.0f %% is required; resample "
                    "the log first)",
                    t[i - 1], t[i], step, 100.0 * std::abs(step - dt) / dt, dt, 100.0 * jitter);
      fail = failure(path, lines[i], timeColumn, timeName, buf);
      timeFailure(fail, t, lines, jitter);
      return false;
    }
  }
  data.sampleTime = dt;
  return true;
}

void assignDefaultRoles(IdData& data) {
  for (auto& c : data.channels) {
    if (c.name == columns::kTorqueRef) c.role = ChannelRole::Input;
    if (c.name == columns::kAngleRef) c.role = ChannelRole::Reference;
  }
  // The seed identifies with the motor velocity as output (Section 5.2) when it is logged.
  if (data.channel(columns::kMotorVelocity))
    data.setRole(columns::kMotorVelocity, ChannelRole::Output);
  else if (data.channel(columns::kMotorAngle))
    data.setRole(columns::kMotorAngle, ChannelRole::Output);
}

bool hasExtension(const std::string& path, const char* ext) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e == ext;
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
  if (inputColumn == outputColumn) return fail("input and output must be different columns");
  if (timeColumn < 0) return fail("the time column number must be 1 or more (0 for none)");
  if (!(sampleTime > 0.0) || !std::isfinite(sampleTime)) return fail("the sample time must be positive");
  if (!(maxSampleJitter > 0.0)) return fail("the sampling tolerance must be positive");
  return true;
}

LogReadResult readFlexArmCsv(const std::string& path, const LogReadOptions& options) {
  LineReader cursor;
  LogReadResult fail;
  if (!openText(path, options.maxFileBytes, cursor, fail)) return fail;

  IdData data;
  bool empty = true;  // no line but blank ones so far
  std::string_view line;
  std::vector<std::string_view> fields;
  std::vector<std::string> header;
  int headerLine = 0;
  int rateLine = 0;
  double declaredRate = 0.0;
  while (cursor.next(line)) {
    if (isBlank(line)) continue;
    empty = false;
    std::string t = trim(line);
    if (t[0] == '#') {
      std::string body = trim(std::string_view(t).substr(1));
      std::size_t colon = body.find(':');
      if (colon != std::string::npos) {
        std::string key = trim(std::string_view(body).substr(0, colon));
        std::string value = trim(std::string_view(body).substr(colon + 1));
        if (!key.empty()) data.setMeta(key, value);
        if (key == "sample_rate_hz") {
          double v = 0;
          if (parseNumber(value, v) != FieldStatus::Ok || !(v > 0))
            return failure(path, cursor.number(), 0, "sample_rate_hz",
                           "'" + value + "' is not a positive sample rate");
          declaredRate = v;
          rateLine = cursor.number();
        }
      }
      continue;
    }
    headerLine = cursor.number();
    splitFields(line, ',', fields);
    for (std::size_t i = 0; i < fields.size(); ++i) {
      std::string name = trim(fields[i]);
      if (name.empty())
        return failure(path, headerLine, static_cast<int>(i + 1), {},
                       "the header has an empty column name");
      if (std::find(header.begin(), header.end(), name) != header.end())
        return failure(path, headerLine, static_cast<int>(i + 1), name,
                       "the column name appears twice in the header");
      header.push_back(name);
    }
    break;
  }
  if (readFailed(path, cursor, fail)) return fail;
  if (empty) return failure(path, 1, 0, {}, "the file is empty");
  if (headerLine == 0) return failure(path, cursor.number(), 0, {}, "no header line: the file holds only comments");
  double probe = 0;
  if (parseNumber(header[0], probe) == FieldStatus::Ok)
    return failure(path, headerLine, 1, {},
                   "expected a header of column names (time_s,torque_ref_nm,motor_angle_rad,"
                   "...) but found numbers; open it as a headerless table instead");
  for (const char* required : {columns::kTime, columns::kTorqueRef, columns::kMotorAngle})
    if (std::find(header.begin(), header.end(), required) == header.end())
      return failure(path, headerLine, 0, required,
                     std::string("the required column '") + required + "' is missing");
  const int timeIndex =
      static_cast<int>(std::find(header.begin(), header.end(), columns::kTime) - header.begin());

  const std::size_t nCols = header.size();
  // With keepIrregularTime an empty field of a channel (not the time) is a hole: the channel
  // has no sample at that time.
  CsvRows rows = readCsvRows(path, cursor, nCols, 0,
                             options.keepIrregularTime ? timeIndex : -1);
  if (!rows.ok)
    return failure(path, rows.errorLine, rows.errorColumn,
                   rows.errorColumn > 0 ? header[static_cast<std::size_t>(rows.errorColumn - 1)]
                                        : std::string(),
                   rows.problem);
  auto& cols = rows.columns;
  const auto& lines = rows.lines;
  const bool holes = rows.holes;
  if (lines.empty())
    return failure(path, headerLine, 0, {}, "the header is not followed by any data rows");
  if (lines.size() < 2)
    return failure(path, lines[0], 0, {}, "only one data row: at least two samples are needed");

  if (!checkTime(path, cols[static_cast<std::size_t>(timeIndex)], lines, timeIndex + 1,
                 columns::kTime, options, data, fail))
    return fail;
  if (holes && data.timeStamps.empty()) {  // channels at different rates: stamps and NaN holes
    data.timeStamps = cols[static_cast<std::size_t>(timeIndex)];
    data.sourceLines = lines;
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
    if (static_cast<int>(i) == timeIndex) continue;
    Channel c;
    c.name = header[i];
    c.unit = unitFromColumnName(c.name);
    c.values = std::move(cols[i]);
    data.channels.push_back(std::move(c));
  }
  assignDefaultRoles(data);
  if (data.meta("source").empty()) data.setMeta("source", fs::path(path).filename().string());
  LogReadResult ok;
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

LogReadResult readTable(const std::string& path, const LogReadOptions& options) {
  std::string why;
  if (!options.isValid(&why)) return failure(path, 0, 0, {}, "bad column mapping: " + why);
  LineReader cursor;
  LogReadResult fail;
  if (!openText(path, options.maxFileBytes, cursor, fail)) return fail;

  bool empty = true;  // no line but blank ones so far
  std::string_view line;
  std::vector<std::string_view> fields;
  std::vector<std::vector<double>> cols;
  std::vector<int> lines;
  char delimiter = 0;
  bool first = true;
  while (cursor.next(line)) {
    if (isBlank(line)) continue;
    empty = false;
    std::string t = trim(line);
    if (t[0] == '#' || t[0] == '%') continue;
    if (first) delimiter = t.find(',') != std::string::npos ? ',' : 0;
    std::string_view body(t);
    if (delimiter == 0) body = line;
    // A trailing delimiter (as in the DaISy files' trailing tab) adds no field.
    splitFields(delimiter ? std::string_view(t) : line, delimiter, fields);
    if (delimiter && !fields.empty() && trim(fields.back()).empty()) fields.pop_back();
    if (first) {
      cols.resize(fields.size());
      const int needed = std::max({options.inputColumn, options.outputColumn, options.timeColumn});
      if (static_cast<int>(fields.size()) < needed)
        return failure(path, cursor.number(), 0, {},
                       "the table has " + std::to_string(fields.size()) +
                           " columns but the mapping uses column " + std::to_string(needed));
      first = false;
    }
    if (fields.size() != cols.size())
      return failure(path, cursor.number(), 0, {},
                     "the line has " + std::to_string(fields.size()) +
                         " fields, the first data line has " + std::to_string(cols.size()));
    for (std::size_t i = 0; i < fields.size(); ++i) {
      double v = 0;
      FieldStatus s = parseNumber(fields[i], v);
      if (s != FieldStatus::Ok) {
        if (lines.empty() && s == FieldStatus::NotNumber)
          return failure(path, cursor.number(), static_cast<int>(i + 1), {},
                         fieldProblem(s, fields[i]) +
                             "; a headerless table must hold numbers only (a file with a "
                             "header line should be a FlexArm CSV log)");
        return failure(path, cursor.number(), static_cast<int>(i + 1), {},
                       fieldProblem(s, fields[i]));
      }
      cols[i].push_back(v);
    }
    lines.push_back(cursor.number());
  }
  if (readFailed(path, cursor, fail)) return fail;
  if (empty) return failure(path, 1, 0, {}, "the file is empty");
  if (lines.size() < 2) return failure(path, lines.empty() ? 1 : lines[0], 0, {},
                                       "at least two rows of numbers are needed");
  IdData data;
  data.sampleTime = options.sampleTime;
  if (options.timeColumn > 0) {
    if (!checkTime(path, cols[static_cast<std::size_t>(options.timeColumn - 1)], lines,
                   options.timeColumn, "time", options, data, fail))
      return fail;
  }
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const int col = static_cast<int>(i + 1);
    if (col == options.timeColumn) continue;
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
  data.setMeta("source", fs::path(path).filename().string());
  data.setMeta("format", "headerless table");
  LogReadResult ok;
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

namespace {

// Reads a real numeric vector variable from an open .mat file. A variable whose doubles would take
// more than maxBytes is refused before anything is allocated (matio believes the sizes a file
// states).
bool readMatVector(mat_t* mat, const std::string& path, const std::string& name,
                   std::vector<double>& out, LogReadResult& fail, bool required,
                   std::uint64_t maxBytes) {
  matvar_t* var = Mat_VarReadInfo(mat, name.c_str());
  if (!var) {
    if (required) fail = failure(path, 0, 0, name, "the variable '" + name + "' is missing");
    return false;
  }
  struct Free {
    matvar_t* v;
    ~Free() { Mat_VarFree(v); }
  } guard{var};
  if (var->isComplex || var->rank != 2 || (var->dims[0] != 1 && var->dims[1] != 1) ||
      var->dims[0] * var->dims[1] == 0) {
    fail = failure(path, 0, 0, name, "the variable must be a real vector");
    return false;
  }
  const std::size_t n = var->dims[0] * var->dims[1];
  if (n > maxBytes / sizeof(double)) {
    fail = failure(path, 0, 0, name,
                   "the variable claims " + std::to_string(n) + " elements, more than the " +
                       humanBytes(maxBytes) + " FlexArm reads at once");
    return false;
  }
  // Read as the variable's class T (matio converts what the file stores to it): doubles
  // straight into `out`, other classes through one buffer of their own.
  const auto readAs = [&](auto zero) {
    using T = decltype(zero);
    constexpr bool direct = std::is_same_v<T, double>;
    sizeOnHugePages(out, n);
    std::vector<T> own(direct ? 0 : n);
    void* into = direct ? static_cast<void*>(out.data()) : static_cast<void*>(own.data());
    if (n > static_cast<std::size_t>(INT_MAX) ||
        Mat_VarReadDataLinear(mat, var, into, 0, 1, static_cast<int>(n)) != 0) {
      fail = failure(path, 0, 0, name, "the variable's data cannot be read (the file is damaged)");
      return false;
    }
    if constexpr (!direct) std::copy(own.begin(), own.end(), out.begin());
    return true;
  };
  bool read = false;
  switch (var->class_type) {
    case MAT_C_DOUBLE: read = readAs(double{}); break;
    case MAT_C_SINGLE: read = readAs(float{}); break;
    case MAT_C_INT32: read = readAs(std::int32_t{}); break;
    case MAT_C_INT16: read = readAs(std::int16_t{}); break;
    default:
      fail = failure(path, 0, 0, name, "the variable is not a numeric vector");
      return false;
  }
  if (!read) return false;
  // x - x is 0 for a finite x and NaN otherwise: one vectorized sum finds any non-finite one.
  const Eigen::Map<const Eigen::ArrayXd> x(out.data(), static_cast<Eigen::Index>(n));
  if (!std::isfinite((x - x).sum())) {
    const auto bad =
        std::find_if(out.begin(), out.end(), [](double v) { return !std::isfinite(v); });
    fail = failure(path, 0, 0, name,
                   "element " + std::to_string(bad - out.begin() + 1) + " is not a finite number");
    return false;
  }
  return true;
}

}  // namespace

LogReadResult readMat(const std::string& path, const LogReadOptions& options) {
  std::string ignored;
  LogReadResult fail;
  std::error_code ec;
  if (!fs::exists(path, ec)) return failure(path, 0, 0, {}, "the file does not exist");
  const auto size = fs::file_size(path, ec);
  if (!ec && size > options.maxFileBytes)
    return failure(path, 0, 0, {}, "the file is " + humanBytes(size) + ", larger than the " +
                                       humanBytes(options.maxFileBytes) + " FlexArm reads at once");
  // matio prints its own complaints to stderr; FlexArm reports one sentence instead.
  Mat_LogInitFunc("flexarm", [](int, char*) {});
  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  if (!mat)
    return failure(path, 0, 0, {},
                   "not a readable MATLAB .mat file (damaged, or not a .mat file at all)");
  struct Close {
    mat_t* m;
    ~Close() { Mat_Close(m); }
  } guard{mat};

  // Variable names: the FlexArm column names, or u/y, or the user's mapping.
  std::vector<std::string> names;
  while (matvar_t* info = Mat_VarReadNextInfo(mat)) {
    if (info->name) names.emplace_back(info->name);
    Mat_VarFree(info);
  }
  Mat_Rewind(mat);
  auto has = [&](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  std::string uName = options.inputVariable, yName = options.outputVariable;
  if (uName.empty()) uName = has(columns::kTorqueRef) ? columns::kTorqueRef : "u";
  if (yName.empty()) yName = has(columns::kMotorAngle) ? columns::kMotorAngle : "y";
  if (names.empty())
    return failure(path, 0, 0, {}, "the .mat file holds no variables FlexArm can read");

  IdData data;
  std::vector<double> u, y, t;
  if (!readMatVector(mat, path, uName, u, fail, true, options.maxFileBytes)) return fail;
  if (!readMatVector(mat, path, yName, y, fail, true, options.maxFileBytes)) return fail;
  if (u.size() != y.size())
    return failure(path, 0, 0, yName,
                   "has " + std::to_string(y.size()) + " samples but '" + uName + "' has " +
                       std::to_string(u.size()));
  if (u.size() < 2) return failure(path, 0, 0, uName, "at least two samples are needed");
  data.sampleTime = options.sampleTime;
  if (has(columns::kTime)) {
    if (!readMatVector(mat, path, columns::kTime, t, fail, true, options.maxFileBytes)) return fail;
    if (t.size() != u.size())
      return failure(path, 0, 0, columns::kTime, "has a different length than the signals");
    std::vector<int> idx;  // sample numbers, for the sentence of a failing check
    sizeOnHugePages(idx, t.size());
    std::iota(idx.begin(), idx.end(), 1);
    if (!checkTime(path, t, idx, 0, columns::kTime, options, data, fail)) {
      fail.error.problem = "sample " + std::to_string(fail.error.line) + ": " + fail.error.problem;
      fail.error.line = 0;
      return fail;
    }
  }
  auto push = [&](const std::string& name, std::vector<double> v, ChannelRole role) {
    Channel c{name, unitFromColumnName(name), role, std::move(v)};
    data.channels.push_back(std::move(c));
  };
  push(uName, std::move(u), ChannelRole::Input);
  push(yName, std::move(y), ChannelRole::Output);
  for (const auto& n : names) {
    if (n == uName || n == yName || n == columns::kTime) continue;
    std::vector<double> v;
    LogReadResult ignore;
    if (readMatVector(mat, path, n, v, ignore, false, options.maxFileBytes) &&
        v.size() == data.samples())
      push(n, std::move(v), n == columns::kAngleRef ? ChannelRole::Reference : ChannelRole::None);
  }
  if (data.channel(columns::kMotorVelocity) && uName == columns::kTorqueRef &&
      options.outputVariable.empty())
    data.setRole(columns::kMotorVelocity, ChannelRole::Output);
  data.setMeta("source", fs::path(path).filename().string());
  data.setMeta("format", "MATLAB .mat");
  LogReadResult ok;
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

LogReadResult readLog(const std::string& path, const LogReadOptions& options) {
  switch (options.format) {
    case LogFormat::FlexArmCsv: return readFlexArmCsv(path, options);
    case LogFormat::Table: return readTable(path, options);
    case LogFormat::Mat: return readMat(path, options);
    case LogFormat::Auto: break;
  }
  if (hasExtension(path, ".mat")) return readMat(path, options);
  // Sniff the first non-comment line: names mean a FlexArm log, numbers a table.
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::error_code ec;
    if (!fs::exists(path, ec)) return failure(path, 0, 0, {}, "the file does not exist");
    return failure(path, 0, 0, {}, std::string("cannot open the file: ") + std::strerror(errno));
  }
  char magic[128] = {};
  in.read(magic, sizeof magic - 1);
  if (std::strncmp(magic, "MATLAB", 6) == 0) return readMat(path, options);
  in.clear();
  in.seekg(0);
  std::string line;
  int count = 0;
  while (count < 1000 && std::getline(in, line)) {
    ++count;
    std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] == '#') {
      if (t.find("flexarm-log") != std::string::npos) return readFlexArmCsv(path, options);
      continue;
    }
    if (t[0] == '%') continue;
    const char c = t[0];
    const bool numeric = (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
    return numeric ? readTable(path, options) : readFlexArmCsv(path, options);
  }
  return readFlexArmCsv(path, options);  // reports the empty or comment-only file
}

bool writeFileAtomically(const std::string& path, const std::string& text, std::string* why) {
  const fs::path target(path);
  fs::path tmp = target;
  tmp += ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      if (why) *why = std::string("cannot create ") + tmp.string() + ": " + std::strerror(errno);
      return false;
    }
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.flush();
    if (!out) {
      if (why) *why = "writing " + tmp.string() + " failed (disk full?)";
      out.close();
      std::error_code ec;
      fs::remove(tmp, ec);
      return false;
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    if (why) *why = "cannot rename " + tmp.string() + " to " + path + ": " + ec.message();
    fs::remove(tmp, ec);
    return false;
  }
  return true;
}

bool writeFlexArmCsv(const IdData& data, const std::string& path, ReadError* error) {
  std::string why;
  if (!data.isValid(&why)) {
    if (error) *error = ReadError{path, 0, 0, {}, "refusing to write invalid data: " + why};
    return false;
  }
  std::string out;
  const std::size_t n = data.samples();
  out.reserve(64 + n * (data.channels.size() + 1) * 14);
  out += "# flexarm-log: 1\n";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", 1.0 / data.sampleTime);
  out += std::string("# sample_rate_hz: ") + buf + "\n";
  for (const auto& [k, v] : data.metadata) {
    if (k == "flexarm-log" || k == "sample_rate_hz") continue;
    std::string value = v;
    std::replace(value.begin(), value.end(), '\n', ' ');
    out += "# " + k + ": " + value + "\n";
  }
  out += columns::kTime;
  for (const auto& c : data.channels) out += "," + c.name;
  out += '\n';
  auto append = [&](double v) {
    auto res = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, res.ptr);
  };
  for (std::size_t i = 0; i < n; ++i) {
    // Time with fixed decimals avoids long binary tails such as 0.30000000000000004.
    int len = std::snprintf(buf, sizeof buf, "%.9f", data.timeAt(i));
    out.append(buf, static_cast<std::size_t>(len));
    for (const auto& c : data.channels) {
      out += ',';
      append(c.values[i]);
    }
    out += '\n';
  }
  if (!writeFileAtomically(path, out, &why)) {
    if (error) *error = ReadError{path, 0, 0, {}, why};
    return false;
  }
  return true;
}

}  // namespace flexarm
