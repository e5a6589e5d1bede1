// flexarm diagnose LOG (--reference-log HEALTHY | --param NAME=VALUE ...) --model three-mass
//                  [--tests ...] [--decide ...] [--window S|cumulative] [--json]
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "core/common/text.h"
#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "app/cli/model_args.h"
#include "app/cli/progress_line.h"
#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/calibration.h"
#include "core/diagnosis/diagnosis_json.h"
#include "core/diagnosis/diagnosis_request.h"

namespace flexarm::cli {
namespace {

const char* kDiagnoseHelp =
    "Usage: flexarm diagnose LOG --model three-mass (--reference-log HEALTHY_LOG | --param ...)\n"
    "                        [--tests classical,robust,cusum,hypothesis,joint] [--decide TESTS]\n"
    "                        [--window S|cumulative] [--friction-alpha A | --temperature-logs\n"
    "                        A,B,C] [--json]\n\n"
    "Detects and isolates a fault in the torque constant k_T, the arm's inertia J_a (a load\n"
    "change) or the motor friction f_m (the seed's chapter 7). The recursive estimator of\n"
    "chapter 6 (forgetting factor 0.995) follows k_T, J_a^-1 and f_m through LOG (by default\n"
    "predicting the motor angle from the position reference through the log's controller, see\n"
    "--predictor); the tests compare them with the fault-free theta_0:\n"
    "  classical   |theta - theta_0| > 3 sqrt(sigma^2 + sigma_0^2), sigma^2 = lambda_0 P_ii\n"
    "              ((7.4), (7.7)-(7.9))\n"
    "  robust      the smoothed estimate (7.12) against 3 times its spread (7.13), (7.14)\n"
    "  cusum       two-sided CUSUM (7.1) with drift 3 sigma and threshold 20 theta_0 (7.15)-(7.17)\n"
    "  hypothesis  a bank of predictors (theta_0 fixed; each parameter alone estimated), their\n"
    "              squared prediction errors normalised by the full estimate's (7.20)/(7.21),\n"
    "              threshold 1.12 (seed: 1), and the decision structure of Section 7.5.2\n"
    "  joint       the change of every parameter at once, chi-square in the metric of the\n"
    "              spreads (7.13) with the correlations of the full P, against its quantile at\n"
    "              3 sigma; isolated by the change's direction (the decision structure of the\n"
    "              hypothesis tests: F_i is rejected when the change does not lie along it)\n"
    "The robust and CUSUM thresholds carry per-parameter factors from the Monte-Carlo\n"
    "calibration (k_T, J_a^-1, f_m: robust 2, 1, 1.8; CUSUM h 0.2, 0.27, 1.25); --calibrate\n"
    "chooses them again for LOG.\n"
    "The decision structure combines the alarms of the --decide tests into the diagnosis S and a\n"
    "verdict: the parameter whose fault alone explains them, and the time it was reached; a\n"
    "change the tests detect but do not isolate to one parameter is the verdict detected.\n"
    "Before a parameter is named the model must still fit: when the errors of the estimator of\n"
    "every monitored parameter stay above --mismatch-ratio (2) times the fault-free mean square\n"
    "lambda_0 for a whole window, no parameter change explains the data and the verdict is\n"
    "model_mismatch (\"the model no longer fits: ...\", with the residual tests of that window).\n"
    "Temperature: a log's temperature is the mean of its temperature_c channel or its metadata\n"
    "value temperature_c. With alpha (--friction-alpha, or estimated from --temperature-logs),\n"
    "theta_0's f_m is carried from the reference's temperature to LOG's by\n"
    "f_m = f_m0 (1 + alpha (T - T_ref)) before the tests compare, so a warm axis is not a fault.\n\n"
    "Reference (one of):\n"
    "  --reference-log LOG   fault-free log: theta_0 is the output-error fit of --model on it\n"
    "                        (direct: the recursive estimator's criterion), the plant for a\n"
    "                        calibration its two-stage closed-loop fit\n"
    "  --param NAME=VALUE    (with --model) the model believed fault-free; theta_0 is fitted on\n"
    "                        a fault-free run of it simulated under LOG's controller and reference\n\n"
    "Options:\n"
    "  --monitor A,B,C       the monitored parameters (default k_T,J_a,f_m; J_a as J_a^-1)\n"
    "  --tests LIST          tests to run (default all five)\n"
    "  --decide LIST         tests the verdict combines (default robust,cusum,hypothesis)\n"
    "  --window S|cumulative hypothesis tests' sums over the last S seconds (on-line use), or\n"
    "                        from the first sample as the seed (default 5)\n"
    "  --predictor P         loop: the motor angle from the position reference through the\n"
    "                        log's controller (free of closed-loop bias); direct: the motor\n"
    "                        velocity from the torque reference, as the seed; auto (default):\n"
    "                        loop when the log has a reference and names its controller\n"
    "  --lambda L            forgetting factor of the estimator and of (7.12)/(7.13) (0.995)\n"
    "  --k K                 the 3 of the classical and robust thresholds (one for every\n"
    "                        parameter: drops the calibrated factors)\n"
    "  --alpha1 A, --alpha2 A  CUSUM drift and threshold factors (3, 20; --alpha2 drops the\n"
    "                        calibrated factors of h)\n"
    "  --hypothesis-threshold C  threshold of the normalised hypothesis statistics (1.12)\n"
    "  --confirm S           a diagnosis must hold S seconds to become the verdict (0)\n"
    "  --settle S            no alarm in the first S seconds (2)\n"
    "  --seed-fault NAME=F   make a fault out of fault-free data as the seed's Section 7.5 does:\n"
    "                        theta_0 of NAME (J_a as J_a^-1) times F (1.2 for its 20 %)\n"
    "  --trace FILE.csv      write time, estimates, every test's statistic, threshold and S\n"
    "  --calibrate           choose every test's threshold by Monte-Carlo runs of the plant\n"
    "                        under LOG's conditions (controller, rate, length, reference) at the\n"
    "                        fault-free log's noise level, for a stated false-alarm rate; the\n"
    "                        diagnosis then uses them\n"
    "  --false-alarms-per-hour R  the rate the calibration allows (default 1)\n"
    "  --runs N              fault-free runs of the calibration (default 40; plus N/5 runs per\n"
    "                        fault, 20 % steps in the middle of the run)\n"
    "  --threads N           calibration runs in parallel (default 2)\n"
    "  --mismatch-ratio R    the model no longer fits when the re-estimated model's errors stay\n"
    "                        above R times lambda_0 for a window (default 2)\n"
    "  --no-model-check      name a parameter even when the model no longer fits\n"
    "  --friction-alpha A    relative change of f_m per degC (e.g. 0.004), T_ref the reference\n"
    "                        log's temperature\n"
    "  --temperature-logs A,B,C  healthy logs at three or more temperatures: alpha is estimated\n"
    "                        from their fitted f_m (with its standard deviation)\n"
    "  --temperature C, --reference-temperature C  the temperatures when the logs do not state\n"
    "                        them (degC)\n"
    "  --json                print the result as JSON\n\n"
    "JSON: verdict (\"none\", \"k_T\", \"J_a\", \"f_m\", \"detected\", \"model_mismatch\"),\n"
    "alarm_time_s (the verdict's time: the detection's for detected, null when none),\n"
    "tests_verdict (the decision's own), named_by_tests (what each test names on its own),\n"
    "model_check {fits, time_s,\n"
    "threshold, median_ratio, peak_ratio, white, independent, what, message}, temperature\n"
    "{monitored_c, reference_c, alpha_per_c, applied, f_m_reference, f_m_expected, message},\n"
    "detection_time_s, window, reference {source, theta0, sigma0, lambda0},\n"
    "estimates {name: {theta0, final, sigma}}, decision {tests, statement_final},\n"
    "tests {name: {verdict, alarm_time_s, detection_time_s, thresholds, columns {q: {first_alarm_s,\n"
    "alarms, max_ratio, final_statistic, final_threshold}}}}, seconds.\n";

bool parseNames(const std::string& text, std::vector<std::string>& out) {
  out.clear();
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    out.push_back(text.substr(pos, comma - pos));
    if (out.back().empty()) return false;
    pos = comma + 1;
  }
  return !out.empty();
}

bool writeTrace(const DiagnosisResult& r, const std::string& path, std::string* why) {
  std::ostringstream f;
  f << "time_s";
  for (const auto& p : r.parameters) f << "," << p.name;
  for (const auto& t : r.tests)
    for (const auto& c : t.columns) f << "," << toString(t.test) << ":" << c << "," << toString(t.test) << ":" << c << ":threshold";
  f << ",statement\n";
  char buf[40];
  for (std::size_t k = 0; k < r.time.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.6f", r.time[k]);
    f << buf;
    for (const auto& th : r.estimates.theta) f << "," << th[k];
    for (const auto& t : r.tests)
      for (std::size_t q = 0; q < t.columns.size(); ++q) f << "," << t.statistic[q][k] << "," << t.threshold[q][k];
    f << ",\"" << modeSetString(r.decision.statement[k], r.faults) << "\"\n";
  }
  return writeFileAtomically(path, f.str(), why);
}

std::string delayText(double d) {
  if (!std::isfinite(d)) return "not isolated";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", d);
  return buf;
}

std::string calibrationText(const CalibrationResult& c) {
  std::string s = "Calibration: " + c.conditions + ".\n";
  char line[300];
  for (const auto& t : c.tests) {
    std::string thresholds;
    for (double v : t.thresholds) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%s%.4g", thresholds.empty() ? "" : ", ", v);
      thresholds += buf;
    }
    const auto& p = t.point;
    std::snprintf(line, sizeof line,
                  "  %-10s threshold%s %s%s: %.3g false alarms per hour (95 %% bound %.3g), %.0f %% "
                  "isolated within the horizon, median delay %s\n",
                  toString(t.test), t.thresholds.size() > 1 ? "s" : "", thresholds.c_str(),
                  t.met ? "" : " (the largest tried; the rate is not met)", p.falseAlarmsPerHour,
                  p.falseAlarmsPerHourUpper, 100.0 * p.isolatedFraction, delayText(p.medianDelayS).c_str());
    s += line;
  }
  return s + "  " + c.message + ".\n";
}

}  // namespace

int runDiagnose(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> valued = logReadOptionNames();
  for (const auto& v : modelValuedOptions()) valued.push_back(v);
  for (const char* n : {"reference-log", "monitor", "tests", "decide", "window", "lambda", "k",
                        "alpha1", "alpha2", "hypothesis-threshold", "confirm", "settle", "trace", "predictor",
                        "seed-fault", "mismatch-ratio", "friction-alpha", "temperature-logs",
                        "temperature", "reference-temperature",
                        "false-alarms-per-hour", "runs", "threads"})
    valued.push_back(n);
  auto flags = modelFlagOptions();
  flags.push_back("json");
  flags.push_back("calibrate");
  flags.push_back("no-model-check");
  flags.push_back("help");
  ArgParser args(flags, valued);
  const std::string pre = "flexarm diagnose: ";
  auto usage = [&](const std::string& why) {
    err << pre << why << "\n(flexarm diagnose --help explains the options)\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << kDiagnoseHelp << "\nModel:\n" << modelOptionsHelp() << "\n" << logReadOptionsHelp();
    return kExitOk;
  }
  if (args.positional().size() != 1) return usage("expected exactly one LOG to diagnose");
  const auto referenceLog = args.value("reference-log");
  if (!referenceLog && args.values("param").empty() && !args.value("model"))
    return usage("give the fault-free reference: --reference-log HEALTHY_LOG, or --model with "
                 "--param values");

  DiagnosisOptions options;
  std::string why;
  if (auto m = args.value("monitor")) {
    if (!parseNames(*m, options.parameters)) return usage("--monitor expects NAME,NAME,...");
    std::vector<std::string> inverted;
    for (const auto& n : options.parameters)
      if (n == "J_a") inverted.push_back(n);
    options.inverted = inverted;
    // The default thresholds' factors belong to the default parameters.
    options.classicalScales.clear();
    options.robustScales.clear();
    options.cusumScales.clear();
  }
  if (auto t = args.value("tests")) {
    auto tests = diagnosisTestsFromList(*t, &why);
    if (!tests) return usage("--tests: " + why);
    options.tests = *tests;
    std::vector<DiagnosisTest> decide;
    for (DiagnosisTest d : options.decision)
      if (options.uses(d)) decide.push_back(d);
    options.decision = decide.empty() ? options.tests : decide;
  }
  if (auto d = args.value("decide")) {
    auto tests = diagnosisTestsFromList(*d, &why);
    if (!tests) return usage("--decide: " + why);
    options.decision = *tests;
  }
  if (auto p = args.value("predictor")) {
    auto parsed = diagnosisPredictorFromString(*p);
    if (!parsed) return usage("--predictor must be auto, loop or direct, not " + inQuotes(*p));
    options.predictor = *parsed;
  }
  if (auto w = args.value("window")) {
    if (*w == "cumulative") {
      options.window = HypothesisWindow::Cumulative;
    } else {
      options.window = HypothesisWindow::Sliding;
      if (!args.number("window", options.windowS))
        return usage("--window expects seconds or 'cumulative', not " + inQuotes(*w));
    }
  }
  double lambda = options.estimator.lambda, k = 0.0;
  // Ranges a diagnosis can use: a threshold of 1e308 sigma would never raise an alarm and
  // report "no fault" on any log.
  if (!args.number("lambda", lambda, 0.5, 1.0) || !args.number("k", k, 0.1, 100.0) ||
      !args.number("alpha1", options.cusumAlpha1, 0.0, 1000.0) ||
      !args.number("alpha2", options.cusumAlpha2, 0.01, 10000.0) ||
      !args.number("hypothesis-threshold", options.hypothesisThreshold, 0.01, 100.0) ||
      !args.number("confirm", options.confirmS, 0.0, 3600.0) || !args.number("settle", options.settleS, 0.0, 3600.0) ||
      !args.number("mismatch-ratio", options.mismatchRatio, 1.0001, 1e6))
    return usage(args.error());
  if (args.flag("no-model-check")) options.checkModel = false;
  for (const auto& [key, target] : {std::pair{"temperature", &options.monitoredTemperatureC},
                                    std::pair{"reference-temperature", &options.referenceTemperatureC}})
    if (args.value(key)) {
      double c = 0.0;
      if (!args.number(key, c)) return usage(args.error());
      *target = c;
    }
  if (args.value("friction-alpha")) {
    FrictionTemperatureModel friction;
    if (!args.number("friction-alpha", friction.alpha)) return usage(args.error());
    options.friction = friction;
  }
  if (args.value("friction-alpha") && args.value("temperature-logs"))
    return usage("give alpha (--friction-alpha) or the logs to estimate it from (--temperature-logs), not both");
  if (args.value("k")) {
    options.classicalK = options.robustK = k;
    options.classicalScales.clear();
    options.robustScales.clear();
  }
  if (args.value("alpha2")) options.cusumScales.clear();
  if (args.value("lambda")) {
    options.estimator.lambda = lambda;
    options.robustLambda = std::min(lambda, 0.999999);
  }
  DiagnosisRequest request;
  request.calibrate = args.flag("calibrate");
  CalibrationOptions& calibration = request.calibration;
  int runs = calibration.healthyRuns;
  if (!args.number("false-alarms-per-hour", calibration.targetFalseAlarmsPerHour) ||
      !args.integer("runs", runs, 1, CalibrationOptions::kMaxRuns) ||
      !args.integer("threads", calibration.threads, 1, 256))
    return usage(args.error());
  calibration.healthyRuns = runs;
  calibration.faultyRuns = std::max(1, runs / 5);
  if (!calibration.isValid(&why)) return usage(why);
  if (!options.isValid(&why)) return usage(why);
  if (auto f = args.value("seed-fault")) {
    const auto eq = f->find('=');
    double factor = 0.0;
    if (eq == std::string::npos || !(std::istringstream(f->substr(eq + 1)) >> factor) || !(factor > 0.0))
      return usage("--seed-fault expects NAME=FACTOR (e.g. k_T=1.2), not " + inQuotes(*f));
    request.seedFault = std::make_pair(f->substr(0, eq), factor);
  }

  auto model = modelFromArgs(args, "diagnose", err);
  if (!model) return kExitUsage;
  auto readOptions = logReadOptions(args, err);
  if (!readOptions) return kExitUsage;
  if (auto list = args.value("temperature-logs")) {
    std::vector<std::string> paths;
    if (!parseNames(*list, paths)) return usage("--temperature-logs expects FILE,FILE,...");
    std::vector<IdData> logs;
    for (const auto& p : paths) {
      auto l = loadLog(p, *readOptions, err);
      if (!l) return kExitBadInput;
      logs.push_back(std::move(*l));
    }
    std::vector<const IdData*> pointers;
    for (const auto& l : logs) pointers.push_back(&l);
    // T_ref: the first log's temperature (any value works; it only names f_m0).
    const auto first = logTemperature(logs.front()).celsius;
    const FrictionTemperatureFit fit =
        frictionFromHealthyLogs(*model, pointers, paths, options, first.value_or(20.0));
    if (fit.termination != Termination::Converged) {
      err << pre << "--temperature-logs: " << fit.message << "\n";
      return kExitBadInput;
    }
    options.friction = fit.model;
    if (!args.flag("json")) out << "Friction against temperature: " << fit.message << "\n";
  }
  request.model = std::move(model);
  request.options = options;
  if (!request.isValid(&why)) return usage(why);
  auto log = loadLog(args.positional()[0], *readOptions, err);
  if (!log) return kExitBadInput;
  if (auto s = diagnosisSignals(*log, options.predictor, &why); !s) {
    err << pre << args.positional()[0] << ": " << why << "\n";
    return kExitBadInput;
  }
  if (referenceLog) {
    auto healthy = loadLog(*referenceLog, *readOptions, err);
    if (!healthy) return kExitBadInput;
    if (auto s = diagnosisSignals(*healthy, options.predictor, &why); !s) {
      err << pre << *referenceLog << ": " << why << "\n";
      return kExitBadInput;
    }
    request.referenceLog = std::make_shared<const IdData>(std::move(*healthy));
  }
  const DiagnosisRun run = runDiagnosisRequest(request, *log, progressLine(err, "diagnose"));
  if (run.termination == Termination::Failed) {
    err << pre << run.message << "\n";
    return run.badRequest ? kExitUsage : kExitNumerical;
  }
  const DiagnosisResult& r = run.result;
  if (auto trace = args.value("trace"); trace && !writeTrace(r, *trace, &why)) {
    err << pre << why << "\n";
    return kExitBadInput;
  }
  if (args.flag("json")) {
    auto j = diagnosisResultJson(r);
    if (run.calibration) j["calibration"] = calibrationJson(*run.calibration);
    else j["thresholds_provenance"] = thresholdsProvenance(r.options);
    out << j.dump(2) << "\n";
  } else {
    if (run.calibration) out << calibrationText(*run.calibration);
    else out << "Thresholds: " << thresholdsProvenance(r.options) << "\n";
    out << r.summary() << "\n";
    if (r.termination != Termination::Converged) out << r.message << "\n";
    if (r.modelCheck.checked && !r.modelCheck.mismatch) out << r.modelCheck.message << "\n";
    out << "Temperature: " << r.temperature.message << "\n";
    out << "Reference: " << r.referenceSource << "\n";
  }
  return r.termination == Termination::Converged ? kExitOk : kExitNumerical;
}

}  // namespace flexarm::cli
