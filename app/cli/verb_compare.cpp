// flexarm compare (LOG | --session FILE) [models] [--on validation|estimation] [--horizon K]
//                 [--json]
#include <cstdio>
#include <nlohmann/json.hpp>
#include <ostream>

#include "core/common/text.h"
#include "app/cli/cli.h"
#include "app/cli/evaluation_args.h"
#include "app/cli/progress_line.h"
#include "core/compare/compare_json.h"

namespace flexarm::cli {
namespace {

const char* kCompareHelp =
    "Usage: flexarm compare (LOG | --session FILE) [--model-file FIT.json ...]\n"
    "                       [--model STRUCTURE --param NAME=VALUE ... --effect ...]\n"
    "                       [--on validation|estimation] [--horizon K] [--json]\n\n"
    "Compares the measured output with each model's output on the validation range (the\n"
    "estimation range when none is set), as the seed's Figure 5.11, and prints each model's\n"
    "fit % (5.2) 1 - sum e^2 / sum (y - mean y)^2 and MATLAB compare's NRMSE fit\n"
    "1 - |e| / |y - mean y|. Every model runs on the data as its fit prepared them (its rate,\n"
    "the motor velocity from a logged angle, the estimation means removed for a linear model,\n"
    "kept with effects). The output is simulated from the input alone, on the validation range\n"
    "from the log's first sample and on the estimation range from the range's first sample,\n"
    "the figures `flexarm fit` and the Fit panel report; with --horizon K it is the K-step\n"
    "prediction y(t | t-K) (a black-box model's noise model predicts; an output-error model\n"
    "predicts what it simulates). On a log with an arm-side encoder (arm_angle_rad) each\n"
    "physical model's deflection r phi_m - phi_a is compared too, each about its mean.\n\n"
    "Options:\n"
    "  --on RANGE            validation (default) or estimation\n"
    "  --horizon K           0: simulation (default); K >= 1: K-step prediction\n"
    "  --observer auto|off|HZ  models with effects: auto (default) predicts each one step\n"
    "                        ahead through the load observer its fit predicts through (4 Hz on\n"
    "                        a closed-loop log, what `flexarm fit --effect` and `flexarm\n"
    "                        discover` minimise, since the open-loop simulation integrates the\n"
    "                        load torque the controller answers); off simulates them open loop;\n"
    "                        HZ sets the bandwidth. Models without effects are simulated\n"
    "  --no-deflection       skip the deflection check\n"
    "  --json                print the result as JSON\n\n";

const char* kCompareJson =
    "\nJSON: schema, termination, code (ok, no_data, cancelled), message, data, data_note,\n"
    "range, range_fell_back, horizon, output {name, unit}, gear_ratio, models [{name, status\n"
    "(compared, rate_mismatch, diverged, failed), message, decimation, rate_hz, fit_percent,\n"
    "fit_percent_nrmse, basis {kind, horizon, observer_hz, start, effects, means_removed,\n"
    "rate_hz, data, range, text}, deflection {fit_percent, fit_percent_nrmse, rms_error_rad,\n"
    "measured_rms_rad, gear_ratio}}], seconds.\n\n"
    "Exit status: 0 compared (a model that could not be simulated is listed with its status),\n"
    "2 usage, 3 unreadable input, 4 no model could be compared.\n";

}  // namespace

int runCompare(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  auto flags = evaluationFlagOptions();
  flags.push_back("no-deflection");
  auto valued = evaluationValuedOptions();
  valued.push_back("on");
  valued.push_back("horizon");
  valued.push_back("observer");
  ArgParser args(flags, valued);
  auto usage = [&](const std::string& why) {
    err << "flexarm compare: " << why << "\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << kCompareHelp << evaluationOptionsHelp() << kCompareJson;
    return kExitOk;
  }
  CompareRequest request;
  if (const auto on = args.value("on")) {
    const auto r = dataRangeFromString(*on);
    if (!r) return usage("--on must be validation or estimation, not " + inQuotes(*on));
    request.range = *r;
  }
  if (args.value("horizon") && !args.integer("horizon", request.horizon, 0, kMaxCompareHorizon))
    return usage(args.error());
  if (const auto observer = args.value("observer"); observer && *observer != "auto") {
    double hz = 0.0;
    if (*observer != "off" && !args.number("observer", hz)) return usage("--observer must be auto, off or a bandwidth in Hz");
    request.observerHz = hz;
  }
  request.deflection = !args.flag("no-deflection");
  EvaluationInput in;
  if (const int code = evaluationInput(args, "compare", in, err); code != kExitOk) return code;
  if (in.models.empty()) return usage("no model to compare: give --session, --model-file or --model");
  request.data = in.data;
  request.models = in.models;
  std::string why;
  if (!request.isValid(&why)) return usage(why);
  const CompareResult r = flexarm::runCompare(request, progressLine(err, "compare"));
  bool any = false;
  for (const auto& m : r.models) any = any || m.compared();
  if (args.flag("json")) {
    out << compareResultJson(r).dump(2) << "\n";
  } else {
    for (const auto& line : r.lines()) out << line << "\n";
  }
  if (!r.ok()) {
    if (!args.flag("json")) err << "flexarm compare: " << r.message << "\n";
    return r.code == CompareCode::NoData ? kExitBadInput : kExitNumerical;
  }
  return any ? kExitOk : kExitNumerical;
}

}  // namespace flexarm::cli
