// The Slurm engine: the work cut into chunks of many items, one array task per chunk, each
// task writing its results as a file into the run's folder; this process merges the files as
// they appear and is the store's only writer.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fcntl.h>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <poll.h>
#include <set>
#include <spawn.h>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "core/common/text.h"
#include "core/fleet/work.h"
#include "core/io/log_io.h"

extern char** environ;

namespace flexarm::fleet {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct CommandResult {
  int status = -1;       // exit status, -1 when killed
  std::string output;    // standard output and error
  bool timedOut = false;
};

// Runs argv (searched on PATH) with its output captured, killed after timeoutS.
std::optional<CommandResult> runCommand(const std::vector<std::string>& argv, double timeoutS, std::string* why) {
  int fds[2];
  if (::pipe(fds) != 0) {
    if (why) *why = std::string("cannot make a pipe: ") + std::strerror(errno);
    return std::nullopt;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  if (rc != 0) {
    ::close(fds[0]);
    if (why) *why = "cannot run " + argv[0] + ": " + std::strerror(rc);
    return std::nullopt;
  }
  CommandResult r;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutS);
  char buf[4096];
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      r.timedOut = true;
      ::kill(pid, SIGKILL);
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long>(left.count(), 200)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n <= 0) break;
    if (r.output.size() < (1u << 20)) r.output.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.status = !r.timedOut && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string tail(const std::string& path, std::size_t bytes) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return "no output file " + path;
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (text.size() > bytes) text = "..." + text.substr(text.size() - bytes);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text.empty() ? "no output" : text;
}

// Makes dir (mode 0700), or accepts it when it is already a folder of this user and not a
// link; exclusive: it must not exist yet. Nothing is followed: a link planted at the name
// would send the chunks and job.sh (which the nodes run) into its target.
bool makeOwnFolder(const std::string& dir, bool exclusive, std::string* why) {
  if (::mkdir(dir.c_str(), 0700) == 0) return true;
  if (errno != EEXIST) {
    if (why) *why = "cannot make the Slurm folder " + dir + ": " + std::strerror(errno);
    return false;
  }
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0 || S_ISLNK(st.st_mode)) {
    if (why) *why = "the Slurm folder " + dir + " is a symbolic link; FlexArm makes this folder itself and does not follow a link";
    return false;
  }
  if (!S_ISDIR(st.st_mode)) {
    if (why) *why = "the Slurm folder " + dir + " exists and is not a folder";
    return false;
  }
  if (st.st_uid != ::geteuid()) {
    if (why) *why = "the Slurm folder " + dir + " belongs to another user; FlexArm writes only into its own";
    return false;
  }
  if (exclusive) {
    if (why) *why = "the Slurm folder " + dir + " exists already (another run's?); FlexArm starts each in a new one";
    return false;
  }
  return true;
}

// The text a scheduler command printed, cut to one readable line.
std::string schedulerSays(const CommandResult& r) {
  std::string s = r.output;
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.size() > 300) s = s.substr(0, 300) + "...";
  return s.empty() ? "no output" : s;
}

}  // namespace

bool runOnSlurm(const WorkChunk& work, const SlurmOptions& o, const std::string& runDir, const Sinks& sinks,
                std::string* why) {
  auto fail = [&](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (work.size() == 0) return true;
  std::error_code ec;
  const std::string dir = fs::absolute(runDir, ec).lexically_normal().string();
  if (ec || dir.empty()) return fail("cannot resolve the Slurm folder " + runDir);
  // The folder's name goes into job.sh: a line break there would add #SBATCH directives.
  if (hasControlCharacter(dir))
    return fail("the Slurm folder's name holds a line break or another control character; give --slurm-dir a plain path");
  // runDir is BASE/run-N/PART: BASE (--slurm-dir, or STORE.slurm) and run-N are made or
  // reused when they are this user's own folders, PART is always new.
  {
    const fs::path part(dir), run = part.parent_path(), base = run.parent_path();
    if (!base.parent_path().empty()) fs::create_directories(base.parent_path(), ec);
    std::string e;
    if (!makeOwnFolder(base.string(), false, &e) || !makeOwnFolder(run.string(), false, &e) ||
        !makeOwnFolder(part.string(), true, &e))
      return fail(e);
  }

  // Chunks: many items a task (fits take longer than logs: a quarter as many).
  std::vector<WorkChunk> chunks;
  const std::size_t perFit = static_cast<std::size_t>(std::max(1, o.logsPerTask / 4));
  const std::size_t perLog = static_cast<std::size_t>(std::max(1, o.logsPerTask));
  for (std::size_t i = 0; i < work.fits.size(); i += perFit) {
    WorkChunk c;
    c.options = work.options;
    c.fits.assign(work.fits.begin() + static_cast<long>(i),
                  work.fits.begin() + static_cast<long>(std::min(work.fits.size(), i + perFit)));
    chunks.push_back(std::move(c));
  }
  for (std::size_t i = 0; i < work.logs.size(); i += perLog) {
    WorkChunk c;
    c.options = work.options;
    c.logs.assign(work.logs.begin() + static_cast<long>(i),
                  work.logs.begin() + static_cast<long>(std::min(work.logs.size(), i + perLog)));
    for (const auto& l : c.logs)
      if (auto it = work.references.find(l.referenceSha256); it != work.references.end())
        c.references.insert(*it);
    chunks.push_back(std::move(c));
  }
  std::string err;
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    const std::string path = dir + "/chunk-" + std::to_string(k) + ".json";
    if (!writeFileAtomically(path, chunkJson(chunks[k]).dump() + "\n", &err)) return fail(err);
    fs::remove(dir + "/result-" + std::to_string(k) + ".json", ec);
  }
  const std::string script = dir + "/job.sh";
  const std::string text =
      "#!/bin/sh\n"
      "#SBATCH --job-name=flexarm-fleet\n"
      "#SBATCH --output=" + dir + "/task-%a.out\n"
      "# One task of a FlexArm fleet run: the chunk's references and logs, the results as a file.\n"
      "exec " + quoted(o.executable) + " fleet --task " + quoted(dir) + "/chunk-\"$SLURM_ARRAY_TASK_ID\".json --out " +
      quoted(dir) + "/result-\"$SLURM_ARRAY_TASK_ID\".json\n";
  if (!writeFileAtomically(script, text, &err)) return fail(err);
  fs::permissions(script, fs::perms::owner_exec, fs::perm_options::add, ec);

  std::vector<std::string> submit = {o.sbatch, "--parsable"};
  std::string array = "--array=0-" + std::to_string(chunks.size() - 1);
  if (o.maxTasksAtOnce > 0) array += "%" + std::to_string(o.maxTasksAtOnce);
  submit.push_back(array);
  for (const auto& a : o.sbatchArguments) submit.push_back(a);
  submit.push_back(script);
  const auto submitted = runCommand(submit, 120.0, &err);
  if (!submitted) return fail(err);
  if (submitted->status != 0)
    return fail("sbatch refused the job array (" + (submitted->timedOut ? std::string("no answer in 120 s") : schedulerSays(*submitted)) +
                "); is Slurm running, and can this user submit?");
  std::string jobId = submitted->output.substr(0, submitted->output.find_first_of(";\n"));
  jobId.erase(0, jobId.find_first_not_of(" \t"));
  if (jobId.empty() || jobId.find_first_not_of("0123456789") != std::string::npos)
    return fail("sbatch gave no job id: " + schedulerSays(*submitted));

  std::set<std::size_t> merged;
  bool stopped = false;
  // A task's result is checked before anything of it is merged: its format, every id one of
  // the chunk's own (once), every value as FlexArm writes it. An item whose result is bad is
  // reported with the reason and the rest of the chunk merged.
  auto merge = [&](std::size_t k) {
    const std::string path = dir + "/result-" + std::to_string(k) + ".json";
    if (!fs::exists(path, ec)) return false;
    std::ifstream f(path, std::ios::binary);
    json j;
    try {
      j = json::parse(f);
    } catch (const json::exception&) {
      return false;  // not complete yet (results are renamed into place, so rarely)
    }
    merged.insert(k);
    const std::string task = "the Slurm task " + jobId + "_" + std::to_string(k);
    if (!j.is_object() || j.value("format", json()) != "flexarm-fleet-result" || j.value("version", json()) != 1) {
      for (const auto& x : chunks[k].fits) sinks.lost(x.id, true, task + " wrote a file that is not a FlexArm task result");
      for (const auto& x : chunks[k].logs) sinks.lost(x.id, false, task + " wrote a file that is not a FlexArm task result");
      return true;
    }
    std::map<std::size_t, const ReferenceJob*> fitJobs;
    std::map<std::size_t, const LogJob*> logJobs;
    for (const auto& x : chunks[k].fits) fitJobs[x.id] = &x;
    for (const auto& x : chunks[k].logs) logJobs[x.id] = &x;
    std::set<std::size_t> seenFits, seenLogs;
    auto idOf = [](const json& r) -> std::optional<std::size_t> {
      if (!r.is_object() || !r.contains("id") || !r.at("id").is_number_unsigned()) return std::nullopt;
      return r.at("id").get<std::size_t>();
    };
    const json fits = j.value("fits", json::array()), logs = j.value("logs", json::array());
    for (const auto& r : fits.is_array() ? fits : json::array()) {
      const auto id = idOf(r);
      if (!id || !fitJobs.count(*id) || seenFits.count(*id)) continue;  // not one of the chunk's: ignored
      seenFits.insert(*id);
      ReferenceOutcome out;
      out.id = *id;
      std::string bad;
      try {
        out.ok = r.at("ok").get<bool>();
        out.message = r.at("message").get<std::string>().substr(0, 4096);
        if (out.ok) {
          std::string e;
          if (!referenceFromJson(r.at("reference"), &e)) bad = "its reference is unusable: " + e;
          out.json = r.at("reference").dump();
        }
      } catch (const json::exception&) {
        bad = "its fields are malformed";
      }
      if (!bad.empty()) sinks.lost(*id, true, task + "'s result for it is invalid: " + bad);
      else if (!stopped && !sinks.reference(out)) stopped = true;
    }
    for (const auto& r : logs.is_array() ? logs : json::array()) {
      const auto id = idOf(r);
      if (!id || !logJobs.count(*id) || seenLogs.count(*id)) continue;
      seenLogs.insert(*id);
      std::string e;
      auto result = fleetLogResultFromJson(r, &e);
      if (result && result->referenceSha256 != logJobs.at(*id)->referenceSha256) {
        e = "it names another reference";
        result.reset();
      }
      if (result && !isValidFleetLogResult(*result, &e)) result.reset();
      if (result) result->message = result->message.substr(0, 4096);
      if (!result) sinks.lost(*id, false, task + "'s result for it is invalid: " + e);
      else if (!stopped && !sinks.log(*id, std::move(*result))) stopped = true;
    }
    for (const auto& x : chunks[k].fits)
      if (!seenFits.count(x.id)) sinks.lost(x.id, true, task + "'s result lacks it");
    for (const auto& x : chunks[k].logs)
      if (!seenLogs.count(x.id)) sinks.lost(x.id, false, task + "'s result lacks it");
    return true;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.timeoutS);
  std::string ending, schedulerError;
  int failedPolls = 0;
  while (true) {
    for (std::size_t k = 0; k < chunks.size(); ++k)
      if (!merged.count(k)) merge(k);
    if (merged.size() == chunks.size()) break;
    if (stopped) {
      ending = "stopped";
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ending = "the job array " + jobId + " did not finish within " + std::to_string(static_cast<long>(o.timeoutS)) + " s";
      break;
    }
    const auto queued = runCommand({o.squeue, "-h", "-j", jobId, "-o", "%i"}, 30.0, &err);
    const bool gone = queued && !queued->timedOut &&
                      ((queued->status == 0 && queued->output.find_first_not_of(" \n") == std::string::npos) ||
                       queued->output.find("Invalid job id") != std::string::npos);
    // A scheduler that cannot answer ends the wait with its own words (three failures in a
    // row: one may be a controller restarting), not after the whole timeout.
    const bool answered = queued && !queued->timedOut && (queued->status == 0 || gone);
    failedPolls = answered ? 0 : failedPolls + 1;
    if (failedPolls >= 3) {
      schedulerError = !queued ? err
                       : queued->timedOut ? o.squeue + " gave no answer in 30 s"
                                          : o.squeue + " failed (exit " + std::to_string(queued->status) + "): " +
                                                schedulerSays(*queued);
      ending = "the scheduler could not say whether job " + jobId + " runs: " + schedulerError;
      break;
    }
    if (gone) {
      for (std::size_t k = 0; k < chunks.size(); ++k)
        if (!merged.count(k)) merge(k);
      break;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(o.pollS));
  }
  if (!ending.empty()) runCommand({o.scancel, jobId}, 30.0, &err);
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    if (merged.count(k)) continue;
    const std::string reason = (ending.empty() ? "the Slurm task " + jobId + "_" + std::to_string(k) +
                                                     " ended without a result (" +
                                                     tail(dir + "/task-" + std::to_string(k) + ".out", 400) + ")"
                                               : ending);
    for (const auto& x : chunks[k].fits) sinks.lost(x.id, true, reason);
    for (const auto& x : chunks[k].logs) sinks.lost(x.id, false, reason);
  }
  if (!schedulerError.empty()) return fail("the scheduler could not say whether job " + jobId + " runs: " + schedulerError);
  return true;
}

}  // namespace flexarm::fleet
