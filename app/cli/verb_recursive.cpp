// flexarm recursive LOG --model three-mass [--param NAME=V ...] --estimate k_T,J_a,f_m
//                   [--algorithm forgetting|kalman] [--lambda 0.995] [--r1 a,b,c] [--r2 v]
//                   [--start-scale 1.2] [--gradient sensitivity|difference]
//                   [--decimate N] [--out trajectory.csv] [--json]
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>

#include "core/common/text.h"
#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "app/cli/model_args.h"
#include "core/recursive/recursive_log.h"

namespace flexarm::cli {
namespace {

OptionTable recursiveTable() {
  OptionTable t("flexarm recursive LOG --model three-mass [--param NAME=V ...] --estimate k_T,J_a,f_m [options] "
                "[--json]",
                "Estimates physical parameters recursively, sample by sample, as the seed's chapter 6 does: the "
                "recursive prediction-error method on the continuous-time model sampled with a zero-order hold at "
                "the current estimate every sample, its gradient from the sensitivity system (6.27). The log is "
                "prepared as for a fit: the motor velocity from the motor angle (central differences at the log's "
                "rate), means removed. The estimator runs at the log's own rate up to 2 kHz, where the zero-order "
                "hold of the torque is what the controller did (a faster log is decimated to 2 kHz or below, the "
                "torque held as its mean over each new period). The seed's design variables are per 200 Hz sample "
                "and keep their memory and random walk per second at any rate (lambda^(T/5 ms), R1 T/5 ms). P(0) "
                "is chosen as the seed does (Section 6.6.2): the P update run at the nominal parameters, its "
                "diagonal averaged.");
  const double any = 1e308;
  t.add(textOption("model", "NAME", "the structure (default three-mass); nominal values are its defaults "
                                    "(three-mass: Table 5.7 p6) or a fit's (--nominal)"))
      .add(textOption("param", "NAME=VALUE", "set a nominal parameter", true))
      .add(textOption("nominal", "FILE.json", "the nominal model from `flexarm fit --json` (or a session's model): "
                                              "its structure and parameter values"))
      .add(textOption("estimate", "A,B,...", "parameters to estimate (default k_T,J_a,f_m, the seed's); the others "
                                             "stay at their nominal values. theta holds J_a as J_a^-1 as the seed does "
                                             "(see --invert); results use the model's names"))
      .add(textOption("invert", "A,B|none", "parameters theta holds as inverses (default J_a); NAME^-1 in --estimate "
                                            "does the same"))
      .add(choiceOption("algorithm", {"forgetting", "kalman"}, "forgetting",
                        "forgetting factor (Algorithm 6.1) or Kalman filter (Algorithm 6.2)"))
      .add(numberOption("lambda", "L", -any, any, "0.995", "forgetting factor per 200 Hz sample (the seed's: a "
                                                          "memory of one second at any rate)"))
      .add(textOption("r1", "a,b,c", "diag R1 of Algorithm 6.2 per 200 Hz sample, one per estimated parameter "
                                     "(default (6.54): 5e-8, 5e-7, 5e-6 for k_T, J_a^-1, f_m)"))
      .add(flagOption("per-sample", "--lambda and --r1 are per sample at the rate the estimator runs at, not per "
                                    "200 Hz sample"))
      .add(choiceOption("tracking", {"fixed", "variable", "bank"}, "fixed",
                        "how changing parameters are followed (the seed's 9.2): fixed (lambda or R1 as designed), "
                        "variable (information-constant forgetting: lambda(t) drops when the prediction errors "
                        "grow, down to --lambda-min; forgetting algorithm), bank (estimators started at "
                        "hypothesised change times every --bank-spacing s, the last --bank-size kept; a change is "
                        "accepted when one predicts the data since its start better by --bank-threshold noise "
                        "variances)"))
      .add(numberOption("lambda-min", "L", -any, any, "0.95", "variable tracking: the lowest lambda per 200 Hz "
                                                             "sample"))
      .add(numberOption("bank-spacing", "S", -any, any, "0.25", "bank tracking: seconds between hypothesised "
                                                               "changes"))
      .add(integerOption("bank-size", "N", -1, 1000, "6", "bank tracking: estimators kept"))
      .add(numberOption("bank-threshold", "T", -any, any, "40", "bank tracking: noise variances a change must "
                                                               "explain"))
      .add(numberOption("r2", "V", -any, any, "1", "R2 of Algorithm 6.2"))
      .add(numberOption("mu", "M", -any, any, "0", "regularisation (6.9)"))
      .add(numberOption("start-scale", "S", -any, any, "1", "theta(0) = S * nominal (the seed starts 20 % above: "
                                                           "1.2)"))
      .add(textOption("p0", "a,b,c", "diag P(0) (default: the seed's pre-run)"))
      .add(choiceOption("gradient", {"sensitivity", "difference"}, "sensitivity",
                        "sensitivity (6.27) or difference (6.33; can diverge for an output-error model, Example "
                        "6.1)"))
      .add(integerOption("decimate", "N", 1, 1000000, "", "decimation factor (default: the log's rate up to 2 kHz; "
                                                         "10 on a 2 kHz log is the seed's 200 Hz, with the torque "
                                                         "held as its mean over each period)"))
      .add(textOption("range", "A:B", "use the log from A to B seconds (default: all of it)"))
      .add(textOption("out", "FILE.csv", "write the trajectory: time_s, theta, sigma per parameter, y, yhat, "
                                         "epsilon"))
      .add(flagOption("json", "print the result as JSON"))
      .group("Reading the log")
      .add(logReadOptionList());
  t.note("JSON fields: final and std (the model's names: J_a even when theta holds J_a^-1), theta {name: {nominal, "
         "start, final, std}} (theta's names), nominal, start, termination, message, caveat, samples, "
         "sample_time_s, decimation, preparation, algorithm, gradient, lambda and r1 (as given), "
         "design_sample_time_s, lambda_per_sample and r1_per_sample (as run), tracking, changes [{detected_s, "
         "time_s}] (bank), lambda_min_reached (variable), p0, psi_variance (diag Q (6.53)), rms_prediction_error, "
         "seconds, out.");
  t.note("Exit status: 0 the estimates stayed within their bounds, 2 usage, 3 bad log, 4 the estimate left its "
         "bounds or P blew up (the message says when; the trajectory up to there is written).");
  return t;
}

// A comma-separated list of numbers; false with a sentence for anything else.
bool parseNumbers(const std::string& option, const std::string& text, std::vector<double>& out,
                  std::string* why) {
  out.clear();
  for (const auto& item : splitList(text)) {
    double v = 0.0;
    const auto r = std::from_chars(item.data(), item.data() + item.size(), v);
    if (r.ec != std::errc() || r.ptr != item.data() + item.size() || !std::isfinite(v)) {
      *why = "--" + option + " expects numbers separated by commas, not " + inQuotes(text);
      return false;
    }
    out.push_back(v);
  }
  if (out.empty()) {
    *why = "--" + option + " expects numbers separated by commas";
    return false;
  }
  return true;
}

nlohmann::json byName(const RecursiveResult& r, double RecursiveEstimate::*field) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& e : r.estimates) j[e.parameter.modelName] = e.*field;
  return j;
}

}  // namespace

int runRecursive(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(recursiveTable());
  const std::string pre = "flexarm recursive: ";
  if (auto rc = parseArguments(args, argv, "recursive", out, err)) return *rc;
  if (args.positional().size() != 1) {
    err << pre << "expected exactly one LOG\n";
    return kExitUsage;
  }

  // The nominal model: a fit's JSON or the structure's defaults, then --param.
  std::unique_ptr<PhysicalModel> model;
  if (auto file = args.value("nominal")) {
    std::string why;
    model = modelFromFile(*file, &why);
    if (!model) {
      err << "flexarm: " << *file << ": " << why << "\n";
      return kExitBadInput;
    }
    if (auto m = args.value("model"); m && *m != model->structureName()) {
      err << pre << "--model " << *m << " differs from the " << model->structureName()
          << " model of " << *file << "\n";
      return kExitUsage;
    }
    if (!applyParams(args, *model, "recursive", err)) return kExitUsage;
  } else {
    model = modelFromArgs(args, "recursive", err);
    if (!model) return kExitUsage;
  }

  RecursiveOptions o;
  std::string why;
  if (auto e = args.value("estimate")) o.estimate = splitList(*e);
  if (auto inv = args.value("invert")) o.inverted = *inv == "none" ? std::vector<std::string>{} : splitList(*inv);
  o.algorithm = *recursiveAlgorithmFromString(args.text("algorithm"));
  o.gradient = *recursiveGradientFromString(args.text("gradient"));
  o.tracking = *recursiveTrackingFromString(args.text("tracking"));
  for (auto [name, target] : {std::pair{"lambda", &o.lambda}, {"r2", &o.r2}, {"mu", &o.mu},
                              {"start-scale", &o.startScale}, {"lambda-min", &o.lambdaMin},
                              {"bank-spacing", &o.bankSpacingS}, {"bank-threshold", &o.bankThreshold}})
    if (args.value(name)) *target = args.number(name);
  if (args.value("bank-size")) o.bankSize = static_cast<int>(args.integer("bank-size"));
  if (auto v = args.value("r1"); v && !parseNumbers("r1", *v, o.r1, &why)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  if (auto v = args.value("p0"); v && !parseNumbers("p0", *v, o.p0, &why)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  if (args.flag("per-sample")) o.designSampleTime = 0.0;
  if (!o.isValid(&why)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  RecursiveDataOptions d;
  d.decimation = static_cast<int>(args.integer("decimate"));  // 0: the log's rate up to 2 kHz
  if (auto r = args.value("range")) {
    d.range = secondsRangeFromText(*r, &why);
    if (!d.range) {
      err << pre << "--range: " << why << "\n";
      return kExitUsage;
    }
  }

  auto readOptions = logReadOptions(args, err);
  if (!readOptions) return kExitUsage;
  const std::string& path = args.positional()[0];
  LogReadResult log = readLog(path, *readOptions);
  if (!log.ok) {
    err << "flexarm: " << log.error.toString() << "\n";
    return kExitBadInput;
  }
  const RecursiveLogResult run = recursiveIdentification(log.data, *model, d, o);
  const RecursiveResult& r = run.result;
  if (r.termination == Termination::Failed) {
    err << "flexarm: " << path << ": " << r.message << "\n";
    return kExitBadInput;
  }
  const auto outPath = args.value("out");
  if (outPath && !writeTrajectoryCsv(r, *outPath, &why)) {
    err << "flexarm: " << *outPath << ": " << why << "\n";
    return kExitBadInput;
  }
  const int status = r.termination == Termination::Diverged ? kExitNumerical : kExitOk;

  if (!args.flag("json")) {
    out << model->structureName() << ", " << toString(o.algorithm) << ", "
        << toString(o.gradient) << " gradient: " << toString(r.termination) << "\n"
        << r.message << "\n";
    for (const auto& e : r.estimates) {
      char line[200];
      std::snprintf(line, sizeof line, "  %-6s = %-12.6g +- %-10.3g (start %.6g, nominal %.6g)\n",
                    e.parameter.modelName.c_str(), e.modelFinal, e.modelSigma, e.modelStart,
                    e.modelNominal);
      out << line;
    }
    out << "samples " << r.samples << " at " << 1.0 / run.sampleTime << " Hz (" << run.preparation
        << "), " << r.seconds << " s\n";
    if (o.algorithm == RecursiveAlgorithm::ForgettingFactor)
      out << "lambda " << o.lambda << " " << designRateText(o) << ": " << r.asRun.lambda
          << " per sample at " << 1.0 / run.sampleTime << " Hz\n";
    if (!r.caveat.empty()) out << "note: " << r.caveat << "\n";
    return status;
  }
  nlohmann::json theta = nlohmann::json::object();
  for (const auto& e : r.estimates)
    theta[e.parameter.name] = {{"nominal", e.parameter.nominal}, {"start", e.start},
                               {"final", e.final},               {"std", e.sigma},
                               {"unit", e.parameter.unit},       {"spread", e.spread}};
  nlohmann::json changes = nlohmann::json::array();
  for (std::size_t i = 0; i < r.trajectory.changeTime.size(); ++i)
    changes.push_back({{"detected_s", r.trajectory.changeDetected[i]},
                       {"time_s", r.trajectory.changeTime[i]}});
  const double lambdaLow = r.trajectory.lambda.empty()
                               ? 1.0
                               : *std::min_element(r.trajectory.lambda.begin(), r.trajectory.lambda.end());
  nlohmann::json p0 = nlohmann::json::object(), psi = nlohmann::json::object();
  for (std::size_t i = 0; i < r.estimates.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    p0[r.estimates[i].parameter.name] = r.p0[k];
    psi[r.estimates[i].parameter.name] = r.Q.size() ? nlohmann::json(r.Q(k, k)) : nlohmann::json();
  }
  nlohmann::json j = {{"model", model->structureName()},
                      {"final", byName(r, &RecursiveEstimate::modelFinal)},
                      {"std", byName(r, &RecursiveEstimate::modelSigma)},
                      {"nominal", byName(r, &RecursiveEstimate::modelNominal)},
                      {"start", byName(r, &RecursiveEstimate::modelStart)},
                      {"theta", theta},
                      {"termination", toString(r.termination)},
                      {"message", r.message},
                      {"caveat", r.caveat.empty() ? nlohmann::json() : nlohmann::json(r.caveat)},
                      {"samples", r.samples},
                      {"sample_time_s", run.sampleTime},
                      {"decimation", run.decimation},
                      {"preparation", run.preparation},
                      {"algorithm", toString(o.algorithm)},
                      {"gradient", toString(o.gradient)},
                      {"lambda", o.lambda},
                      {"r1", o.r1},
                      {"design_sample_time_s", o.designSampleTime},
                      {"lambda_per_sample", r.asRun.lambda},
                      {"r1_per_sample", r.asRun.r1},
                      {"r2", o.r2},
                      {"tracking", toString(o.tracking)},
                      {"changes", changes},
                      {"lambda_min_reached", lambdaLow},
                      {"mu", o.mu},
                      {"p0", p0},
                      {"psi_variance", psi},
                      {"rms_prediction_error", r.rmsEpsilon},
                      {"prediction_error_lag1", r.epsilonLag1},
                      {"seconds", r.seconds},
                      {"out", outPath ? nlohmann::json(*outPath) : nlohmann::json()}};
  out << j.dump(2) << "\n";
  return status;
}

}  // namespace flexarm::cli
