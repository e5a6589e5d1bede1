#pragma once
// Replaying a session without a window: read its logs (or substitutes), check their
// checksums, apply the preprocessing and ranges, then let every part recompute its results
// into a Report. The window opens sessions through prepareSession too, so it sees exactly
// the data a replay sees.
#include <map>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/session/report.h"
#include "core/session/session.h"
#include "core/signal/id_data.h"

namespace flexarm {

// One log of a session, read and prepared.
struct PreparedLog {
  std::string name;
  std::string path;    // the file actually read
  std::string sha256;  // of that file
  std::string note;    // "substituted", "changed since the session was saved" or empty
  IdData raw;          // as read
  IdData data;         // preprocessed as the session says, ranges set from its seconds
};

struct PreparedSession {
  bool ok = false;
  std::string message;  // why the logs could not be prepared (file, line, problem)
  std::vector<PreparedLog> logs;
  std::vector<std::string> warnings;  // e.g. a log whose checksum differs
};

// Reads every log (substitutes[name] replaces a log's path), computes its checksum and
// applies the preprocessing and ranges. Fails as a whole: a missing or unreadable log, a
// substitute for an unknown name, or preprocessing the data do not allow.
PreparedSession prepareSession(const Session& session, const std::string& sessionPath,
                               const std::map<std::string, std::string>& substitutes = {});

struct ReplayOptions {
  std::map<std::string, std::string> substitutes;  // log name -> path
  ProgressCallback progress;
  bool isValid(std::string* why) const;
};

struct ReplayResult {
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  bool badInput = false;  // the failure is in the input files (exit code 3, not 4)
  Report report;
};

// Prepares the session and replays every part into a report: a "Data" section (logs,
// channels, rate, preprocessing, ranges) followed by each part's sections.
ReplayResult replaySession(const Session& session, const std::string& sessionPath,
                           const ReplayOptions& options = {});

}  // namespace flexarm
