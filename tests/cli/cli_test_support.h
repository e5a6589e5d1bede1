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

struct MeasuredRun : RunResult {
  long maxRssMb = -1;  // peak resident memory of the flexarm process
};

struct RunLimits {
  long addressSpaceMb = 4096;  // a runaway allocation fails here instead of eating the machine
  long fileSizeBlocks = -1;    // RLIMIT_FSIZE in 512-byte blocks (simulates a full disk); -1: none
};

// Runs flexarm directly (no shell) with limits, and measures its peak resident memory.
inline MeasuredRun runFlexarmMeasured(const std::vector<std::string>& args, RunLimits limits = {}) {
  const auto dir = scratchDir();
  static int counter = 0;
  const std::string out = (dir / ("mout" + std::to_string(counter))).string();
  const std::string err = (dir / ("merr" + std::to_string(counter++))).string();
  MeasuredRun r;
  const pid_t pid = ::fork();
  if (pid == 0) {
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
    std::vector<char*> argv;
    std::string exe = FLEXARM_EXE;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(exe.c_str(), argv.data());
    std::_Exit(127);
  }
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.maxRssMb = usage.ru_maxrss / 1024;
  r.out = readAll(out);
  r.err = readAll(err);
  return r;
}

}  // namespace flexarm::test
