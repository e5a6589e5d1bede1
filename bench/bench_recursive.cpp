// Recursive identification speed (the seed's chapter 6): the three-parameter three-mass RPEM
// with the exact zero-order hold of the extended model (6.27) at every sample, FlexArm against
// a straightforward NumPy/SciPy implementation (scipy.linalg.expm of the extended matrix each
// sample) on the same data, start and P(0), in one run; and the whole `flexarm recursive`
// process on a sample log against the log's duration (the real-time factor).
//
//   cmake --build BUILD --target bench_recursive && BUILD/bench/bench_recursive
//
// Output: one JSON object per line on stdout (task, size, flexarm_s, peer, peer_s, agree, and
// free fields: agreement, realtime_x, us_per_sample); notes on stderr.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/models/physical_models.h"
#include "core/recursive/rpem.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"
#include "tests/core/recursive/recursive_helpers.h"

using namespace flexarm;
using Json = nlohmann::json;

namespace {

// FLEXARM_BENCH_CLOCK=cpu times the process's CPU time instead of the wall clock (the work is
// single-threaded; on a machine shared with other jobs wall times wander), as the peer does.
bool cpuClock() {
  const char* c = std::getenv("FLEXARM_BENCH_CLOCK");
  return c && std::string(c) == "cpu";
}

double now() {
  if (cpuClock()) {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double medianSeconds(int repeats, const std::function<void()>& work) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const double t0 = now();
    work();
    t.push_back(now() - t0);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Runs a command, returns its stdout; empty optional-like flag on failure.
bool run(const std::string& command, std::string& out) {
  out.clear();
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return false;
  std::array<char, 4096> buffer{};
  std::size_t got = 0;
  while ((got = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), got);
  return pclose(pipe) == 0;
}

}  // namespace

int main() {
  // Data: the closed loop of Figure 5.1 around the p6 truth at 2 kHz, the multisine (6.50),
  // the motor velocity differentiated from the angle and both signals decimated to 200 Hz.
  SimulationOptions so;
  so.durationS = 60.0;
  so.seed = 6;
  so.excitation.kind = ExcitationKind::Multisine;
  so.excitation.amplitude = 0.2;
  const auto truth = testing::threeMassP6();
  const auto sim = simulateClosedLoop(*truth, {}, so);
  DecimateOptions dec;
  dec.factor = 10;
  const IdData d = detrend(decimate(addDerivative(sim.data), dec), Detrend::Mean);
  const auto n = static_cast<Eigen::Index>(d.samples());
  const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(d.input()->values.data(), n);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(d.output()->values.data(), n);
  const double ts = d.sampleTime;
  const double duration = static_cast<double>(n) * ts;

  RecursiveOptions base;
  base.startScale = 1.2;
  const RecursiveAlgorithm algorithms[] = {RecursiveAlgorithm::ForgettingFactor,
                                           RecursiveAlgorithm::Kalman};
  const double r1[] = {5e-8, 5e-7, 5e-6};
  Json setup = {{"ts", ts}, {"lambda", base.lambda}, {"r1", r1}, {"r2", base.r2}};
  Json nominal = Json::object();
  for (const auto& p : truth->parameters()) nominal[p.name] = p.value;
  setup["nominal"] = nominal;
  setup["theta0"] = {1.2 * 1.0, 1.2 / 1.72, 1.2 * 0.0355};
  setup["runs"] = Json::array();

  struct Row {
    RecursiveAlgorithm algorithm;
    double seconds = 0.0;
    Eigen::VectorXd theta;
  };
  std::vector<Row> rows;
  for (RecursiveAlgorithm a : algorithms) {
    RecursiveOptions o = base;
    o.algorithm = a;
    const InitialCovariance ic = steadyStateCovariance(*truth, u, y, ts, o);
    if (ic.termination != Termination::Converged) {
      std::cerr << "bench_recursive: " << ic.message << "\n";
      return 1;
    }
    o.p0.assign(ic.p0.data(), ic.p0.data() + ic.p0.size());
    Row row;
    row.algorithm = a;
    row.seconds = medianSeconds(5, [&] {
      RecursiveEstimator est(*truth, ts, o);
      for (Eigen::Index k = 0; k < n; ++k) est.update(u[k], y[k]);
      row.theta = est.theta();
    });
    rows.push_back(row);
    setup["runs"].push_back({{"algorithm", toString(a)}, {"p0", o.p0}});
  }

  const auto dir = std::filesystem::temp_directory_path() /
                   ("flexarm_bench_recursive_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream data(dir / "data.csv");
    data.precision(17);
    data << "u,y\n";
    for (Eigen::Index k = 0; k < n; ++k) data << u[k] << "," << y[k] << "\n";
    std::ofstream(dir / "setup.json") << setup.dump() << "\n";
  }
  std::string peerOut;
  const bool peerRan = run(std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR +
                               "/peer_recursive.py " + dir.string(),
                           peerOut);
  if (!peerRan) std::cerr << "bench_recursive: the NumPy/SciPy peer failed\n";
  std::vector<Json> peer;
  std::istringstream lines(peerOut);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) peer.push_back(Json::parse(line));

  char size[64];
  std::snprintf(size, sizeof size, "%ld samples (%.0f s at %.0f Hz)", static_cast<long>(n), duration,
                1.0 / ts);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    Json row = {{"task", std::string("RPEM three-mass k_T, J_a^-1, f_m, ") +
                             (rows[i].algorithm == RecursiveAlgorithm::Kalman ? "Kalman (6.18)"
                                                                              : "forgetting (6.13)")},
                {"size", size},
                {"flexarm_s", rows[i].seconds},
                {"peer", "NumPy/SciPy, scipy.linalg.expm of (6.27) each sample"},
                {"realtime_x", duration / rows[i].seconds},
                {"us_per_sample", 1e6 * rows[i].seconds / static_cast<double>(n)}};
    if (i < peer.size()) {
      double worst = 0.0;
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(peer[i]["theta"][static_cast<std::size_t>(k)].get<double>() -
                                         rows[i].theta[k]) /
                                    std::abs(rows[i].theta[k]));
      char agreement[128];
      std::snprintf(agreement, sizeof agreement, "final theta relative difference %.1e", worst);
      row["peer_s"] = peer[i]["seconds"];
      row["agree"] = worst < 1e-6;
      row["agreement"] = agreement;
    } else {
      row["peer_s"] = nullptr;
      row["agree"] = nullptr;
    }
    std::cout << row.dump() << std::endl;
  }
  std::filesystem::remove_all(dir);
  return 0;
}
