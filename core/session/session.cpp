#include "core/session/session.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/common/text.h"
#include "core/io/input_file.h"
#include "core/session/session_part.h"

namespace flexarm {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Reads typed fields and remembers the first problem with the field's place in the file.
class FieldReader {
 public:
  explicit FieldReader(std::string* why) : why_(why) {}
  bool failed() const { return failed_; }
  bool fail(const std::string& where, const std::string& problem) {
    if (!failed_ && why_) *why_ = where + ": " + problem;
    failed_ = true;
    return false;
  }
  const json* member(const json& obj, const char* key, const std::string& where, bool required) {
    if (!obj.is_object()) {
      fail(where, "must be an object");
      return nullptr;
    }
    auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) fail(where, std::string("'") + key + "' is missing");
      return nullptr;
    }
    return &*it;
  }
  bool string(const json& obj, const char* key, const std::string& where, std::string& out,
              bool required = true) {
    const json* v = member(obj, key, where, required);
    if (!v) return !failed_;
    if (!v->is_string()) return fail(where + "." + key, "must be text");
    out = v->get<std::string>();
    return true;
  }
  bool number(const json& obj, const char* key, const std::string& where, double& out,
              bool required = true) {
    const json* v = member(obj, key, where, required);
    if (!v) return !failed_;
    if (!v->is_number() || !std::isfinite(v->get<double>()))
      return fail(where + "." + key, "must be a finite number");
    out = v->get<double>();
    return true;
  }
  bool integer(const json& obj, const char* key, const std::string& where, int& out,
               bool required = true) {
    const json* v = member(obj, key, where, required);
    if (!v) return !failed_;
    if (!v->is_number_integer()) return fail(where + "." + key, "must be a whole number");
    out = v->get<int>();
    return true;
  }
  bool boolean(const json& obj, const char* key, const std::string& where, bool& out,
               bool required = true) {
    const json* v = member(obj, key, where, required);
    if (!v) return !failed_;
    if (!v->is_boolean()) return fail(where + "." + key, "must be true or false");
    out = v->get<bool>();
    return true;
  }

 private:
  std::string* why_;
  bool failed_ = false;
};

bool rangeFromJson(const json& v, const std::string& where, std::optional<SecondsRange>& out,
                   FieldReader& f) {
  if (v.is_null()) {
    out.reset();
    return true;
  }
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
    return f.fail(where, "must be [start, end] in seconds or null");
  const double a = v[0].get<double>(), b = v[1].get<double>();
  if (!std::isfinite(a) || !std::isfinite(b) || !(a < b))
    return f.fail(where, "start must be before end");
  out = SecondsRange{a, b};
  return true;
}

json readOptionsToJson(const LogReadOptions& o) {
  const LogMapping& m = o.mapping;
  json j = {{"format", toString(o.format)},    {"input_column", o.inputColumn},
            {"output_column", o.outputColumn}, {"time_column", o.timeColumn},
            {"sample_time_s", o.sampleTime},   {"input_name", o.inputName},
            {"output_name", o.outputName},     {"input_variable", m.input},
            {"output_variable", m.output},     {"max_sample_jitter", o.maxSampleJitter},
            {"keep_irregular_time", o.keepIrregularTime}};
  // The mapping's units, sides and gear ratio: written only when said, so that a session of a
  // FlexArm log reads as before.
  if (!m.time.empty()) j["time_variable"] = m.time;
  if (!m.arm.empty()) j["arm_variable"] = m.arm;
  if (!m.reference.empty()) j["reference_variable"] = m.reference;
  if (m.outputUnit) j["output_unit"] = toString(*m.outputUnit);
  if (m.armUnit) j["arm_unit"] = toString(*m.armUnit);
  if (m.outputSide) j["output_side"] = toString(*m.outputSide);
  if (!m.gearRatio.empty()) j["gear_ratio"] = m.gearRatio;
  if (m.inputScale != 1.0) j["input_scale"] = m.inputScale;
  return j;
}

bool readOptionsFromJson(const json& j, const std::string& where, LogReadOptions& o,
                         FieldReader& f) {
  std::string format = toString(o.format);
  f.string(j, "format", where, format, false);
  bool known = false;
  for (LogFormat k : {LogFormat::Auto, LogFormat::FlexArmCsv, LogFormat::Table, LogFormat::Mat})
    if (format == toString(k)) {
      o.format = k;
      known = true;
    }
  if (!known) return f.fail(where + ".format", "unknown log format " + inQuotes(format));
  f.integer(j, "input_column", where, o.inputColumn, false);
  f.integer(j, "output_column", where, o.outputColumn, false);
  f.integer(j, "time_column", where, o.timeColumn, false);
  f.number(j, "sample_time_s", where, o.sampleTime, false);
  f.string(j, "input_name", where, o.inputName, false);
  f.string(j, "output_name", where, o.outputName, false);
  LogMapping& m = o.mapping;
  f.string(j, "input_variable", where, m.input, false);
  f.string(j, "output_variable", where, m.output, false);
  f.string(j, "time_variable", where, m.time, false);
  f.string(j, "arm_variable", where, m.arm, false);
  f.string(j, "reference_variable", where, m.reference, false);
  for (const auto& [key, unit] : {std::pair<const char*, std::optional<SignalUnit>*>{"output_unit", &m.outputUnit},
                                  {"arm_unit", &m.armUnit}}) {
    std::string text;
    f.string(j, key, where, text, false);
    if (text.empty()) continue;
    *unit = signalUnitFromString(text);
    if (!*unit) return f.fail(where + "." + key, "unknown unit " + inQuotes(text));
  }
  std::string side;
  f.string(j, "output_side", where, side, false);
  if (!side.empty() && !(m.outputSide = encoderSideFromString(side)))
    return f.fail(where + ".output_side", "must be motor or arm, not " + inQuotes(side));
  f.string(j, "gear_ratio", where, m.gearRatio, false);
  f.number(j, "input_scale", where, m.inputScale, false);
  f.number(j, "max_sample_jitter", where, o.maxSampleJitter, false);
  f.boolean(j, "keep_irregular_time", where, o.keepIrregularTime, false);
  if (f.failed()) return false;
  std::string why;
  if (!o.isValid(&why)) return f.fail(where, why);
  return true;
}

json resampleToJson(const std::optional<UniformGridOptions>& r) {
  if (!r) return nullptr;
  return {{"rate_hz", r->rateHz},           {"method", toString(r->method)},
          {"max_gap_s", r->maxGapSeconds},  {"jitter_tolerance", r->jitterTolerance},
          {"stopband_db", r->stopbandDb}};
}

bool resampleFromJson(const json& j, const std::string& where, UniformGridOptions& r, FieldReader& f) {
  f.number(j, "rate_hz", where, r.rateHz);
  std::string method;
  if (f.string(j, "method", where, method)) {
    auto m = interpolationMethodFromString(method);
    if (!m) return f.fail(where + ".method", "unknown method " + inQuotes(method));
    r.method = *m;
  }
  f.number(j, "max_gap_s", where, r.maxGapSeconds, false);
  f.number(j, "jitter_tolerance", where, r.jitterTolerance, false);
  f.number(j, "stopband_db", where, r.stopbandDb, false);
  return !f.failed();
}

json preprocessToJson(const Session& s) {
  const PreprocessOptions& p = s.preprocess;
  json j = {{"applied", s.preprocessed},
            {"resample", resampleToJson(p.resample)},
            {"differentiate_angle", p.differentiateAngle},
            {"range_samples", p.range ? json::array({p.range->begin, p.range->end}) : json(nullptr)},
            {"decimation",
             {{"factor", p.decimation.factor},
              {"filter", toString(p.decimation.filter)},
              {"stopband_db", p.decimation.stopbandDb}}},
            {"detrend", toString(p.detrend)}};
  return j;
}

bool preprocessFromJson(const json& j, Session& s, FieldReader& f) {
  const std::string where = "preprocessing";
  PreprocessOptions& p = s.preprocess;
  f.boolean(j, "applied", where, s.preprocessed);
  if (const json* r = f.member(j, "resample", where, false); r && !r->is_null()) {
    UniformGridOptions u;
    if (!resampleFromJson(*r, where + ".resample", u, f)) return false;
    p.resample = u;
  }
  f.boolean(j, "differentiate_angle", where, p.differentiateAngle);
  if (const json* r = f.member(j, "range_samples", where, false); r && !r->is_null()) {
    if (!r->is_array() || r->size() != 2 || !(*r)[0].is_number_unsigned() ||
        !(*r)[1].is_number_unsigned() || (*r)[1].get<std::size_t>() <= (*r)[0].get<std::size_t>())
      return f.fail(where + ".range_samples", "must be [first, end) sample indices or null");
    p.range = SampleRange{(*r)[0].get<std::size_t>(), (*r)[1].get<std::size_t>()};
  }
  if (const json* d = f.member(j, "decimation", where, true)) {
    f.integer(*d, "factor", where + ".decimation", p.decimation.factor);
    std::string filter;
    if (f.string(*d, "filter", where + ".decimation", filter)) {
      auto k = antiAliasFilterFromString(filter);
      if (!k) return f.fail(where + ".decimation.filter", "unknown filter " + inQuotes(filter));
      p.decimation.filter = *k;
    }
    f.number(*d, "stopband_db", where + ".decimation", p.decimation.stopbandDb);
  }
  std::string detrend;
  if (f.string(j, "detrend", where, detrend)) {
    auto k = detrendFromString(detrend);
    if (!k) return f.fail(where + ".detrend", "unknown detrend " + inQuotes(detrend));
    p.detrend = *k;
  }
  if (f.failed()) return false;
  std::string why;
  if (!p.isValid(&why)) return f.fail(where, why);
  return true;
}

// Limits checked on the text before a document is built: a 40 MB file of one list of a
// million items, or brackets nested a million deep (whose document is destroyed
// recursively, overflowing the stack), is refused at the cost of one pass.
constexpr std::size_t kMaxJsonDepth = 64;
constexpr std::size_t kMaxJsonItems = 100000;  // in one list or object

class ShapeCheck : public nlohmann::json_sax<json> {
 public:
  std::string problem;
  bool null() override { return item(); }
  bool boolean(bool) override { return item(); }
  bool number_integer(number_integer_t) override { return item(); }
  bool number_unsigned(number_unsigned_t) override { return item(); }
  bool number_float(number_float_t, const string_t&) override { return item(); }
  bool string(string_t&) override { return item(); }
  bool binary(binary_t&) override { return item(); }
  bool start_object(std::size_t) override { return open(); }
  bool key(string_t&) override { return true; }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;  // the document parse that follows names the place
  }

 private:
  bool item() {
    if (!counts_.empty() && ++counts_.back() > kMaxJsonItems) {
      problem = "a list or object holds more than " + std::to_string(kMaxJsonItems) + " items";
      return false;
    }
    return true;
  }
  bool open() {
    if (!item()) return false;
    if (counts_.size() >= kMaxJsonDepth) {
      problem = "lists and objects are nested more than " + std::to_string(kMaxJsonDepth) + " deep";
      return false;
    }
    counts_.push_back(0);
    return true;
  }
  bool close() {
    counts_.pop_back();
    return true;
  }
  std::vector<std::size_t> counts_;
};

bool jsonShapeIsBounded(const std::string& text, std::string* why) {
  ShapeCheck check;
  json::sax_parse(text, &check);
  if (check.problem.empty()) return true;
  if (why) *why = check.problem;
  return false;
}

// Line and column of a byte offset, for parse errors.
std::string placeOf(const std::string& text, std::size_t byte) {
  int line = 1, column = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

}  // namespace

json secondsRangeToJson(const std::optional<SecondsRange>& r) {
  return r ? json::array({r->start, r->end}) : json(nullptr);
}

bool readSecondsRange(const json& j, const char* key, std::optional<SecondsRange>& out, std::string* why) {
  out.reset();
  if (!j.contains(key) || j[key].is_null()) return true;
  const json& r = j[key];
  if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number() ||
      !(r[0].get<double>() < r[1].get<double>())) {
    if (why) *why = std::string(key) + " must be [start, end] in seconds with start < end";
    return false;
  }
  out = SecondsRange{r[0].get<double>(), r[1].get<double>()};
  return true;
}

std::string toJsonText(const Session& s) {
  json logs = json::array();
  for (const auto& l : s.logs)
    logs.push_back({{"name", l.name}, {"path", l.path}, {"sha256", l.sha256},
                    {"read", readOptionsToJson(l.read)}});
  json j = {{"format", kSessionFormat},
            {"version", kSessionVersion},
            {"written_by", std::string("FlexArm ") + FLEXARM_VERSION},
            {"logs", logs},
            {"preprocessing", preprocessToJson(s)},
            {"ranges",
             {{"estimation_s", secondsRangeToJson(s.estimation)},
              {"validation_s", secondsRangeToJson(s.validation)}}},
            {"parts", s.parts.is_object() ? s.parts : json::object()}};
  return j.dump(2) + "\n";
}

SessionParseResult parseSession(const std::string& text) {
  SessionParseResult r;
  if (std::string why; !jsonShapeIsBounded(text, &why)) {
    r.message = "not a readable session: " + why;
    return r;
  }
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    r.message = "not a readable session: the JSON is damaged at " + placeOf(text, e.byte) +
                (e.byte >= text.size() ? " (the file ends too early)" : "");
    return r;
  } catch (const json::exception&) {  // e.g. a number beyond what a double holds
    r.message = "not a readable session: it holds a number too large to read";
    return r;
  }
  if (!j.is_object() || !j.contains("format") || j["format"] != kSessionFormat) {
    r.message = "not a FlexArm session (\"format\": \"flexarm-session\" is missing)";
    return r;
  }
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<int>() < 1) {
    r.message = "damaged session: \"version\" must be a whole number from 1 on";
    return r;
  }
  const int version = j["version"].get<int>();
  const std::string writer = j.contains("written_by") && j["written_by"].is_string()
                                 ? j["written_by"].get<std::string>()
                                 : std::string("a newer FlexArm");
  if (version > kSessionVersion) {
    r.message = "this session is in session format " + std::to_string(version) + " (written by " +
                writer + "); FlexArm " + FLEXARM_VERSION + " reads formats up to " +
                std::to_string(kSessionVersion) + ". Open it with a newer FlexArm.";
    return r;
  }
  std::string why;
  FieldReader f(&why);
  Session& s = r.session;
  s.writtenBy = writer;
  const json* logs = f.member(j, "logs", "session", true);
  if (logs && !logs->is_array()) f.fail("logs", "must be a list");
  if (logs && logs->is_array()) {
    if (logs->empty()) f.fail("logs", "the session names no log");
    for (std::size_t i = 0; i < logs->size() && !f.failed(); ++i) {
      const std::string where = "logs[" + std::to_string(i) + "]";
      LogReference l;
      f.string((*logs)[i], "name", where, l.name);
      f.string((*logs)[i], "path", where, l.path);
      f.string((*logs)[i], "sha256", where, l.sha256);
      if (!f.failed() && (l.name.empty() || l.path.empty()))
        f.fail(where, "name and path must not be empty");
      if (!f.failed() && l.sha256.size() != 64)
        f.fail(where + ".sha256", "must be 64 hexadecimal digits");
      for (const auto& other : s.logs)
        if (!f.failed() && other.name == l.name) f.fail(where, "the name '" + l.name + "' is used twice");
      if (const json* ro = f.member((*logs)[i], "read", where, false))
        readOptionsFromJson(*ro, where + ".read", l.read, f);
      s.logs.push_back(std::move(l));
    }
  }
  if (!f.failed())
    if (const json* p = f.member(j, "preprocessing", "session", true)) preprocessFromJson(*p, s, f);
  if (!f.failed())
    if (const json* rg = f.member(j, "ranges", "session", true)) {
      if (const json* e = f.member(*rg, "estimation_s", "ranges", false))
        rangeFromJson(*e, "ranges.estimation_s", s.estimation, f);
      if (const json* v = f.member(*rg, "validation_s", "ranges", false))
        rangeFromJson(*v, "ranges.validation_s", s.validation, f);
    }
  if (!f.failed())
    if (const json* parts = f.member(j, "parts", "session", true)) {
      if (!parts->is_object()) {
        f.fail("parts", "must be an object");
      } else {
        for (auto it = parts->begin(); it != parts->end() && !f.failed(); ++it) {
          const SessionPart* part = findSessionPart(it.key());
          std::string partWhy;
          if (!part)
            f.fail("parts." + it.key(), "this FlexArm does not know this part (saved by " +
                                            writer + "?)");
          else if (!part->validate(it.value(), &partWhy))
            f.fail("parts." + it.key(), partWhy);
        }
        if (!f.failed()) s.parts = *parts;
      }
    }
  if (f.failed()) {
    r.message = "damaged session: " + why;
    r.session = Session{};
    return r;
  }
  r.ok = true;
  return r;
}

SessionParseResult loadSession(const std::string& path) {
  SessionParseResult r;
  FileBytes bytes;
  std::string problem;
  if (!readInputFile(path, kMaxSessionBytes, bytes, &problem)) {
    r.message = path + ": " + problem;
    return r;
  }
  if (std::string enc = textEncodingProblem(bytes.view()); !enc.empty()) {
    r.message = path + ": " + enc;
    return r;
  }
  r = parseSession(std::string(bytes.view()));
  if (!r.ok) r.message = path + ": " + r.message;
  return r;
}

bool saveSession(const Session& session, const std::string& path, std::string* why) {
  return writeFileAtomically(path, toJsonText(session), why);
}

std::string resolveLogPath(const std::string& sessionPath, const std::string& logPath) {
  const fs::path p(logPath);
  if (p.is_absolute()) return logPath;
  return (fs::path(sessionPath).parent_path() / p).lexically_normal().string();
}

std::string storedLogPath(const std::string& sessionPath, const std::string& logPath) {
  std::error_code ec;
  const fs::path log = fs::absolute(logPath, ec).lexically_normal();
  const fs::path dir = fs::absolute(sessionPath, ec).parent_path().lexically_normal();
  const fs::path rel = log.lexically_relative(dir);
  if (!rel.empty() && *rel.begin() != "..") return rel.generic_string();
  return log.string();
}

std::vector<std::string> describePreprocessing(const PreprocessOptions& p) {
  std::vector<std::string> steps;
  if (p.resample) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "resampling onto a uniform %.6g Hz grid (%s for irregular time stamps, ",
                  p.resample->rateHz, toString(p.resample->method));
    std::string text = buf;
    if (p.resample->maxGapSeconds > 0.0)
      text += "gaps up to " + durationText(p.resample->maxGapSeconds);
    else
      text += "gaps up to ten sample intervals";
    std::snprintf(buf, sizeof buf, "; anti-alias FIR, %.0f dB)", p.resample->stopbandDb);
    steps.push_back(text + buf);
  }
  if (p.differentiateAngle)
    steps.push_back("motor velocity from the motor angle by central differences (the output)");
  if (p.range)
    steps.push_back("keep samples " + std::to_string(p.range->begin) + " to " +
                    std::to_string(p.range->end));
  if (p.decimation.factor > 1) {
    std::string filter = toString(p.decimation.filter);
    if (p.decimation.filter == AntiAliasFilter::Fir)
      filter += ", " + std::to_string(static_cast<int>(std::lround(p.decimation.stopbandDb))) + " dB";
    steps.push_back("decimation by " + std::to_string(p.decimation.factor) + " (anti-alias " +
                    filter + ")");
  }
  if (p.detrend != Detrend::None)
    steps.push_back(std::string(p.detrend == Detrend::Mean ? "mean" : "linear trend") +
                    " removal");
  return steps;
}

}  // namespace flexarm
