#pragma once
// The fleet's store: an SQLite file with every analysed log (by the SHA-256 of its bytes and
// of its axis' reference log), its estimates and verdict, each axis' reference (theta_0 as
// JSON) and each run. Schema versioned (meta.schema_version), WAL journal: one process writes
// (a writer holds FILE.writer and the file itself locked for its run), any number read while it writes. Each
// batch of results is one transaction, so a run killed at any point keeps every batch it
// committed and a rerun skips them. Keep the file on a local disk: SQLite's locking is not
// safe over a network file system.
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/fleet/log_analysis.h"

struct sqlite3;

namespace flexarm {

inline constexpr int kFleetSchemaVersion = 1;

struct StoredAxis {
  std::string robot;
  int axis = 0;
  std::string referenceSha256;
  std::string referenceLog;             // its path, as the manifest resolved it
  std::optional<double> referenceTemperatureC;
  std::string referenceJson;            // referenceToJson
};

struct StoredLog {
  std::string robot;
  int axis = 0;
  std::string time;                     // ISO 8601, as in the manifest
  double day = 0.0;                     // days since the epoch
  std::string path;
  std::optional<double> temperatureC;
  std::string role;                     // "reference" or empty
  FleetLogResult result;
};

struct StoredRun {
  long id = 0;
  std::string started, finished, engine, manifest;
  int analysed = 0, skipped = 0, failed = 0;
  double seconds = 0.0;
};

class FleetStore {
 public:
  // Opens (creating it when writable and absent) the store at path. A writer takes the
  // writer lock and fails with a sentence when another process holds it; a store of another
  // schema version, or a file that is not a FlexArm store, is refused with a sentence.
  static std::unique_ptr<FleetStore> open(const std::string& path, bool writable, std::string* why);
  ~FleetStore();
  FleetStore(const FleetStore&) = delete;
  FleetStore& operator=(const FleetStore&) = delete;

  const std::string& path() const { return path_; }
  int schemaVersion() const;
  std::string journalMode() const;

  std::optional<StoredAxis> axis(const std::string& robot, int axis) const;
  std::vector<StoredAxis> axes() const;
  bool putAxis(const StoredAxis& axis, std::string* why);

  // (log SHA-256, reference SHA-256) of every stored log.
  std::set<std::pair<std::string, std::string>> storedKeys() const;
  // Stores the logs in one transaction (a log already stored is left as it is).
  bool putLogs(const std::vector<StoredLog>& logs, long runId, std::string* why);
  // The logs of an axis analysed against the given reference, in time order (every axis and
  // reference when robot is empty).
  std::vector<StoredLog> logs(const std::string& robot = {}, int axis = 0,
                              const std::string& referenceSha256 = {}) const;
  std::size_t logCount() const;

  long beginRun(const std::string& engine, const std::string& manifest, std::string* why);
  bool finishRun(const StoredRun& run, std::string* why);
  std::vector<StoredRun> runs() const;

  // The SHA-256 of a file as last hashed, when its size, modification time (ns) and inode are
  // still those recorded: a rerun need not read every log of the manifest again.
  struct FileStamp {
    long long size = 0, mtimeNs = 0, inode = 0;
  };
  std::optional<std::string> knownSha256(const std::string& path, const FileStamp& stamp) const;
  // Records hashed files in one transaction.
  bool putSha256(const std::vector<std::pair<std::string, std::pair<FileStamp, std::string>>>& files, std::string* why);

  std::optional<std::string> meta(const std::string& key) const;

  // The first read that failed (a damaged page, a statement SQLite refused) since the store
  // was opened, as a sentence; a caller that read the store checks it before trusting what it
  // read as whole.
  std::optional<std::string> readError() const;
  bool setMeta(const std::string& key, const std::string& value, std::string* why);

 private:
  FleetStore() = default;
  bool exec(const std::string& sql, std::string* why) const;
  sqlite3* db_ = nullptr;
  int lockFd_ = -1;
  int fileFd_ = -1;          // the store file itself, flock'ed for a writer's run
  bool writerOpen_ = false;  // meta writer_open is set; cleared on a clean close
  mutable std::string readError_;
  std::string path_;
};

}  // namespace flexarm
