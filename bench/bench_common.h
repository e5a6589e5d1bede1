#pragma once
// What every bench program shares: median timing, a private temporary folder, running a peer
// (Python or Octave) and reading its JSON lines, and printing result rows.
//
// The row protocol (bench/README.md): a bench program prints one JSON object per line on
// stdout for every comparison it made, and anything else (progress, notes) on stderr:
//   {"task": "oe[2 2 1]", "size": "4000 samples", "flexarm_s": 0.0011,
//    "peer": "SciPy least_squares", "peer_s": 0.0052, "agree": true,
//    "agreement": "loss 0.2501 vs 0.2501", ...free fields...}
// Required: task, size, flexarm_s, peer, peer_s (null when the peer did not run), agree
// (true/false, null when nothing could be compared). Known free fields: agreement (what was
// compared, shown in the table), group (section of the table), scale (1, 4, 16 for the
// scaling rows), repeats, note. scripts/bench.sh runs every program and computes the ratio
// peer_s / flexarm_s.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <sys/resource.h>

namespace flexarm::bench {

using Json = nlohmann::json;

// FLEXARM_BENCH_QUICK=1 runs fewer repeats (a smoke run of the suite).
inline bool quick() {
  const char* q = std::getenv("FLEXARM_BENCH_QUICK");
  return q && *q && std::string(q) != "0";
}

inline int repeats(int full) { return quick() ? std::min(full, 3) : full; }

// The clock of the timings: wall time by default; FLEXARM_BENCH_CLOCK=cpu measures the
// process's CPU time instead (for single-threaded work on a machine shared with other jobs,
// where wall times wander). Parallel work is always timed by the wall clock.
inline bool cpuClock() {
  const char* c = std::getenv("FLEXARM_BENCH_CLOCK");
  return c && std::string(c) == "cpu";
}

inline double now(bool cpu) {
  if (cpu) {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// CPU seconds (user + system) of the child processes waited for so far: a whole process's
// work, measured apart from how much of the machine it was given.
inline double childCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Median time of `repeats` calls of work(i), i = 0..repeats-1 (parallel: wall clock always).
inline double medianSeconds(int repeatCount, const std::function<void(int)>& work,
                            bool parallel = false) {
  const bool cpu = cpuClock() && !parallel;
  std::vector<double> t;
  for (int i = 0; i < std::max(1, repeatCount); ++i) {
    const double a = now(cpu);
    work(i);
    t.push_back(now(cpu) - a);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

inline double medianSeconds(int repeatCount, const std::function<void()>& work,
                            bool parallel = false) {
  return medianSeconds(repeatCount, [&](int) { work(); }, parallel);
}

// A fresh folder under the system's temporary directory, removed with everything in it at
// the end of its scope (FLEXARM_BENCH_KEEP=1 keeps it).
class TempDir {
 public:
  explicit TempDir(const std::string& stem) {
    std::random_device rd;
    const auto base = std::filesystem::temp_directory_path();
    for (int i = 0; i < 100; ++i) {
      auto p = base / (stem + "-" + std::to_string(rd()));
      if (std::filesystem::create_directory(p)) {
        path_ = p;
        return;
      }
    }
    throw std::runtime_error("cannot create a temporary folder for " + stem);
  }
  ~TempDir() {
    if (std::getenv("FLEXARM_BENCH_KEEP")) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// Command line of a Python peer in bench/ (Debian's interpreter, where python3-scipy is).
inline std::string python(const std::string& script, const std::string& args) {
  return std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR + "/" + script + " " + args;
}

// Command line of an Octave peer in bench/ (octave-cli with the control and signal packages).
inline std::string octave(const std::string& script, const std::string& args) {
  return std::string("octave-cli --no-gui --quiet --norc --no-history ") + FLEXARM_BENCH_DIR +
         "/" + script + " " + args;
}

// Runs a peer and returns the JSON objects it printed, one per line (other lines are passed
// to stderr). Empty when the peer could not run; `why` then says so.
inline std::vector<Json> runPeer(const std::string& command, std::string* why = nullptr) {
  std::vector<Json> out;
  FILE* p = popen(command.c_str(), "r");
  if (!p) {
    if (why) *why = "cannot start: " + command;
    return out;
  }
  std::string line;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) {
    line += buf;
    if (line.empty() || line.back() != '\n') continue;
    line.pop_back();
    if (!line.empty() && line.front() == '{') {
      try {
        out.push_back(Json::parse(line));
      } catch (const std::exception&) {
        std::cerr << "  peer: " << line << "\n";
      }
    } else if (!line.empty()) {
      std::cerr << "  peer: " << line << "\n";
    }
    line.clear();
  }
  const int status = pclose(p);
  if (status != 0) {
    if (why) *why = "the peer failed (" + command + ")";
    out.clear();
  }
  return out;
}

// Runs a command and returns its standard output; *ok tells whether it exited with 0.
inline std::string capture(const std::string& command, bool* ok) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (!p) {
    *ok = false;
    return out;
  }
  char buf[65536];
  std::size_t got;
  while ((got = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, got);
  *ok = pclose(p) == 0;
  return out;
}

// The first object of a peer's output whose "name" is `name` (null when absent).
inline Json peerResult(const std::vector<Json>& results, const std::string& name) {
  for (const auto& r : results)
    if (r.value("name", std::string()) == name) return r;
  return nullptr;
}

// One result row.
struct Row {
  std::string group;
  std::string task;
  std::string size;
  double flexarmSeconds = 0.0;
  std::string peer;
  std::optional<double> peerSeconds;  // empty: the peer did not run
  std::optional<bool> agree;          // empty: nothing compared
  std::string agreement;              // what was compared, e.g. "loss 0.25 vs 0.25"
  int scale = 0;                      // 1, 4, 16 for the scaling rows; 0 otherwise
  Json extra = Json::object();        // free fields
};

inline void emit(const Row& r) {
  Json j = r.extra;
  j["group"] = r.group;
  j["task"] = r.task;
  j["size"] = r.size;
  j["flexarm_s"] = r.flexarmSeconds;
  j["peer"] = r.peer;
  j["peer_s"] = r.peerSeconds ? Json(*r.peerSeconds) : Json(nullptr);
  j["agree"] = r.agree ? Json(*r.agree) : Json(nullptr);
  j["agreement"] = r.agreement;
  if (r.scale) j["scale"] = r.scale;
  if (!j.contains("clock")) j["clock"] = cpuClock() ? "cpu" : "wall";
  std::cout << j.dump() << std::endl;
}

// Relative difference |a - b| / max(|a|, |b|, tiny).
inline double relDiff(double a, double b) {
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300});
}

// "0.2501 vs 0.2502" with `digits` significant digits.
inline std::string versus(const std::string& what, double a, double b, int digits = 4) {
  std::ostringstream s;
  s.precision(digits);
  s << what << " " << a << " vs " << b;
  return s.str();
}

// A short data size: "4000 samples", "92.1 MB".
inline std::string samples(long n) { return std::to_string(n) + " samples"; }
inline std::string megabytes(double bytes) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(bytes < 1e7 ? 2 : 1);
  s << bytes / 1e6 << " MB";
  return s.str();
}

}  // namespace flexarm::bench
