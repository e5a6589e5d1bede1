#pragma once
// Runs the flexarm executable and captures its exit code, standard output and error.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <csignal>
#include <sys/resource.h>
#include <sys/wait.h>
#include <vector>
#include <unistd.h>

namespace flexarm::test {

struct RunResult {
  int code = -1;
  std::string out, err;
};

inline std::string readAll(const std::string& path) {
  std::string text;
  if (FILE* f = std::fopen(path.c_str(), "rb")) {
    std::array<char, 4096> buf;
    std::size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) text.append(buf.data(), n);
    std::fclose(f);
  }
  return text;
}

// The text of a rendered PDF (pdftotext -layout, written beside it); empty when pdftotext
// failed. The PDF's font sets "ff", "fi", "fl", "ffi" and "ffl" as ligatures: they are read
// back as letters.
inline std::string pdfText(const std::string& pdf) {
  const std::string txt = pdf + ".txt";
  const std::string cmd = "pdftotext -layout '" + pdf + "' '" + txt + "'";
  if (std::system(cmd.c_str()) != 0) return {};
  std::string text = readAll(txt);
  for (const auto& [lig, letters] :
       {std::pair<std::string, std::string>{"\xef\xac\x80", "ff"}, {"\xef\xac\x81", "fi"},
        {"\xef\xac\x82", "fl"}, {"\xef\xac\x83", "ffi"}, {"\xef\xac\x84", "ffl"}})
    for (std::size_t at; (at = text.find(lig)) != std::string::npos;) text.replace(at, lig.size(), letters);
  return text;
}

inline std::filesystem::path scratchDir() {
  auto p = std::filesystem::temp_directory_path() / ("flexarm_cli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(p);
  return p;
}

// args are passed through the shell, each single-quoted.
inline RunResult runFlexarm(const std::vector<std::string>& args) {
  const auto dir = scratchDir();
  static int counter = 0;
  const std::string out = (dir / ("out" + std::to_string(counter))).string();
  const std::string err = (dir / ("err" + std::to_string(counter++))).string();
  std::string cmd = std::string("'") + FLEXARM_EXE + "'";
  for (const auto& a : args) cmd += " '" + a + "'";
  cmd += " >'" + out + "' 2>'" + err + "' </dev/null";
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readAll(out);
  r.err = readAll(err);
  return r;
}

// The sanitizers reserve terabytes of address space and keep freed memory in quarantine:
// under them an address-space limit cannot be set and resident memory runs higher.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderAddressSanitizer = true;
#else
inline constexpr bool kUnderAddressSanitizer = false;
#endif
#else
inline constexpr bool kUnderAddressSanitizer = false;
#endif

// Peak memory allowed for a run that should stay near the given size in a Release build;
// the sanitizers add their shadow memory and quarantine.
inline long ceilingMb(long mb) { return kUnderAddressSanitizer ? 3 * mb + 400 : mb; }

// A large hostile file, made by scripts/make_hostile_data.py --big in this test's scratch
// folder; empty when the script failed.
inline std::string bigHostileFile(const std::string& name, const std::string& extension) {
  const std::filesystem::path d = scratchDir() / "hostile_big";
  std::filesystem::create_directories(d);
  const std::string cmd = "python3 '" + std::string(FLEXARM_SOURCE_DIR) + "/scripts/make_hostile_data.py' --big '" +
                          d.string() + "' " + name;
  if (std::system(cmd.c_str()) != 0) return {};
  return (d / (name + extension)).string();
}

struct MeasuredRun : RunResult {
  long maxRssMb = -1;  // peak resident memory of the flexarm process
  bool timedOut = false;  // killed at RunLimits::timeoutSeconds
  // With RunLimits::traceFiles: every file the run opened, created, renamed or removed outside
  // the places it may touch (scratchDir() for writes; that, the source tree, the build and the
  // system's libraries and /proc, /sys for reads), one "read PATH" or "write PATH" each.
  std::vector<std::string> outsideAccess;
  // With RunLimits::traceFiles: each file the run created (an open with O_CREAT), as "PATH FLAGS".
  std::vector<std::string> creations;
  bool traced = false;  // the trace was taken (strace ran)
};

struct RunLimits {
  long addressSpaceMb = 4096;  // a runaway allocation fails here instead of eating the machine
  long fileSizeBlocks = -1;    // RLIMIT_FSIZE in 512-byte blocks (simulates a full disk); -1: none
  int timeoutSeconds = 120;    // wall clock; the run (and all it started) is killed after it
  bool traceFiles = false;     // run under strace and fill MeasuredRun::outsideAccess
};

// The files a traced run touched outside where it may (see MeasuredRun::outsideAccess), from
// strace's logs traceLog.PID (one per process and thread).
inline std::vector<std::string> accessesOutside(const std::string& traceLog,
                                                std::vector<std::string>* creations = nullptr) {
  const std::string scratch = scratchDir().string() + "/";
  const std::string source = std::string(FLEXARM_SOURCE_DIR) + "/";
  const std::string build = std::filesystem::path(FLEXARM_EXE).parent_path().parent_path().string() + "/";
  auto under = [](const std::string& path, const std::string& dir) { return path.rfind(dir, 0) == 0; };
  auto readable = [&](const std::string& path) {
    for (const char* dir : {"/lib/", "/lib64/", "/usr/", "/proc/", "/sys/", "/etc/ld.so.", "/etc/localtime"})
      if (under(path, dir)) return true;
    return path == "/dev/null" || path == "/dev/urandom" || under(path, scratch) || under(path, source) ||
           under(path, build);
  };
  std::vector<std::string> outside;
  const std::filesystem::path log(traceLog);
  for (const auto& entry : std::filesystem::directory_iterator(log.parent_path())) {
    if (entry.path().filename().string().rfind(log.filename().string() + ".", 0) != 0) continue;
    const std::string text = readAll(entry.path().string());
    for (std::size_t from = 0; from < text.size();) {
      const std::size_t end = std::min(text.find('\n', from), text.size());
      const std::string line = text.substr(from, end - from);
      from = end + 1;
      const auto eq = line.rfind(" = ");
      if (eq == std::string::npos || line.compare(eq + 3, 2, "-1") == 0) continue;  // failed calls touch nothing
      const bool open = line.compare(0, 4, "open") == 0 || line.compare(0, 5, "creat") == 0;
      const bool writes = !open || line.compare(0, 5, "creat") == 0 || line.find("O_WRONLY") != std::string::npos ||
                          line.find("O_RDWR") != std::string::npos || line.find("O_CREAT") != std::string::npos;
      for (std::size_t q1 = line.find('"'); q1 != std::string::npos && q1 < eq; q1 = line.find('"', q1 + 1)) {
        const auto q2 = line.find('"', q1 + 1);
        if (q2 == std::string::npos) break;
        std::string path = line.substr(q1 + 1, q2 - q1 - 1);
        q1 = q2;
        if (!path.empty() && path[0] != '/') path = std::filesystem::current_path().string() + "/" + path;
        path = std::filesystem::path(path).lexically_normal().string();
        if (writes ? !under(path, scratch) : !readable(path)) outside.push_back((writes ? "write " : "read ") + path);
        if (open && creations && line.find("O_CREAT") != std::string::npos)
          creations->push_back(path + " " + line.substr(q2 + 1, eq - q2 - 1));
        if (open) break;  // the path opened; later strings are not paths
      }
    }
  }
  return outside;
}

// Runs flexarm directly (no shell) with limits, and measures its peak resident memory.
inline MeasuredRun runFlexarmMeasured(const std::vector<std::string>& args, RunLimits limits = {}) {
  const auto dir = scratchDir();
  static int counter = 0;
  const std::string out = (dir / ("mout" + std::to_string(counter))).string();
  const std::string err = (dir / ("merr" + std::to_string(counter++))).string();
  MeasuredRun r;
  const std::string trace = (dir / ("trace" + std::to_string(counter))).string();
  const bool traced = limits.traceFiles && std::system("command -v strace > /dev/null 2>&1") == 0;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);  // one process group: a timeout kills the run and all it started
    std::freopen("/dev/null", "r", stdin);
    std::freopen(out.c_str(), "w", stdout);
    std::freopen(err.c_str(), "w", stderr);
    if (!kUnderAddressSanitizer && limits.addressSpaceMb > 0) {
      rlimit as{static_cast<rlim_t>(limits.addressSpaceMb) << 20, static_cast<rlim_t>(limits.addressSpaceMb) << 20};
      ::setrlimit(RLIMIT_AS, &as);
    }
    if (limits.fileSizeBlocks >= 0) {
      std::signal(SIGXFSZ, SIG_IGN);  // write() then fails with EFBIG, as on a full disk
      rlimit fs{static_cast<rlim_t>(limits.fileSizeBlocks) * 512, static_cast<rlim_t>(limits.fileSizeBlocks) * 512};
      ::setrlimit(RLIMIT_FSIZE, &fs);
    }
    if (traced && kUnderAddressSanitizer) {  // LeakSanitizer cannot run under ptrace; untraced runs check leaks
      const char* asan = std::getenv("ASAN_OPTIONS");
      ::setenv("ASAN_OPTIONS", (std::string(asan ? asan : "") + ":detect_leaks=0").c_str(), 1);
    }
    std::vector<std::string> command;
    if (traced)  // the calls that open, create, rename or remove a file, of every thread and child
      command = {"/usr/bin/env", "strace", "-ff", "-qq", "-o", trace, "-e",
                 "trace=open,openat,creat,rename,renameat,renameat2,unlink,unlinkat,mkdir,mkdirat,link,linkat,"
                 "symlink,symlinkat,truncate,mknod,mknodat"};
    command.push_back(FLEXARM_EXE);
    command.insert(command.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : command) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    std::_Exit(127);
  }
  int status = 0;
  rusage usage{};
  // Waits up to the time limit, then kills the whole process group.
  for (int waited = 0;; waited += 20) {
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (waited >= limits.timeoutSeconds * 1000) {
      r.timedOut = true;
      ::kill(-pid, SIGKILL);
      ::wait4(pid, &status, 0, &usage);
      break;
    }
    ::usleep(20000);
  }
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.maxRssMb = usage.ru_maxrss / 1024;
  r.out = readAll(out);
  r.err = readAll(err);
  if (traced) {
    r.traced = true;
    r.outsideAccess = accessesOutside(trace, &r.creations);
  }
  return r;
}

}  // namespace flexarm::test
