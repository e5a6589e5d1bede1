// One slider move of the LQG panel: redesign (two Riccati equations) plus all plot data
// (Nyquist of F_y G and G_0, |S|, |T|, Bode's integral, the Figure 8.3 steps, pole lists),
// timed against SciPy doing the Riccati solves, the frequency responses on the same grid and
// the same step simulation (bench_lqg.py). Usage: bench_lqg [repetitions]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "core/control/lqg_analysis.h"

using namespace flexarm;

namespace {

double medianSeconds(int reps, const std::function<void(int)>& work) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto a = std::chrono::steady_clock::now();
    work(i);
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::max(3, std::atoi(argv[1])) : 50;
  // A slider sweep of R2 between the seed's two cases, as a user drags it.
  auto options = [](int i) {
    LqgOptions o = LqgOptions::seedCaseII();
    o.r2(0) = std::pow(10.0, -8.0 + 2.0 * (i % 20) / 19.0);
    return o;
  };
  LqgAnalysisOptions ao;
  ao.taBandwidth = 0.0;  // depends on the plant only, not on the slider
  LqgAnalysis last;
  const double cpp = medianSeconds(reps, [&](int i) { last = analyzeLqg(options(i), ao); });
  LqgAnalysisOptions withSat = ao;
  withSat.saturationLimit = 2.5;
  const double cppSat = medianSeconds(reps, [&](int i) { analyzeLqg(options(i), withSat); });

  // The same grid and step settings for the peer.
  const std::string grid = "/tmp/flexarm_bench_lqg_grid.txt";
  {
    std::ofstream g(grid);
    g.precision(17);
    for (double w : last.loop.frequencies) g << w << "\n";
  }
  const std::string cmd = "/usr/bin/python3 " + std::string(FLEXARM_BENCH_DIR) + "/bench_lqg.py " +
                          grid + " " + std::to_string(reps);
  FILE* pipe = popen(cmd.c_str(), "r");
  double peer = -1.0;
  if (pipe) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, pipe)) {
      std::string line(buf);
      if (line.rfind("seconds ", 0) == 0)
        peer = std::atof(line.c_str() + 8);
      else
        std::cout << "  peer: " << line;
    }
    pclose(pipe);
  }
  std::remove(grid.c_str());
  std::printf("LQG slider move (redesign + plot data), median of %d, %zu grid points\n", reps,
              last.loop.frequencies.size());
  std::printf("  FlexArm analyzeLqg:                 %8.3f ms\n", cpp * 1e3);
  std::printf("  FlexArm analyzeLqg with saturation: %8.3f ms (two more simulations)\n",
              cppSat * 1e3);
  if (peer > 0) {
    std::printf("  SciPy (CARE x2, responses, steps):  %8.3f ms\n", peer * 1e3);
    std::printf("  ratio SciPy / FlexArm:              %8.2f\n", peer / cpp);
  } else {
    std::printf("  SciPy peer did not run (needs /usr/bin/python3 with numpy and scipy)\n");
    return 1;
  }
  return 0;
}
