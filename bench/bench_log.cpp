// Reading and decimating a 10-minute, 2 kHz, four-column log: FlexArm against NumPy/SciPy on
// the same file in one run, reported as time ratios.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/io/log_io.h"
#include "core/signal/preprocess.h"

using namespace flexarm;

namespace {
double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

int main() {
  const std::size_t n = 2000 * 600;
  IdData d;
  d.sampleTime = 0.0005;
  std::vector<double> angle(n), torque(n), ref(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i * d.sampleTime;
    ref[i] = 0.05 * std::sin(2 * M_PI * (0.5 + 0.02 * t) * t);
    angle[i] = ref[i] + 1e-4 * std::sin(2 * M_PI * 17 * t);
    torque[i] = 0.1 * std::cos(2 * M_PI * 3.1 * t) + 0.01 * std::sin(2 * M_PI * 211 * t);
  }
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, angle});
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, torque});
  d.setChannel({columns::kAngleRef, "", ChannelRole::Reference, ref});
  const std::string path = (std::filesystem::temp_directory_path() / "flexarm_bench_10min.csv").string();
  if (!writeFlexArmCsv(d, path)) return 1;
  std::printf("log: %s, %zu samples x 3 channels, %.1f MB\n", path.c_str(), n,
              std::filesystem::file_size(path) / 1e6);

  const int reps = 3;
  double readBest = 1e9, decBest = 1e9;
  std::size_t outSamples = 0;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    LogReadResult res = readLog(path);
    auto t1 = std::chrono::steady_clock::now();
    if (!res.ok) return 1;
    DecimateOptions o;
    o.factor = 10;
    IdData y = decimate(res.data, o);
    auto t2 = std::chrono::steady_clock::now();
    readBest = std::min(readBest, seconds(t0, t1));
    decBest = std::min(decBest, seconds(t1, t2));
    outSamples = y.samples();
  }
  std::printf("FlexArm: read %.3f s, decimate x10 (FIR, 3 channels) %.3f s -> %zu samples\n",
              readBest, decBest, outSamples);

  const std::string cmd = std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR + "/peer_log.py " + path + " 10";
  double peerRead = 0, peerDec = 0;
  long peerSamples = 0;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    if (std::fscanf(p, "%lf %lf %ld", &peerRead, &peerDec, &peerSamples) != 3) peerRead = 0;
    pclose(p);
  }
  if (peerRead <= 0) {
    std::printf("peer (NumPy/SciPy) did not run: install python3-scipy\n");
    return 1;
  }
  std::printf("NumPy/SciPy: read %.3f s, decimate %.3f s -> %ld samples\n", peerRead, peerDec, peerSamples);
  std::printf("ratio (peer / FlexArm): read %.1fx, decimate %.1fx\n", peerRead / readBest, peerDec / decBest);
  if (!std::getenv("FLEXARM_BENCH_KEEP")) std::filesystem::remove(path);
  return 0;
}
