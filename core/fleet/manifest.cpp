#include "core/fleet/manifest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

#include "core/common/text.h"

namespace flexarm {

namespace {

constexpr std::uintmax_t kMaxManifestBytes = 1ull << 30;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t comma = line.find(',', pos);
    out.push_back(trim(line.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos)));
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  return out;
}

// Days from 1970-01-01 of a proleptic Gregorian date (the civil-from-days count by eras of
// 400 years).
long daysFromCivil(long y, unsigned m, unsigned d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<long>(doe) - 719468;
}

bool leap(long y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

bool readInt(std::string_view s, std::size_t digits, long& out) {
  if (s.size() != digits) return false;
  out = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    out = out * 10 + (c - '0');
  }
  return true;
}

// A decimal number, whole (no hex, no inf or nan, nothing after it).
std::optional<double> decimal(std::string_view s) {
  if (s.empty() || s.size() > 40 || s.find_first_not_of("0123456789+-.eE") != std::string_view::npos) return std::nullopt;
  const std::string t(s);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

// The folder, links resolved, that a manifest's logs must lie in.
std::filesystem::path resolvedFolder(const std::filesystem::path& folder) {
  std::error_code ec;
  auto f = std::filesystem::weakly_canonical(std::filesystem::absolute(folder.empty() ? "." : folder, ec), ec);
  return ec ? std::filesystem::path() : f;
}

// Whether `inner`, links resolved, lies inside `folder` (resolvedFolder's).
bool insideFolder(const std::filesystem::path& inner, const std::filesystem::path& folder) {
  if (folder.empty()) return false;
  std::error_code ec;
  const auto p = std::filesystem::weakly_canonical(std::filesystem::absolute(inner, ec), ec);
  if (ec) return false;
  const auto rel = p.lexically_relative(folder);
  return !rel.empty() && *rel.begin() != ".." && rel != ".";
}

}  // namespace

std::string FleetAxis::key() const { return robot + "/" + std::to_string(axis); }

const FleetAxis* FleetManifest::axis(const std::string& robot, int a) const {
  for (const auto& x : axes)
    if (x.robot == robot && x.axis == a) return &x;
  return nullptr;
}

std::string ManifestError::toString() const {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": ";
  if (!column.empty()) s += "column " + column + ": ";
  return s + problem;
}

std::optional<double> parseIsoDay(std::string_view t) {
  // YYYY-MM-DD[THH:MM[:SS[.fff]]][Z]
  if (t.size() < 10 || t[4] != '-' || t[7] != '-') return std::nullopt;
  long y = 0, mo = 0, d = 0, h = 0, mi = 0;
  double sec = 0.0;
  if (!readInt(t.substr(0, 4), 4, y) || !readInt(t.substr(5, 2), 2, mo) || !readInt(t.substr(8, 2), 2, d))
    return std::nullopt;
  std::string_view rest = t.substr(10);
  if (!rest.empty() && rest.back() == 'Z') rest.remove_suffix(1);
  if (!rest.empty()) {
    if ((rest[0] != 'T' && rest[0] != ' ') || rest.size() < 6 || rest[3] != ':') return std::nullopt;
    if (!readInt(rest.substr(1, 2), 2, h) || !readInt(rest.substr(4, 2), 2, mi)) return std::nullopt;
    rest = rest.substr(6);
    if (!rest.empty()) {
      if (rest[0] != ':' || rest.size() < 3) return std::nullopt;
      long s = 0;
      if (!readInt(rest.substr(1, 2), 2, s)) return std::nullopt;
      sec = static_cast<double>(s);
      rest = rest.substr(3);
      if (!rest.empty()) {
        if (rest[0] != '.' || rest.size() < 2) return std::nullopt;
        double scale = 0.1;
        for (char c : rest.substr(1)) {
          if (c < '0' || c > '9') return std::nullopt;
          sec += scale * (c - '0');
          scale /= 10.0;
        }
      }
    }
  }
  static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (mo < 1 || mo > 12 || d < 1 || d > kDays[mo - 1] + (mo == 2 && leap(y)) || h > 23 || mi > 59 ||
      sec >= 61.0)
    return std::nullopt;
  return static_cast<double>(daysFromCivil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d))) +
         (static_cast<double>(h) * 3600.0 + static_cast<double>(mi) * 60.0 + sec) / 86400.0;
}

std::string isoFromDay(double day) {
  const double whole = std::floor(day);
  long z = static_cast<long>(whole) + 719468;
  const long era = (z >= 0 ? z : z - 146096) / 146097;
  const unsigned doe = static_cast<unsigned>(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  long y = static_cast<long>(yoe) + era * 400;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  const unsigned d = doy - (153 * mp + 2) / 5 + 1;
  const unsigned m = mp < 10 ? mp + 3 : mp - 9;
  y += m <= 2;
  const int secs = static_cast<int>(std::clamp(std::lround((day - whole) * 86400.0), 0L, 86399L));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04ld-%02u-%02uT%02d:%02d:%02dZ", y, m, d, secs / 3600, (secs / 60) % 60,
                secs % 60);
  return buf;
}

std::optional<FleetManifest> parseFleetManifest(std::string_view text, const std::string& path,
                                                ManifestError* error, const ManifestReadOptions& options) {
  auto fail = [&](int line, std::string column, std::string problem) -> std::optional<FleetManifest> {
    if (error) *error = {path, line, std::move(column), std::move(problem)};
    return std::nullopt;
  };
  if (text.size() >= 2 && ((text[0] == '\xff' && text[1] == '\xfe') || (text[0] == '\xfe' && text[1] == '\xff')))
    return fail(0, "", "is UTF-16 text; save the manifest as UTF-8 (plain text, as a spreadsheet's 'CSV UTF-8')");
  if (text.rfind("\xef\xbb\xbf", 0) == 0) text.remove_prefix(3);  // a UTF-8 byte-order mark
  if (const auto nul = text.find('\0'); nul != std::string_view::npos)
    return fail(static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(nul), '\n')) + 1, "",
                "holds a NUL byte: not a text file (UTF-16, or binary data)");
  FleetManifest m;
  m.path = path;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  const std::filesystem::path inside = options.allowLogsOutside ? std::filesystem::path() : resolvedFolder(folder);
  bool versioned = false;
  std::vector<std::string> header;
  int iRobot = -1, iAxis = -1, iTime = -1, iLog = -1, iTemp = -1, iRole = -1;
  std::set<std::tuple<std::string, int, std::string>> seen;
  std::size_t pos = 0;
  int lineNo = 0;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = trim(text.substr(pos, end - pos));
    pos = end + 1;
    ++lineNo;
    if (line.empty()) continue;
    if (line[0] == '#') {
      std::string_view body = trim(line.substr(1));
      if (body.rfind("flexarm-fleet:", 0) == 0) {
        const std::string_view v = trim(body.substr(14));
        if (v != "1")
          return fail(lineNo, "", "manifest version " + inQuotes(v) + " is not one this FlexArm reads (version 1)");
        versioned = true;
      }
      continue;
    }
    if (!versioned)
      return fail(lineNo, "", "a fleet manifest starts with the line '# flexarm-fleet: 1'");
    const auto fields = splitFields(line);
    if (header.empty()) {
      for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string name(fields[i]);
        int* slot = name == "robot" ? &iRobot : name == "axis" ? &iAxis : name == "time" ? &iTime
                  : name == "log" ? &iLog : name == "temperature_c" ? &iTemp : name == "role" ? &iRole
                  : nullptr;
        if (!slot)
          return fail(lineNo, name.size() <= 100 && !hasControlCharacter(name) ? name : inQuotes(name), "unknown column (robot, axis, time, log, temperature_c, role)");
        if (*slot >= 0) return fail(lineNo, name, "the column appears twice");
        *slot = static_cast<int>(i);
        header.push_back(name);
      }
      for (auto [slot, name] : {std::pair{iRobot, "robot"}, {iAxis, "axis"}, {iTime, "time"}, {iLog, "log"}})
        if (slot < 0) return fail(lineNo, name, "the header lacks this column");
      continue;
    }
    if (m.entries.size() >= options.maxRows)
      return fail(lineNo, "", "more than " + std::to_string(options.maxRows) +
                                  " rows, more than one run is allowed to take on; split the plant into several manifests "
                                  "or raise the limit (--max-rows)");
    if (fields.size() != header.size())
      return fail(lineNo, "", std::to_string(fields.size()) + " fields, the header has " +
                                  std::to_string(header.size()));
    FleetEntry e;
    e.line = lineNo;
    e.robot = std::string(fields[static_cast<std::size_t>(iRobot)]);
    // (A leading # would make the row a comment once the manifest is written back.)
    if (e.robot.empty() || e.robot.size() > 64 || e.robot.find_first_of("/\\\"") != std::string::npos ||
        e.robot[0] == '#' || hasControlCharacter(e.robot))
      return fail(lineNo, "robot", inQuotes(e.robot) + ": a robot needs a name of 1 to 64 characters without / \\ \", control characters or a leading #");
    {
      const std::string a(fields[static_cast<std::size_t>(iAxis)]);
      if (a.empty() || a.size() > 2 || a.find_first_not_of("0123456789") != std::string::npos ||
          (e.axis = std::stoi(a)) < 1 || e.axis > 64)
        return fail(lineNo, "axis", inQuotes(a) + " is not an axis number from 1 to 64");
    }
    e.time = std::string(fields[static_cast<std::size_t>(iTime)]);
    const auto day = parseIsoDay(e.time);
    if (!day) return fail(lineNo, "time", inQuotes(e.time) + " is not an ISO 8601 UTC time (2026-03-01T06:00:00Z)");
    e.day = *day;
    e.log = std::string(fields[static_cast<std::size_t>(iLog)]);
    if (e.log.empty()) return fail(lineNo, "log", "the log's path is empty");
    if (hasControlCharacter(e.log)) return fail(lineNo, "log", inQuotes(e.log) + ": a path with control characters");
    const std::filesystem::path lp(e.log);
    e.path = lp.is_absolute() || folder.empty() ? e.log : (folder / lp).string();
    if (!options.allowLogsOutside && !insideFolder(e.path, inside))
      return fail(lineNo, "log", inQuotes(e.log) + " lies outside the manifest's folder " +
                                     inQuotes(folder.empty() ? "." : folder.string()) +
                                     " (links resolved); FlexArm reads only the logs beside their manifest unless "
                                     "told otherwise (--allow-logs-outside)");
    if (iTemp >= 0) {
      const std::string t(fields[static_cast<std::size_t>(iTemp)]);
      if (!t.empty()) {
        const auto v = decimal(t);
        if (!v || *v < -100.0 || *v > 300.0)
          return fail(lineNo, "temperature_c", inQuotes(t) + " is not a temperature in degC (-100 to 300)");
        e.temperatureC = *v;
      }
    }
    if (iRole >= 0) {
      const std::string_view r = fields[static_cast<std::size_t>(iRole)];
      if (r == "reference") e.reference = true;
      else if (!r.empty()) return fail(lineNo, "role", inQuotes(r) + " is not a role (reference, or empty)");
    }
    if (!seen.insert({e.robot, e.axis, e.time}).second)
      return fail(lineNo, "time", "robot " + e.robot + " axis " + std::to_string(e.axis) +
                                      " has two logs at " + e.time);
    m.entries.push_back(std::move(e));
  }
  if (!versioned) return fail(0, "", "a fleet manifest starts with the line '# flexarm-fleet: 1'");
  if (header.empty()) return fail(0, "", "the manifest has no header line (robot,axis,time,log,...)");

  std::map<std::pair<std::string, int>, FleetAxis> axes;
  for (std::size_t i = 0; i < m.entries.size(); ++i) {
    auto& a = axes[{m.entries[i].robot, m.entries[i].axis}];
    a.robot = m.entries[i].robot;
    a.axis = m.entries[i].axis;
    a.entries.push_back(i);
  }
  for (auto& [key, a] : axes) {
    std::stable_sort(a.entries.begin(), a.entries.end(),
                     [&](std::size_t x, std::size_t y) { return m.entries[x].day < m.entries[y].day; });
    std::optional<std::size_t> ref;
    for (std::size_t i : a.entries) {
      if (!m.entries[i].reference) continue;
      if (ref)
        return fail(m.entries[i].line, "role", "robot " + a.robot + " axis " + std::to_string(a.axis) +
                                                  " already has its reference on line " +
                                                  std::to_string(m.entries[*ref].line));
      ref = i;
    }
    a.referenceEntry = ref ? *ref : a.entries.front();
    m.axes.push_back(std::move(a));
  }
  return m;
}

std::optional<FleetManifest> readFleetManifest(const std::string& path, ManifestError* error,
                                               const ManifestReadOptions& options) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  auto fail = [&](const std::string& problem) -> std::optional<FleetManifest> {
    if (error) *error = {path, 0, "", problem};
    return std::nullopt;
  };
  if (ec || !std::filesystem::exists(status)) return fail("no such file");
  if (!std::filesystem::is_regular_file(status)) return fail("not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return fail("cannot tell its size: " + ec.message());
  if (size > kMaxManifestBytes) return fail("larger than 1 GiB, more than a manifest can be");
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail("cannot be opened");
  std::string text(static_cast<std::size_t>(size), '\0');
  f.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(f.gcount()) != size) return fail("could not be read whole");
  return parseFleetManifest(text, path, error, options);
}

std::string fleetManifestText(const std::vector<FleetEntry>& entries) {
  std::ostringstream s;
  s << "# flexarm-fleet: 1\nrobot,axis,time,log,temperature_c,role\n";
  char buf[32];
  for (const auto& e : entries) {
    s << e.robot << "," << e.axis << "," << e.time << "," << e.log << ",";
    if (e.temperatureC) {
      std::snprintf(buf, sizeof buf, "%.1f", *e.temperatureC);
      s << buf;
    }
    s << "," << (e.reference ? "reference" : "") << "\n";
  }
  return s.str();
}

}  // namespace flexarm
