#include "core/fleet/store.h"

#include <sqlite3.h>

#include "core/session/provenance.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sys/file.h>
#include <unistd.h>

namespace flexarm {

namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS axes(
  robot TEXT NOT NULL, axis INTEGER NOT NULL,
  reference_sha256 TEXT NOT NULL, reference_log TEXT NOT NULL, reference_temperature_c REAL,
  reference_json TEXT NOT NULL,
  PRIMARY KEY(robot, axis));
CREATE TABLE IF NOT EXISTS logs(
  sha256 TEXT NOT NULL, reference_sha256 TEXT NOT NULL,
  robot TEXT NOT NULL, axis INTEGER NOT NULL, time TEXT NOT NULL, day REAL NOT NULL,
  path TEXT NOT NULL, temperature_c REAL, role TEXT NOT NULL,
  ok INTEGER NOT NULL, message TEXT NOT NULL, verdict TEXT NOT NULL, verdict_time_s REAL,
  seconds REAL NOT NULL, run INTEGER,
  PRIMARY KEY(sha256, reference_sha256));
CREATE INDEX IF NOT EXISTS logs_axis ON logs(robot, axis, day);
CREATE TABLE IF NOT EXISTS estimates(
  sha256 TEXT NOT NULL, reference_sha256 TEXT NOT NULL, parameter TEXT NOT NULL,
  value REAL NOT NULL, std REAL NOT NULL, reference REAL NOT NULL, position INTEGER NOT NULL,
  PRIMARY KEY(sha256, reference_sha256, parameter));
CREATE TABLE IF NOT EXISTS files(
  path TEXT PRIMARY KEY, size INTEGER NOT NULL, mtime_ns INTEGER NOT NULL, inode INTEGER NOT NULL,
  sha256 TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs(
  id INTEGER PRIMARY KEY, started TEXT NOT NULL, finished TEXT, engine TEXT NOT NULL,
  manifest TEXT NOT NULL, analysed INTEGER, skipped INTEGER, failed INTEGER, seconds REAL);
)sql";

// A prepared statement, finalised when it goes out of scope. A statement that failed to
// prepare (a table another program changed) does nothing: step() says SQLITE_ERROR and the
// columns read as empty, so a caller that checks step() never touches a null handle.
class Statement {
 public:
  // sink, when given, receives the first error (a failed prepare or step) as a sentence.
  Statement(sqlite3* db, const char* sql, std::string* sink = nullptr) : db_(db), sink_(sink) {
    ok_ = sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) == SQLITE_OK && s_;
    if (!ok_) note();
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return ok_; }
  void bind(int i, const std::string& v) {
    if (ok_) sqlite3_bind_text(s_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void bind(int i, double v) {
    if (ok_) sqlite3_bind_double(s_, i, v);
  }
  void bind(int i, int v) {
    if (ok_) sqlite3_bind_int(s_, i, v);
  }
  void bind(int i, long v) {
    if (ok_) sqlite3_bind_int64(s_, i, v);
  }
  void bind(int i, const std::optional<double>& v) {
    if (!ok_) return;
    if (v) sqlite3_bind_double(s_, i, *v);
    else sqlite3_bind_null(s_, i);
  }
  int step() {
    if (!ok_) return SQLITE_ERROR;
    const int rc = sqlite3_step(s_);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) note();
    return rc;
  }
  void reset() {
    if (!ok_) return;
    sqlite3_reset(s_);
    sqlite3_clear_bindings(s_);
  }
  std::string text(int c) const {
    const auto* p = ok_ ? sqlite3_column_text(s_, c) : nullptr;
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(s_, c)))
             : std::string();
  }
  double real(int c) const { return ok_ ? sqlite3_column_double(s_, c) : 0.0; }
  long integer(int c) const { return ok_ ? static_cast<long>(sqlite3_column_int64(s_, c)) : 0; }
  std::optional<double> optionalReal(int c) const {
    if (!ok_ || sqlite3_column_type(s_, c) == SQLITE_NULL) return std::nullopt;
    return sqlite3_column_double(s_, c);
  }

 private:
  void note() {
    if (sink_ && sink_->empty()) *sink_ = std::string("SQLite says: ") + sqlite3_errmsg(db_);
  }
  sqlite3* db_ = nullptr;
  std::string* sink_ = nullptr;
  sqlite3_stmt* s_ = nullptr;
  bool ok_ = false;
};

// The tables FlexArm writes and their columns, in order: a store holding anything else (a
// view, a trigger, a table of other columns) was changed by another program and is refused
// before any of it runs.
const std::vector<std::pair<std::string, std::vector<std::string>>>& expectedTables() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> t = {
      {"meta", {"key", "value"}},
      {"axes", {"robot", "axis", "reference_sha256", "reference_log", "reference_temperature_c", "reference_json"}},
      {"logs", {"sha256", "reference_sha256", "robot", "axis", "time", "day", "path", "temperature_c", "role", "ok",
                "message", "verdict", "verdict_time_s", "seconds", "run"}},
      {"estimates", {"sha256", "reference_sha256", "parameter", "value", "std", "reference", "position"}},
      {"files", {"path", "size", "mtime_ns", "inode", "sha256"}},
      {"runs", {"id", "started", "finished", "engine", "manifest", "analysed", "skipped", "failed", "seconds"}}};
  return t;
}

std::string shortName(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 60)) out += (static_cast<unsigned char>(c) < 0x20) ? '?' : c;
  return s.size() > 60 ? out + "..." : out;
}

// Empty when the store's schema is the one FlexArm writes; else what differs.
std::string schemaProblem(sqlite3* db) {
  Statement objects(db, "SELECT type, name, tbl_name, coalesce(sql, '') FROM sqlite_master ORDER BY rowid");
  if (!objects.ok()) return "its schema cannot be read";
  const auto& tables = expectedTables();
  auto known = [&](const std::string& name) {
    for (const auto& [t, columns] : tables)
      if (t == name) return true;
    return false;
  };
  std::vector<std::string> present;
  int rc;
  while ((rc = objects.step()) == SQLITE_ROW) {
    const std::string type = objects.text(0), name = objects.text(1), table = objects.text(2), sql = objects.text(3);
    if (type == "table" && known(name) && sql.rfind("CREATE TABLE", 0) == 0) {
      present.push_back(name);
      continue;
    }
    if (type == "index" && known(table) && (name == "logs_axis" || name.rfind("sqlite_autoindex_" + table, 0) == 0))
      continue;
    return "it holds " + type + " '" + shortName(name) + "', which FlexArm does not write (another program changed it)";
  }
  if (rc != SQLITE_DONE) return std::string("its schema cannot be read (SQLite says: ") + sqlite3_errmsg(db) + ")";
  for (const auto& name : present) {
    std::vector<std::string> columns;
    Statement info(db, "SELECT name FROM pragma_table_info(?) ORDER BY cid");
    info.bind(1, name);
    while (info.step() == SQLITE_ROW) columns.push_back(info.text(0));
    for (const auto& [t, expected] : tables)
      if (t == name && columns != expected)
        return "its table '" + name + "' has other columns than FlexArm writes (another program changed it)";
  }
  return {};
}

// SQLite's sentence for the last failure; "not an error" (its text for SQLITE_OK, as after a
// ROLLBACK) is never passed on as one.
std::string errorOf(sqlite3* db) {
  if (!db) return "out of memory";
  if (sqlite3_errcode(db) == SQLITE_OK) return "a statement did not complete (SQLite gives no reason)";
  return sqlite3_errmsg(db);
}

// Why a store could not be read, by SQLite's error code: a full disk or a locked file is not
// "not a store".
std::string readProblem(sqlite3* db) {
  const int code = db ? (sqlite3_errcode(db) & 0xff) : SQLITE_NOMEM;
  switch (code) {
    case SQLITE_NOTADB:
    case SQLITE_CORRUPT:
      return "not a FlexArm fleet store (SQLite says: " + errorOf(db) + ")";
    case SQLITE_FULL:
      return "the disk holding it is full (SQLite says: " + errorOf(db) + ")";
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return "another program holds it locked (SQLite says: " + errorOf(db) + ")";
    case SQLITE_NOMEM:
      return "out of memory while opening it";
    default:
      return "cannot be read (SQLite says: " + errorOf(db) + ")";
  }
}

}  // namespace

std::unique_ptr<FleetStore> FleetStore::open(const std::string& path, bool writable, std::string* why) {
  auto fail = [&](const std::string& s) -> std::unique_ptr<FleetStore> {
    if (why) *why = path + ": " + s;
    return nullptr;
  };
  std::unique_ptr<FleetStore> store(new FleetStore);
  store->path_ = path;
  std::error_code ec;
  const bool exists = std::filesystem::exists(path, ec);
  if (exists && !std::filesystem::is_regular_file(path, ec)) return fail("not a regular file");
  if (!exists && !writable) return fail("no such store");
  if (writable) {
    // A store is written in place, so neither it nor its lock may be a link planted to send
    // the writes elsewhere (SQLITE_OPEN_NOFOLLOW below, O_NOFOLLOW here).
    if (std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec)))
      return fail("is a symbolic link; FlexArm writes only regular files and does not follow a link");
    const std::string lock = path + ".writer";
    store->lockFd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (store->lockFd_ < 0 && errno == ELOOP)
      return fail("the writer lock " + lock + " is a symbolic link; FlexArm does not follow it");
    if (store->lockFd_ < 0) return fail("cannot create the writer lock " + lock + ": " + std::strerror(errno));
    if (::flock(store->lockFd_, LOCK_EX | LOCK_NB) != 0)
      return fail("another flexarm fleet is writing to this store (it holds " + lock + "); one writer at a time");
    // The lock by name misses the same file reached by another name (a hard link): the store
    // file itself is locked too (flock, apart from SQLite's own POSIX locks), for the run.
    store->fileFd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (store->fileFd_ < 0) return fail(std::string("cannot open the store: ") + std::strerror(errno));
    if (::flock(store->fileFd_, LOCK_EX | LOCK_NB) != 0)
      return fail("another flexarm fleet is writing to this store under another name (a link to the same file); "
                  "one writer at a time");
  }
  const int flags =
      writable ? (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOFOLLOW) : SQLITE_OPEN_READONLY;
  if (sqlite3_open_v2(path.c_str(), &store->db_, flags | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK)
    return fail("cannot open the store: " + errorOf(store->db_));
  // Nothing another program planted runs inside FlexArm: no triggers, no views, no functions
  // of the schema, and no writes to SQLite's own tables.
  sqlite3_db_config(store->db_, SQLITE_DBCONFIG_ENABLE_TRIGGER, 0, nullptr);
  sqlite3_db_config(store->db_, SQLITE_DBCONFIG_ENABLE_VIEW, 0, nullptr);
  sqlite3_db_config(store->db_, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, nullptr);
  sqlite3_db_config(store->db_, SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
  sqlite3_busy_timeout(store->db_, 10000);
  std::string err;
  // Is it a FlexArm store (or a new file)?
  {
    Statement tables(store->db_, "SELECT count(*) FROM sqlite_master");
    if (!tables.ok() || tables.step() != SQLITE_ROW) return fail(readProblem(store->db_));
    const long count = tables.integer(0);
    if (count > 0) {
      Statement v(store->db_, "SELECT value FROM meta WHERE key = 'schema_version'");
      if (!v.ok() || v.step() != SQLITE_ROW) return fail("not a FlexArm fleet store (no schema version)");
      const std::string version = v.text(0);
      if (version != std::to_string(kFleetSchemaVersion))
        return fail("store schema version " + shortName(version) + ", this FlexArm reads version " +
                    std::to_string(kFleetSchemaVersion));
      if (const std::string problem = schemaProblem(store->db_); !problem.empty())
        return fail("not a FlexArm fleet store as FlexArm wrote it: " + problem + "; FlexArm does not use it");
    } else if (!writable) {
      return fail("an empty file, not a FlexArm fleet store");
    }
  }
  if (writable) {
    // A writer that did not close cleanly (killed, the machine down) leaves writer_open set:
    // the next writer checks the whole file before adding to it.
    if (store->meta("writer_open") == std::optional<std::string>("1")) {
      Statement check(store->db_, "PRAGMA integrity_check(5)");
      std::string verdict;
      while (check.step() == SQLITE_ROW) verdict += (verdict.empty() ? "" : "; ") + check.text(0);
      if (verdict != "ok")
        return fail("the store is damaged (SQLite's integrity check: " + shortName(verdict.empty() ? readProblem(store->db_) : verdict) +
                    "); restore it from a copy or start another store");
    }
    if (!store->exec("PRAGMA journal_mode=WAL", &err) || !store->exec("PRAGMA synchronous=NORMAL", &err) ||
        !store->exec("BEGIN IMMEDIATE", &err) || !store->exec(kSchema, &err) ||
        !store->exec("INSERT OR IGNORE INTO meta(key, value) VALUES('schema_version', '" +
                         std::to_string(kFleetSchemaVersion) + "')", &err) ||
        !store->exec("INSERT OR IGNORE INTO meta(key, value) VALUES('created', '" + utcNow() + "')", &err) ||
        !store->exec("INSERT OR REPLACE INTO meta(key, value) VALUES('writer_open', '1')", &err) ||
        !store->exec("COMMIT", &err))
      return fail("cannot prepare the store: " + err);
    store->writerOpen_ = true;
  }
  return store;
}

FleetStore::~FleetStore() {
  if (db_ && writerOpen_) exec("INSERT OR REPLACE INTO meta(key, value) VALUES('writer_open', '0')", nullptr);
  if (db_) sqlite3_close_v2(db_);
  if (fileFd_ >= 0) ::close(fileFd_);
  if (lockFd_ >= 0) ::close(lockFd_);  // releases the writer lock
}

std::optional<std::string> FleetStore::readError() const {
  if (readError_.empty()) return std::nullopt;
  return path_ + ": the store could not be read whole (" + readError_ + "); it may be damaged";
}

bool FleetStore::exec(const std::string& sql, std::string* why) const {
  char* msg = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &msg) == SQLITE_OK) return true;
  if (why) *why = msg ? msg : errorOf(db_);
  sqlite3_free(msg);
  return false;
}

int FleetStore::schemaVersion() const {
  const auto v = meta("schema_version");
  return v ? std::stoi(*v) : 0;
}

std::string FleetStore::journalMode() const {
  Statement s(db_, "PRAGMA journal_mode");
  return s.ok() && s.step() == SQLITE_ROW ? s.text(0) : std::string();
}

std::optional<std::string> FleetStore::meta(const std::string& key) const {
  Statement s(db_, "SELECT value FROM meta WHERE key = ?");
  if (!s.ok()) return std::nullopt;
  s.bind(1, key);
  if (s.step() != SQLITE_ROW) return std::nullopt;
  return s.text(0);
}

bool FleetStore::setMeta(const std::string& key, const std::string& value, std::string* why) {
  Statement s(db_, "INSERT OR REPLACE INTO meta(key, value) VALUES(?, ?)");
  s.bind(1, key);
  s.bind(2, value);
  if (s.ok() && s.step() == SQLITE_DONE) return true;
  if (why) *why = errorOf(db_);
  return false;
}

namespace {

StoredAxis axisRow(const Statement& s) {
  StoredAxis a;
  a.robot = s.text(0);
  a.axis = static_cast<int>(s.integer(1));
  a.referenceSha256 = s.text(2);
  a.referenceLog = s.text(3);
  a.referenceTemperatureC = s.optionalReal(4);
  a.referenceJson = s.text(5);
  return a;
}

constexpr const char* kAxisColumns =
    "SELECT robot, axis, reference_sha256, reference_log, reference_temperature_c, reference_json FROM axes";

}  // namespace

std::optional<StoredAxis> FleetStore::axis(const std::string& robot, int axis) const {
  Statement s(db_, (std::string(kAxisColumns) + " WHERE robot = ? AND axis = ?").c_str(), &readError_);
  if (!s.ok()) return std::nullopt;
  s.bind(1, robot);
  s.bind(2, axis);
  if (s.step() != SQLITE_ROW) return std::nullopt;
  return axisRow(s);
}

std::vector<StoredAxis> FleetStore::axes() const {
  std::vector<StoredAxis> out;
  Statement s(db_, (std::string(kAxisColumns) + " ORDER BY robot, axis").c_str(), &readError_);
  while (s.ok() && s.step() == SQLITE_ROW) out.push_back(axisRow(s));
  return out;
}

bool FleetStore::putAxis(const StoredAxis& a, std::string* why) {
  Statement s(db_,
              "INSERT OR REPLACE INTO axes(robot, axis, reference_sha256, reference_log, "
              "reference_temperature_c, reference_json) VALUES(?, ?, ?, ?, ?, ?)");
  s.bind(1, a.robot);
  s.bind(2, a.axis);
  s.bind(3, a.referenceSha256);
  s.bind(4, a.referenceLog);
  s.bind(5, a.referenceTemperatureC);
  s.bind(6, a.referenceJson);
  if (s.ok() && s.step() == SQLITE_DONE) return true;
  if (why) *why = "cannot store the reference of " + a.robot + " axis " + std::to_string(a.axis) + ": " + errorOf(db_);
  return false;
}

std::set<std::pair<std::string, std::string>> FleetStore::storedKeys() const {
  std::set<std::pair<std::string, std::string>> out;
  Statement s(db_, "SELECT sha256, reference_sha256 FROM logs", &readError_);
  while (s.ok() && s.step() == SQLITE_ROW) out.emplace(s.text(0), s.text(1));
  return out;
}

bool FleetStore::putLogs(const std::vector<StoredLog>& logs, long runId, std::string* why) {
  std::string err;
  for (const auto& l : logs) {
    if (!isValidFleetLogResult(l.result, &err) || !(std::isfinite(l.day) && std::fabs(l.day) < 1e7)) {
      if (why) *why = "refused to store the result of " + shortName(l.path) + ": " + (err.empty() ? "its day is not a date" : err);
      return false;
    }
  }
  if (!exec("BEGIN IMMEDIATE", &err)) {
    if (why) *why = "cannot write to the store: " + err;
    return false;
  }
  Statement log(db_,
                "INSERT OR IGNORE INTO logs(sha256, reference_sha256, robot, axis, time, day, path, "
                "temperature_c, role, ok, message, verdict, verdict_time_s, seconds, run) "
                "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  Statement est(db_,
                "INSERT OR IGNORE INTO estimates(sha256, reference_sha256, parameter, value, std, "
                "reference, position) VALUES(?, ?, ?, ?, ?, ?, ?)");
  bool good = log.ok() && est.ok();
  for (const auto& l : logs) {
    if (!good) break;
    const auto& r = l.result;
    log.bind(1, r.sha256);
    log.bind(2, r.referenceSha256);
    log.bind(3, l.robot);
    log.bind(4, l.axis);
    log.bind(5, l.time);
    log.bind(6, l.day);
    log.bind(7, l.path);
    log.bind(8, l.temperatureC);
    log.bind(9, l.role);
    log.bind(10, r.ok ? 1 : 0);
    log.bind(11, r.message);
    log.bind(12, r.verdict);
    log.bind(13, r.verdictTimeS);
    log.bind(14, r.seconds);
    log.bind(15, runId);
    good = log.step() == SQLITE_DONE;
    log.reset();
    for (std::size_t i = 0; good && i < r.estimates.size(); ++i) {
      const auto& e = r.estimates[i];
      est.bind(1, r.sha256);
      est.bind(2, r.referenceSha256);
      est.bind(3, e.name);
      est.bind(4, e.value);
      est.bind(5, e.std);
      est.bind(6, e.reference);
      est.bind(7, static_cast<int>(i));
      good = est.step() == SQLITE_DONE;
      est.reset();
    }
  }
  if (!good) {
    const std::string e = errorOf(db_);
    exec("ROLLBACK", nullptr);
    if (why) *why = "cannot store the results: " + e;
    return false;
  }
  if (!exec("COMMIT", &err)) {
    exec("ROLLBACK", nullptr);
    if (why) *why = "cannot commit the results: " + err;
    return false;
  }
  return true;
}

std::vector<StoredLog> FleetStore::logs(const std::string& robot, int axis,
                                        const std::string& referenceSha256) const {
  std::string sql =
      "SELECT sha256, reference_sha256, robot, axis, time, day, path, temperature_c, role, ok, "
      "message, verdict, verdict_time_s, seconds FROM logs";
  if (!robot.empty()) sql += " WHERE robot = ?1 AND axis = ?2";
  if (!robot.empty() && !referenceSha256.empty()) sql += " AND reference_sha256 = ?3";
  sql += " ORDER BY robot, axis, day, sha256";
  std::vector<StoredLog> out;
  {
    Statement s(db_, sql.c_str(), &readError_);
    if (!robot.empty()) {
      s.bind(1, robot);
      s.bind(2, axis);
      if (!referenceSha256.empty()) s.bind(3, referenceSha256);
    }
    while (s.ok() && s.step() == SQLITE_ROW) {
      StoredLog l;
      l.result.sha256 = s.text(0);
      l.result.referenceSha256 = s.text(1);
      l.robot = s.text(2);
      l.axis = static_cast<int>(s.integer(3));
      l.time = s.text(4);
      l.day = s.real(5);
      l.path = s.text(6);
      l.temperatureC = s.optionalReal(7);
      l.role = s.text(8);
      l.result.ok = s.integer(9) != 0;
      l.result.message = s.text(10);
      l.result.verdict = s.text(11);
      l.result.verdictTimeS = s.optionalReal(12);
      l.result.seconds = s.real(13);
      out.push_back(std::move(l));
    }
  }
  Statement e(db_,
              "SELECT parameter, value, std, reference FROM estimates WHERE sha256 = ? AND "
              "reference_sha256 = ? ORDER BY position",
              &readError_);
  for (auto& l : out) {
    e.bind(1, l.result.sha256);
    e.bind(2, l.result.referenceSha256);
    while (e.ok() && e.step() == SQLITE_ROW)
      l.result.estimates.push_back({e.text(0), e.real(1), e.real(2), e.real(3)});
    e.reset();
    // What comes back is checked as what goes in: a row another program changed is shown as
    // a failure with the reason, never trended.
    std::string bad;
    if (l.result.ok && !isValidFleetLogResult(l.result, &bad)) {
      l.result.ok = false;
      l.result.message = "the store's row for this log is not one FlexArm wrote (" + bad + "); it is not trended";
    } else if (!(std::isfinite(l.day) && std::fabs(l.day) < 1e7)) {
      l.result.ok = false;
      l.result.message = "the store's row for this log has no valid day; it is not trended";
    }
  }
  return out;
}

std::optional<std::string> FleetStore::knownSha256(const std::string& path, const FileStamp& f) const {
  Statement s(db_, "SELECT sha256 FROM files WHERE path = ? AND size = ? AND mtime_ns = ? AND inode = ?");
  if (!s.ok()) return std::nullopt;  // a store opened read-only before the table existed
  s.bind(1, path);
  s.bind(2, static_cast<long>(f.size));
  s.bind(3, static_cast<long>(f.mtimeNs));
  s.bind(4, static_cast<long>(f.inode));
  if (s.step() != SQLITE_ROW) return std::nullopt;
  return s.text(0);
}

bool FleetStore::putSha256(const std::vector<std::pair<std::string, std::pair<FileStamp, std::string>>>& files,
                           std::string* why) {
  if (files.empty()) return true;
  std::string err;
  if (!exec("BEGIN IMMEDIATE", &err)) {
    if (why) *why = "cannot write to the store: " + err;
    return false;
  }
  Statement s(db_, "INSERT OR REPLACE INTO files(path, size, mtime_ns, inode, sha256) VALUES(?, ?, ?, ?, ?)");
  bool good = s.ok();
  for (const auto& [path, stamped] : files) {
    if (!good) break;
    s.bind(1, path);
    s.bind(2, static_cast<long>(stamped.first.size));
    s.bind(3, static_cast<long>(stamped.first.mtimeNs));
    s.bind(4, static_cast<long>(stamped.first.inode));
    s.bind(5, stamped.second);
    good = s.step() == SQLITE_DONE;
    s.reset();
  }
  if (!good || !exec("COMMIT", &err)) {
    const std::string e = errorOf(db_);
    exec("ROLLBACK", nullptr);
    if (why) *why = "cannot record the files' checksums: " + e;
    return false;
  }
  return true;
}

std::size_t FleetStore::logCount() const {
  Statement s(db_, "SELECT count(*) FROM logs", &readError_);
  return s.ok() && s.step() == SQLITE_ROW ? static_cast<std::size_t>(s.integer(0)) : 0;
}

long FleetStore::beginRun(const std::string& engine, const std::string& manifest, std::string* why) {
  Statement s(db_, "INSERT INTO runs(started, engine, manifest) VALUES(?, ?, ?)");
  s.bind(1, utcNow());
  s.bind(2, engine);
  s.bind(3, manifest);
  if (!s.ok() || s.step() != SQLITE_DONE) {
    if (why) *why = "cannot record the run: " + errorOf(db_);
    return 0;
  }
  return static_cast<long>(sqlite3_last_insert_rowid(db_));
}

bool FleetStore::finishRun(const StoredRun& r, std::string* why) {
  Statement s(db_,
              "UPDATE runs SET finished = ?, analysed = ?, skipped = ?, failed = ?, seconds = ? "
              "WHERE id = ?");
  s.bind(1, utcNow());
  s.bind(2, r.analysed);
  s.bind(3, r.skipped);
  s.bind(4, r.failed);
  s.bind(5, r.seconds);
  s.bind(6, r.id);
  if (s.ok() && s.step() == SQLITE_DONE) return true;
  if (why) *why = "cannot record the run's end: " + errorOf(db_);
  return false;
}

std::vector<StoredRun> FleetStore::runs() const {
  std::vector<StoredRun> out;
  Statement s(db_,
              "SELECT id, started, coalesce(finished, ''), engine, manifest, coalesce(analysed, 0), "
              "coalesce(skipped, 0), coalesce(failed, 0), coalesce(seconds, 0) FROM runs ORDER BY id",
              &readError_);
  while (s.ok() && s.step() == SQLITE_ROW) {
    StoredRun r;
    r.id = s.integer(0);
    r.started = s.text(1);
    r.finished = s.text(2);
    r.engine = s.text(3);
    r.manifest = s.text(4);
    r.analysed = static_cast<int>(s.integer(5));
    r.skipped = static_cast<int>(s.integer(6));
    r.failed = static_cast<int>(s.integer(7));
    r.seconds = s.real(8);
    out.push_back(r);
  }
  return out;
}

}  // namespace flexarm
