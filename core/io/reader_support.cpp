#include "core/io/reader_support.h"

#include "core/signal/timing.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace flexarm::io {

LogReadResult failure(const std::string& file, int line, int column, std::string columnName,
                      std::string problem) {
  LogReadResult r;
  r.ok = false;
  r.error = ReadError{file, line, column, std::move(columnName), std::move(problem)};
  return r;
}

std::string trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return std::string(s.substr(b, e - b));
}

std::string utf8Problem(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = length > 0 && i + length <= s.size() && !(c == 0xC0 || c == 0xC1 || c > 0xF4);
    for (std::size_t k = 1; ok && k < length; ++k) ok = (static_cast<unsigned char>(s[i + k]) & 0xC0) == 0x80;
    if (!ok) {
      char buf[120];
      std::snprintf(buf, sizeof buf, "byte 0x%02x at character %zu is not UTF-8 (Latin-1 text? save the file as UTF-8)",
                    static_cast<unsigned>(c), i + 1);
      return buf;
    }
    i += length;
  }
  return {};
}

bool isBlank(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c == ' ' || c == '\t' || c == '\r'; });
}

FieldStatus parseNumber(std::string_view field, double& value) {
  std::size_t b = 0, e = field.size();
  while (b < e && (field[b] == ' ' || field[b] == '\t')) ++b;
  while (e > b && (field[e - 1] == ' ' || field[e - 1] == '\t')) --e;
  if (b == e) return FieldStatus::Empty;
  const char* first = field.data() + b;
  const char* last = field.data() + e;
  if (*first == '+') ++first;  // from_chars does not accept a leading '+'
  const char* end = parseDouble(first, last, value);
  if (end != last) return FieldStatus::NotNumber;
  if (!std::isfinite(value)) return FieldStatus::NotFinite;
  return FieldStatus::Ok;
}

std::string fieldProblem(FieldStatus s, std::string_view field) {
  std::string shown = trim(field);
  if (shown.size() > 40) shown = shown.substr(0, 40) + "...";
  switch (s) {
    case FieldStatus::Empty: return "the field is empty";
    case FieldStatus::NotNumber: return "'" + shown + "' is not a number";
    case FieldStatus::NotFinite: return "'" + shown + "' is not a finite number";
    case FieldStatus::Ok: break;
  }
  return {};
}

void splitFields(std::string_view line, char delimiter, std::vector<std::string_view>& out,
                 std::size_t maxFields) {
  out.clear();
  if (delimiter) {
    std::size_t start = 0;
    while (out.size() <= maxFields) {
      std::size_t p = line.find(delimiter, start);
      if (p == std::string_view::npos) {
        out.push_back(line.substr(start));
        return;
      }
      out.push_back(line.substr(start, p - start));
      start = p + 1;
    }
    return;
  }
  std::size_t i = 0;
  while (i < line.size() && out.size() <= maxFields) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i >= line.size()) break;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
}

bool LineCursor::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  std::size_t e = text_.find('\n', pos_);
  if (e == std::string_view::npos) e = text_.size();
  line = text_.substr(pos_, e - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = e + 1;
  ++number_;
  return true;
}

int lineAt(std::string_view text, std::size_t offset) {
  offset = std::min(offset, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
}

int lineOfRow(std::string_view text, std::size_t offset, int firstLine, std::size_t row,
              std::string_view comments) {
  LineCursor cursor(text.substr(std::min(offset, text.size())));
  std::string_view line;
  std::size_t seen = 0;
  while (cursor.next(line)) {
    if (isBlank(line)) continue;
    const std::string t = trim(line.substr(0, std::min<std::size_t>(line.size(), 64)));
    if (!t.empty() && comments.find(t[0]) != std::string_view::npos) continue;
    if (seen++ == row) return firstLine + cursor.number() - 1;
  }
  return 0;
}

std::vector<int> linesOfRows(std::string_view text, std::size_t offset, int firstLine,
                             std::string_view comments) {
  LineCursor cursor(text.substr(std::min(offset, text.size())));
  std::string_view line;
  std::vector<int> lines;
  while (cursor.next(line)) {
    if (isBlank(line)) continue;
    // As the readers decide: a comment starts after spaces and tabs only.
    std::size_t b = 0;
    while (b < line.size() && (line[b] == ' ' || line[b] == '\t')) ++b;
    if (b < line.size() && comments.find(line[b]) != std::string_view::npos) continue;
    lines.push_back(firstLine + cursor.number() - 1);
  }
  return lines;
}

namespace {
TimingReport timingOf(const std::vector<double>& t, const std::vector<int>& lines, double jitter) {
  TimingOptions o;
  o.jitterTolerance = std::min(jitter, 0.49);
  return analyzeTiming(t, lines, o);
}
}  // namespace

bool keepIrregularTime(const std::vector<double>& t, const std::vector<int>& lines,
                       double jitter, IdData& data) {
  if (t.size() < 2) return false;
  const TimingReport report = timingOf(t, lines, jitter);
  if (report.regular()) return false;
  data.timeStamps = t;
  data.sourceLines = lines;
  data.startTime = t[0];
  data.sampleTime = report.interval > 0.0 ? report.interval : 1.0;
  return true;
}

void describeTimeFailure(LogReadResult& fail, const std::vector<double>& t,
                         const std::vector<int>& lines, double jitter) {
  fail.irregularTime = true;
  fail.error.problem += ". The time stamps have " + timingOf(t, lines, jitter).summary() +
                        "; resampling puts them on a uniform grid (flexarm preprocess --resample, "
                        "or Resample in the Preprocess panel)";
}

long long firstTimeProblem(const std::vector<double>& t, double jitter, std::string& problem) {
  const std::size_t n = t.size();
  for (std::size_t i = 1; i < n; ++i)
    if (!(t[i] > t[i - 1])) {
      problem.clear();
      return static_cast<long long>(i);
    }
  if (n < 2) return -1;
  const double dt = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  char buf[260];
  if (!(dt >= IdData::kMinSampleTime)) {
    std::snprintf(buf, sizeof buf,
                  "the time step %.3g s is shorter than %.0e s, the finest step FlexArm "
                  "reads (its logs hold time with 9 decimals)",
                  dt, IdData::kMinSampleTime);
    problem = buf;
    return 1;
  }
  // Stamps of +-1.7e308 overflow their difference: a step of inf (a sample rate of 0 Hz).
  if (!(dt <= 1e6)) {
    std::snprintf(buf, sizeof buf,
                  "the time stamps run from %.9g s to %.9g s, a time step of %.3g s, longer than the 1e+06 s "
                  "FlexArm reads (the time column is damaged or not in seconds)",
                  t[0], t[n - 1], dt);
    problem = buf;
    return 1;
  }
  for (std::size_t i = 1; i < n; ++i) {
    const double step = t[i] - t[i - 1];
    if (std::abs(step - dt) > jitter * dt) {
      std::snprintf(buf, sizeof buf,
                    "irregular sampling: the step from %.9g s to %.9g s is %.6g s, %.1f %% off "
                    "the mean interval %.6g s (uniform within %.0f %% is required; resample "
                    "the log first)",
                    t[i - 1], t[i], step, 100.0 * std::abs(step - dt) / dt, dt, 100.0 * jitter);
      problem = buf;
      return static_cast<long long>(i);
    }
  }
  return -1;
}

std::string notIncreasingProblem(double t, int previousLine, double previous) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "time %.9g does not increase (line %d has %.9g)", t,
                previousLine, previous);
  return buf;
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

}  // namespace flexarm::io
