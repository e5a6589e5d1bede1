// Reading a FlexArm CSV log: a 10-minute, 2 kHz log with three channels (about 90 MB),
// FlexArm's reader against pandas.read_csv and NumPy (np.loadtxt) on the same file in one
// run. Prints each side's median of repeats, FlexArm's throughput, the ratios and whether the
// values agree (column sums).
//
//   build/bench/bench_csv_read [MINUTES] [REPEATS]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/log_io.h"

using namespace flexarm;
namespace fs = std::filesystem;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

IdData makeLog(double minutes) {
  const auto n = static_cast<std::size_t>(2000 * 60 * minutes);
  IdData d;
  d.sampleTime = 0.0005;
  std::vector<double> angle(n), torque(n), ref(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * d.sampleTime;
    ref[i] = 0.05 * std::sin(2 * M_PI * (0.5 + 0.02 * t) * t);
    angle[i] = ref[i] + 1e-4 * std::sin(2 * M_PI * 17 * t);
    torque[i] = 0.1 * std::cos(2 * M_PI * 3.1 * t) + 0.01 * std::sin(2 * M_PI * 211 * t);
  }
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, angle});
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, torque});
  d.setChannel({columns::kAngleRef, "", ChannelRole::Reference, ref});
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  const double minutes = argc > 1 ? std::atof(argv[1]) : 10.0;
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 7;
  char dirTemplate[] = "/tmp/flexarm_bench_csv_XXXXXX";
  if (!::mkdtemp(dirTemplate)) return 1;
  const fs::path dir(dirTemplate);
  const std::string path = (dir / "log.csv").string();
  if (!writeFlexArmCsv(makeLog(minutes), path)) return 1;
  const double mb = static_cast<double>(fs::file_size(path)) / 1e6;

  std::vector<double> times;
  std::vector<double> sums;
  std::size_t samples = 0;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const LogReadResult res = readLog(path);
    const auto t1 = std::chrono::steady_clock::now();
    if (!res.ok) {
      std::fprintf(stderr, "%s\n", res.error.toString().c_str());
      return 1;
    }
    times.push_back(std::chrono::duration<double>(t1 - t0).count());
    samples = res.data.samples();
    sums.clear();
    for (const auto& c : res.data.channels) {
      double s = 0.0;
      for (double v : c.values) s += v;
      sums.push_back(s);
    }
  }
  const double ours = median(times);
  std::printf("log: %.1f MB, %zu samples x 3 channels at 2 kHz (%g min)\n", mb, samples, minutes);
  std::printf("FlexArm readLog:   median %.3f s of %d (best %.3f s)  %.0f MB/s\n", ours, repeats,
              *std::min_element(times.begin(), times.end()), mb / ours);

  const std::string cmd = std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR +
                          "/peer_csv_read.py '" + path + "' " + std::to_string(repeats);
  double pandasTime = 0, numpyTime = 0, peerSums[3] = {0, 0, 0};
  int got = 0;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    got = std::fscanf(p, "%lf %lf %lf %lf %lf", &pandasTime, &numpyTime, &peerSums[0],
                      &peerSums[1], &peerSums[2]);
    pclose(p);
  }
  int status = 0;
  if (got != 5) {
    std::printf("peer (pandas/NumPy) did not run: install python3-pandas and python3-numpy\n");
    status = 1;
  } else {
    bool agree = sums.size() == 3;
    for (std::size_t i = 0; agree && i < 3; ++i)
      agree = std::abs(sums[i] - peerSums[i]) <= 1e-9 * (1.0 + std::abs(peerSums[i]));
    std::printf("pandas.read_csv:   median %.3f s  %.0f MB/s\n", pandasTime, mb / pandasTime);
    std::printf("numpy.loadtxt:     %.3f s (one run)\n", numpyTime);
    std::printf("ratio (peer / FlexArm): pandas %.1fx, NumPy %.1fx; values agree: %s\n",
                pandasTime / ours, numpyTime / ours, agree ? "yes" : "NO");
    if (!agree) status = 1;
  }
  fs::remove_all(dir);
  return status;
}
