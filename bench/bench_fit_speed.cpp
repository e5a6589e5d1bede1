// Whole-process speed of `flexarm fit` against the SciPy script an engineer would write
// (bench_fit_speed.py: least_squares on the ZOH-simulated output-error model), on the same
// log: 12 s of the two-mass arm (3.13) at 2 kHz under the controller of Figure 5.1, the
// Section 5.1 chirp, the simulator's default noise, no controller in the log's metadata (the
// issue's example). The truth is Table 5.2 with every parameter 10-30 % off, so both fits
// start away from it at the nominal values. Both processes are timed from start to exit
// (reading the log, preparing the data, fitting, printing), medians of several runs. The
// losses compared are the same criterion for both: the mean squared output error of the motor
// velocity (central differences of the angle, means removed) over the whole log, evaluated
// here from each process's parameters.
//
//   cmake --build BUILD --target bench_fit_speed flexarm && BUILD/bench/bench_fit_speed [FLEXARM]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <nlohmann/json.hpp>

#include "core/ident/fit_data.h"
#include "core/ident/pem.h"
#include "core/io/log_io.h"
#include "core/models/physical_models.h"
#include "core/sim/closed_loop.h"

using namespace flexarm;

namespace {

const char* kFree[] = {"J_m", "J_a", "f_m", "k_a", "d_a"};
const double kFactors[] = {1.15, 1.3, 0.8, 0.85, 1.2};

double childCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Timing {
  double wall = 0.0, cpu = 0.0;  // medians of the runs, seconds
};

// Runs a command with its output to outPath: wall-clock and CPU (user + system) seconds of the
// whole process, medians of runs. The CPU time does not count waiting for a busy machine.
Timing timeProcess(const std::string& command, const std::string& outPath, int runs) {
  std::vector<double> wall, cpu;
  for (int i = 0; i < runs; ++i) {
    const double c0 = childCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = std::system((command + " > " + outPath).c_str());
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    cpu.push_back(childCpuSeconds() - c0);
    if (rc != 0) {
      std::cerr << "bench_fit_speed: '" << command << "' failed\n";
      std::exit(1);
    }
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  return {wall[wall.size() / 2], cpu[cpu.size() / 2]};
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  return nlohmann::json::parse(text.substr(text.find('{')));
}

}  // namespace

int main(int argc, char** argv) {
#ifdef FLEXARM_EXE
  std::string exe = FLEXARM_EXE;
#else
  std::string exe = "flexarm";
#endif
  if (argc > 1) exe = argv[1];
  auto truth = makeModel("two-mass");
  for (int i = 0; i < 5; ++i) truth->setParameter(kFree[i], truth->value(kFree[i]) * kFactors[i]);
  SimulationOptions so;
  so.durationS = 12.0;
  so.seed = 7;
  const SimulationResult sim = simulateClosedLoop(*truth, {}, so);
  IdData log = sim.data;
  for (const char* key : {"controller_rate_hz", "controller_kp", "controller_kv", "controller_ti"})
    log.metadata.erase(std::remove_if(log.metadata.begin(), log.metadata.end(),
                                      [key](const auto& kv) { return kv.first == key; }),
                       log.metadata.end());
  const auto dir = std::filesystem::temp_directory_path() /
                   ("flexarm_bench_fit_speed_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "two_mass_closed_loop.csv").string();
  if (!writeFlexArmCsv(log, path)) {
    std::cerr << "bench_fit_speed: cannot write " << path << "\n";
    return 1;
  }
  const std::string ours = (dir / "flexarm.json").string(), direct = (dir / "direct.json").string(),
                    peer = (dir / "scipy.json").string();
  const Timing tOurs = timeProcess(exe + " fit " + path + " --model two-mass --json", ours, 7);
  const Timing tDirect = timeProcess(exe + " fit " + path + " --model two-mass --closed-loop direct --json", direct, 7);
  const Timing tPeer = timeProcess(std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR +
                                       "/bench_fit_speed.py " + path, peer, 3);
  const nlohmann::json a = readJson(ours), c = readJson(direct), b = readJson(peer);

  // The same criterion for every answer: the output-error loss of the motor velocity over a
  // whole log, on the estimation log (what the SciPy script minimizes) and on a validation
  // log of the same arm (another seed, the multisine (6.50)).
  SimulationOptions vo = so;
  vo.seed = 8;
  vo.excitation.kind = ExcitationKind::Multisine;
  const IdData validation = simulateClosedLoop(*truth, {}, vo).data;
  FitDataOptions d;
  d.velocityOutput = true;
  const PreparedData pe = prepareFitData(log, d), pv = prepareFitData(validation, d);
  auto modelOf = [&](const nlohmann::json& params) {
    auto m = makeModel("two-mass");
    for (const char* n : kFree) m->setParameter(n, params[n].get<double>());
    return m;
  };
  auto lossOf = [&](const nlohmann::json& params, const PreparedData& p) {
    const Eigen::VectorXd e = p.y - simulate(*modelOf(params), p.u, p.sampleTime);
    return e.squaredNorm() / static_cast<double>(e.size());
  };
  // The model's own error, free of the noise the closed loop feeds into both logs: its
  // simulated motor velocity against the truth's for the validation log's torque.
  const Eigen::VectorXd yTrue = simulate(*truth, pv.u, pv.sampleTime);
  auto modelError = [&](const nlohmann::json& params) {
    const Eigen::VectorXd e = yTrue - simulate(*modelOf(params), pv.u, pv.sampleTime);
    return e.squaredNorm() / static_cast<double>(e.size());
  };
  std::printf("Whole process on a 12 s, 2 kHz closed-loop two-mass log (%zu samples), from reading the log\n"
              "to printing the estimate (medians; cpu: user + system time of the process). Losses in\n"
              "(rad/s)^2: the output error of the motor velocity on the estimation log (what the SciPy\n"
              "script minimizes) and on a validation log, and the model error (its simulated motor\n"
              "velocity against the truth's for the validation torque, free of noise).\n\n",
              log.samples());
  std::printf("%-22s %7s %7s %11s %11s %11s   %s\n", "program", "wall s", "cpu s", "OE est.", "OE val.",
              "model err.", "parameters (error against the truth)");
  auto row = [&](const char* name, const Timing& t, const nlohmann::json& params) {
    std::printf("%-22s %7.3f %7.3f %11.6g %11.6g %11.4g  ", name, t.wall, t.cpu, lossOf(params, pe),
                lossOf(params, pv), modelError(params));
    for (const char* n : kFree) {
      const double v = params[n].get<double>(), tv = truth->value(n);
      std::printf(" %s %+.2f %%", n, 100.0 * (v - tv) / tv);
    }
    std::printf("\n");
  };
  row("flexarm fit (default)", tOurs, a["parameters"]);
  row("flexarm fit (direct)", tDirect, c["parameters"]);
  row("scipy least_squares", tPeer, b["parameters"]);
  std::printf("\nspeed ratio (SciPy seconds / FlexArm seconds), wall: default %.1f, direct %.1f; cpu: default "
              "%.1f, direct %.1f\n",
              tPeer.wall / tOurs.wall, tPeer.wall / tDirect.wall, tPeer.cpu / tOurs.cpu, tPeer.cpu / tDirect.cpu);
  std::printf("loss ratios FlexArm / SciPy: default: OE estimation %.4f, OE validation %.4f, model error %.4f;\n"
              "direct: OE estimation %.6f, model error %.6f\n",
              lossOf(a["parameters"], pe) / lossOf(b["parameters"], pe),
              lossOf(a["parameters"], pv) / lossOf(b["parameters"], pv),
              modelError(a["parameters"]) / modelError(b["parameters"]),
              lossOf(c["parameters"], pe) / lossOf(b["parameters"], pe),
              modelError(c["parameters"]) / modelError(b["parameters"]));
  std::printf("default closed-loop method: %s (%s)\n", a.value("closed_loop_method", nlohmann::json()).dump().c_str(),
              a.value("closed_loop_reason", std::string()).c_str());
  std::filesystem::remove_all(dir);
  return 0;
}
