// How the recursive estimator follows parameters that change (the seed's 9.2): fixed
// forgetting (Algorithm 6.1), information-constant variable forgetting and the bank of
// estimators at hypothesised change times, on simulated three-mass logs (the closed loop of
// Figure 5.1 at 2 kHz, multisine 0.2 rad, the simulator's noise) with a 20 % step or a 20 %
// ramp over 20 s in k_T or f_m, and without a change. Per method: the delay until the
// estimate passes half the change after the truth did, the RMS tracking error (relative, from
// 5 s on), the excursions beyond +-10 % of the truth while it had not moved (false alarms of a
// plain threshold at half the change) and the changes the bank accepted.
//   tracking_study [seeds=3] [duration=40] [decimate=0]
//   (build: cmake --build build --target tracking_study; output kept in bench/results)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "core/recursive/recursive_log.h"
#include "core/recursive/tracking_metrics.h"
#include "core/sim/closed_loop.h"
#include "tests/core/recursive/recursive_helpers.h"

using namespace flexarm;

int main(int argc, char** argv) {
  std::map<std::string, double> kv = {{"seeds", 3}, {"duration", 40}, {"decimate", 0}};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos || !kv.count(a.substr(0, eq))) {
      std::fprintf(stderr, "tracking_study: arguments are seeds=N duration=S decimate=N, not '%s'\n", a.c_str());
      return 2;
    }
    kv[a.substr(0, eq)] = std::atof(a.c_str() + eq + 1);
  }
  const int seeds = static_cast<int>(kv["seeds"]);
  const double duration = kv["duration"];
  const auto truth = testing::threeMassP6();
  struct Method {
    const char* name;
    RecursiveTracking tracking;
    double lambda;
  };
  const Method methods[] = {{"fixed, lambda 0.995", RecursiveTracking::Fixed, 0.995},
                            {"fixed, lambda 0.999", RecursiveTracking::Fixed, 0.999},
                            {"variable, lambda 0.999", RecursiveTracking::Variable, 0.999},
                            {"bank, lambda 0.999", RecursiveTracking::Bank, 0.999},
                            {"variable, lambda 0.995", RecursiveTracking::Variable, 0.995},
                            {"bank, lambda 0.995", RecursiveTracking::Bank, 0.995}};
  struct Scenario {
    const char* name;
    const char* parameter;  // "" for none
    bool ramp;
  };
  const Scenario scenarios[] = {{"no change", "", false},   {"k_T step", "k_T", false},
                                {"f_m step", "f_m", false}, {"k_T ramp", "k_T", true},
                                {"f_m ramp", "f_m", true}};
  std::printf("tracking_study: three-mass p6, %d seeds, %.0f s at 2000 Hz (estimator decimation %s), "
              "multisine 0.2 rad; changes +20 %% at %.0f s (steps) or over %.0f-%.0f s (ramps)\n",
              seeds, duration, kv["decimate"] > 0 ? std::to_string(static_cast<int>(kv["decimate"])).c_str() : "none",
              0.5 * duration, 0.25 * duration, 0.75 * duration);
  std::printf("%-10s %-24s %10s %10s %11s %8s %8s\n", "change", "method", "delay s", "rms err %",
              "excursions", "changes", "s/run");
  for (const Scenario& sc : scenarios) {
    const bool none = std::string(sc.parameter).empty();
    const std::size_t index = std::string(sc.parameter) == "f_m" ? 2 : 0;
    const double before = none ? 1.0 : truth->value(sc.parameter);
    const double after = none ? before : 1.2 * before;
    const double t0 = sc.ramp ? 0.25 * duration : 0.5 * duration, t1 = sc.ramp ? 0.75 * duration : t0;
    auto real = [&](double t) {
      if (none || t < t0) return before;
      if (t >= t1) return after;
      return before + (after - before) * (t - t0) / (t1 - t0);
    };
    std::vector<IdData> logs;
    for (int s = 1; s <= seeds; ++s) {
      SimulationOptions so;
      so.durationS = duration;
      so.seed = static_cast<std::uint64_t>(100 + s);
      so.excitation.kind = ExcitationKind::Multisine;
      so.excitation.amplitude = 0.2;
      if (!none) {
        if (sc.ramp)
          for (int k = 1; k <= 200; ++k)  // 200 small steps make the ramp
            so.parameterSteps.push_back({sc.parameter, real(t0 + (t1 - t0) * k / 200.0), t0 + (t1 - t0) * k / 200.0});
        else
          so.parameterSteps.push_back({sc.parameter, after, t0});
      }
      const SimulationResult sim = simulateClosedLoop(*truth, {}, so);
      if (sim.termination != Termination::Converged) {
        std::printf("simulation failed: %s\n", sim.message.c_str());
        return 4;
      }
      logs.push_back(sim.data);
    }
    for (const Method& m : methods) {
      double delay = 0.0, rms = 0.0, seconds = 0.0;
      int excursions = 0, changes = 0, missed = 0;
      for (const IdData& log : logs) {
        RecursiveOptions o;
        o.tracking = m.tracking;
        o.lambda = m.lambda;
        o.lambdaMin = std::min(o.lambdaMin, m.lambda);
        RecursiveDataOptions d;
        d.decimation = static_cast<int>(kv["decimate"]);
        const RecursiveLogResult run = recursiveIdentification(log, *truth, d, o);
        if (run.result.termination != Termination::Converged) {
          std::printf("run failed: %s\n", run.result.message.c_str());
          return 4;
        }
        const auto& tr = run.result.trajectory;
        const TrackingMetrics tm = trackingMetrics(tr.time, tr.theta[index], real, before, after, 5.0, 0.10);
        if (std::isfinite(tm.delayS)) delay += tm.delayS;
        else ++missed;
        rms += tm.rmsError;
        excursions += tm.excursions;
        changes += static_cast<int>(tr.changeTime.size());
        seconds += run.result.seconds;
      }
      const int passed = seeds - missed;
      char delayText[32];
      if (none) std::snprintf(delayText, sizeof delayText, "-");
      else if (passed == 0) std::snprintf(delayText, sizeof delayText, "never");
      else std::snprintf(delayText, sizeof delayText, "%.2f%s", delay / passed, missed ? "*" : "");
      std::printf("%-10s %-24s %10s %10.2f %11d %8d %8.2f\n", sc.name, m.name, delayText,
                  100.0 * rms / seeds, excursions, changes, seconds / seeds);
      std::fflush(stdout);
    }
  }
  std::printf("(delay: mean over the seeds; * some seeds never passed half the change; excursions and "
              "changes: summed over the seeds)\n");
  return 0;
}
