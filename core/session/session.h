#pragma once
// A session: everything an analysis needs to be reopened or replayed without a window. The
// logs it uses (path, SHA-256, read options), the preprocessing steps, the estimation and
// validation ranges, and one section per capability ("parts": the model list, view state,
// and what later capabilities add; see session_part.h). Stored as readable JSON with a format
// version; a damaged or newer file is refused as a whole with a sentence naming the problem.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/io/log_io.h"
#include "core/signal/preprocess.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

// The session format this FlexArm writes and the newest it reads.
inline constexpr int kSessionVersion = 1;
inline constexpr const char* kSessionFormat = "flexarm-session";

// A log the session uses. The path is as written in the file: relative paths are relative to
// the session file's folder.
struct LogReference {
  std::string name;    // how parts and `flexarm run --log NAME=PATH` refer to it
  std::string path;
  std::string sha256;  // of the file when the session was saved
  LogReadOptions read;
};

struct Session {
  // The first log is the one the analysis uses; further logs are for parts (e.g. validation
  // data of another experiment).
  std::vector<LogReference> logs;
  bool preprocessed = false;     // preprocessing applied (the options below are used)
  PreprocessOptions preprocess;  // resample, differentiate, range, decimate, detrend (5.2)
  std::optional<SecondsRange> estimation, validation;
  // Sections of the registered parts by key (session_part.h); each is validated on load.
  nlohmann::json parts = nlohmann::json::object();
  std::string writtenBy;  // "FlexArm 0.1.0" of the program that saved the file
};

// A range in seconds as session JSON, [start, end] or null.
nlohmann::json secondsRangeToJson(const std::optional<SecondsRange>& r);
// Reads j[key] (absent or null: no range); false with a sentence unless [start, end] with
// start < end.
bool readSecondsRange(const nlohmann::json& j, const char* key, std::optional<SecondsRange>& out,
                      std::string* why);

// The session as JSON text (pretty-printed, keys in a stable order).
std::string toJsonText(const Session& session);

struct SessionParseResult {
  bool ok = false;
  Session session;
  std::string message;  // why the text was refused
};
// Parses and validates a whole session, parts included. Refuses invalid JSON, another format,
// a version newer than kSessionVersion, missing or mistyped fields and unknown parts.
SessionParseResult parseSession(const std::string& text);

// Reads and parses a session file; the message names the file. Only regular files of at most
// kMaxSessionBytes are read.
inline constexpr std::uint64_t kMaxSessionBytes = 64ull << 20;
SessionParseResult loadSession(const std::string& path);

// Writes the session atomically (temporary sibling, then rename): a failure or a crash while
// writing leaves the previous file as it was. False with why on failure.
bool saveSession(const Session& session, const std::string& path, std::string* why);

// The path of a log as the session names it, resolved against the session file's folder.
std::string resolveLogPath(const std::string& sessionPath, const std::string& logPath);
// The path to store for a log: relative when the log lies in the session's folder or below,
// otherwise absolute.
std::string storedLogPath(const std::string& sessionPath, const std::string& logPath);

// The preprocessing steps in words, in the order they run, e.g. "motor velocity by central
// differences", "decimation by 10 (FIR anti-alias filter, 80 dB)", "mean removal".
std::vector<std::string> describePreprocessing(const PreprocessOptions& options);

}  // namespace flexarm
