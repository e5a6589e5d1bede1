// Monte-Carlo study of the chapter-7 diagnosis: arms whose parameters, noise level and
// excitation are drawn at random (core/diagnosis/scenarios.h), each run fault-free and with a
// fault in k_T, J_a^-1 and f_m stepping in, diagnosed against theta_0 fitted on a fault-free
// run of the same arm. Prints, per test and for the decision, the false alarms per hour of
// the fault-free runs against the detection delay as the threshold scale c varies (the
// delay/false-alarm curve), the calibrated threshold for the stated rate, and the isolation
// of every fault within the horizon.
//   montecarlo_diagnosis [key=value ...]   (build: cmake --build build --target montecarlo_diagnosis)
//     arms=60 threads=2 size=0.2 duration=20 healthy=0 (s of the fault-free runs, 0: duration)
//     rate=1 (false alarms per hour) seed=1
//     alpha1=3 window=cumulative|SECONDS predictor=auto|loop|direct noise=0.5:1.5 spread=0.15
//     amplitude=0.1:0.3 excitation=multisine,prbs horizon=5 confirm=0 settle=2
//     design=flexarm|seed (the default thresholds or the seed's) curve=1 (print the curves)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "core/diagnosis/calibration.h"
#include "core/diagnosis/scenarios.h"

using namespace flexarm;

namespace {

std::string delayText(double d) {
  if (!std::isfinite(d)) return "  >h ";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%5.2f", d);
  return buf;
}

void pair(const std::string& text, double& a, double& b) {
  std::sscanf(text.c_str(), "%lf:%lf", &a, &b);
}

void printPoint(const char* name, const CalibrationPoint& p, const std::vector<std::string>& faults,
                const std::vector<double>& iso, const std::vector<double>& delay) {
  // A test's point has its threshold; the decision's combines the tests' own.
  char threshold[64] = "";
  if (faults.empty() || std::string(name).rfind("decision", 0) != 0)
    std::snprintf(threshold, sizeof threshold, "c=%5.2f threshold %-8.4g ", p.scale, p.threshold);
  std::printf("  %-10s %sFA %3d = %7.3g/h (95%% <= %7.3g/h)  isolated %5.1f %%, wrong %4.1f %%, "
              "median delay %s s, 95th %s s |",
              name, threshold, p.falseAlarms, p.falseAlarmsPerHour, p.falseAlarmsPerHourUpper,
              100.0 * p.isolatedFraction, 100.0 * p.wrongFraction, delayText(p.medianDelayS).c_str(),
              delayText(p.p95DelayS).c_str());
  for (std::size_t i = 0; i < faults.size() && i < iso.size(); ++i)
    std::printf(" %s %.0f %% %s s", faults[i].c_str(), 100.0 * iso[i], delayText(delay[i]).c_str());
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> kv;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "montecarlo_diagnosis: arguments are key=value, not '%s'\n", a.c_str());
      return 2;
    }
    kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  auto number = [&kv](const char* key, double fallback) {
    return kv.count(key) ? std::atof(kv[key].c_str()) : fallback;
  };
  ScenarioOptions so;
  so.arms = static_cast<int>(number("arms", 60));
  so.faultSize = number("size", 0.2);
  so.durationS = number("duration", 20.0);
  so.healthyDurationS = number("healthy", 0.0);
  so.faultTimeLowS = 0.4 * so.durationS;
  so.faultTimeHighS = 0.6 * so.durationS;
  so.truthSpread = number("spread", 0.15);
  so.seed = static_cast<std::uint64_t>(number("seed", 1));
  if (kv.count("noise")) pair(kv["noise"], so.noiseLow, so.noiseHigh);
  if (kv.count("amplitude")) pair(kv["amplitude"], so.amplitudeLow, so.amplitudeHigh);
  if (kv.count("excitation")) {
    so.excitations.clear();
    std::string list = kv["excitation"] + ",";
    for (std::size_t pos = 0, comma; (comma = list.find(',', pos)) != std::string::npos; pos = comma + 1)
      if (auto k = excitationKindFromString(list.substr(pos, comma - pos))) so.excitations.push_back(*k);
  }
  DiagnosisOptions options;
  if (kv.count("design") && kv["design"] == "seed") options = DiagnosisOptions::seed();
  options.cusumAlpha1 = number("alpha1", options.cusumAlpha1);
  options.confirmS = number("confirm", options.confirmS);
  options.settleS = number("settle", options.settleS);
  if (kv.count("window")) {
    if (kv["window"] == "cumulative") {
      options.window = HypothesisWindow::Cumulative;
    } else {
      options.window = HypothesisWindow::Sliding;
      options.windowS = number("window", options.windowS);
    }
  }
  if (kv.count("predictor")) options.predictor = *diagnosisPredictorFromString(kv["predictor"]);
  CalibrationOptions co;
  co.threads = static_cast<int>(number("threads", 2));
  co.targetFalseAlarmsPerHour = number("rate", 1.0);
  co.horizonS = number("horizon", 5.0);

  std::string kinds;
  for (auto k : so.excitations) kinds += std::string(kinds.empty() ? "" : " or ") + toString(k);
  const auto nominal = makeModel("three-mass");
  const auto runs = randomScenarios(*nominal, options.parameters, so);
  std::printf("montecarlo_diagnosis: %d arms (three-mass Table 5.7 p6, every parameter times U(%.2f, %.2f)), "
              "noise x U(%.2f, %.2f), %s of U(%.3f, %.3f) rad, %.0f s runs at %.0f Hz, "
              "%+.0f %% faults stepping in at U(%.0f, %.0f) s; predictor %s, CUSUM alpha_1 %.3g, hypothesis "
              "window %s, settle %.3g s, confirm %.3g s; %zu runs on %d threads\n",
              so.arms, 1.0 - so.truthSpread, 1.0 + so.truthSpread, so.noiseLow, so.noiseHigh,
              kinds.c_str(), so.amplitudeLow, so.amplitudeHigh, so.durationS, so.rateHz, 100.0 * so.faultSize,
              so.faultTimeLowS, so.faultTimeHighS, toString(options.predictor), options.cusumAlpha1,
              toString(options.window), options.settleS, options.confirmS, runs.size(), co.threads);
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  const CalibrationResult r = monteCarlo(runs, options, co);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (r.termination != Termination::Converged) {
    std::printf("failed: %s\n", r.message.c_str());
    return 4;
  }
  std::printf("%d fault-free runs (%.3g h after settling), %d faulty runs, %.0f s (%.2f s per run)\n",
              r.healthyRuns, r.healthyHours, r.faultyRuns, seconds, seconds / static_cast<double>(runs.size()));
  if (number("curve", 1) > 0) {
    std::printf("\nDelay against false alarms (threshold scale c times the seed's value):\n");
    for (const auto& t : r.tests) {
      std::printf(" %s\n", toString(t.test));
      for (std::size_t i = 0; i < t.curve.size(); i += 3)
        printPoint("", t.curve[i], {}, {}, {});
    }
  }
  std::printf("\nCalibrated for %.3g false alarms per hour (isolation within %.3g s):\n",
              co.targetFalseAlarmsPerHour, co.horizonS);
  for (const auto& t : r.tests) {
    std::printf("  %-10s thresholds", toString(t.test));
    for (double v : t.thresholds) std::printf(" %.4g", v);
    std::printf("%s\n", t.met ? "" : " (the rate is not met on the grid)");
    printPoint("", t.point, r.faults, t.isolatedFraction, t.medianDelayS);
  }
  std::string decide;
  for (DiagnosisTest t : options.decision) decide += std::string(decide.empty() ? "" : "+") + toString(t);
  printPoint(("decision " + decide).c_str(), r.decision, r.faults, r.decisionIsolatedFraction,
             r.decisionMedianDelayS);
  std::printf("\nModel check (the verdict model_mismatch): %d of %d fault-free and %d of %d faulty runs "
              "(the simulated arm has the model's own structure: none should be)\n",
              r.healthyMismatches, r.healthyRuns, r.faultyMismatches, r.faultyRuns);
  std::printf("\nAt FlexArm's default thresholds (not calibrated on these runs):\n");
  printPoint(("decision " + decide).c_str(), r.given, r.faults, r.givenIsolatedFraction,
             r.givenMedianDelayS);
  std::printf("%s\n", r.message.c_str());
  return 0;
}
