// flexarm sensitivity (LOG | --session FILE) [model] [--runs N] [--seed S] [--threads T]
//                     [--json]
#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "app/cli/evaluation_args.h"
#include "app/cli/progress_line.h"
#include "core/compare/compare_json.h"

namespace flexarm::cli {
namespace {

const char* kSensitivityHelp =
    "Usage: flexarm sensitivity (LOG | --session FILE) [--models NAME | --model-file FILE |\n"
    "                           --model STRUCTURE ...] [--runs N] [--seed S] [--threads T]\n"
    "                           [--json]\n\n"
    "The sensitivity study of the seed's Section 5.3.3 on a physical model (usually an\n"
    "estimate): for every free parameter, how far its initial value may move before the\n"
    "prediction-error fit (5.7) on the estimation range fails, by interval halving (the domain\n"
    "of attraction, Table 5.8), then N fits from random initial values of all free parameters\n"
    "at once, drawn inside 20 % of those limits, and their success rate (the seed: 649 of\n"
    "1000). A fit succeeds when its loss is less than 5 % above the loss of the refit from the\n"
    "model itself. The fits run on the estimation range as the model's fit prepared it\n"
    "(--decimation for a model file); a model's effects are left out (its linear part is\n"
    "refitted). With several models (a session's list) the last physical one is studied\n"
    "unless --models names one.\n\n"
    "Options:\n"
    "  --runs N              Monte-Carlo fits after the domain of attraction (default 100;\n"
    "                        0: the domain of attraction alone)\n"
    "  --seed S              seed of the random starts (default 1)\n"
    "  --threads T           fits in parallel (default 2)\n"
    "  --json                print the result as JSON\n\n";

const char* kSensitivityJson =
    "\nJSON: schema, termination, code (ok, no_data, not_physical, no_free_parameters,\n"
    "reference_failed, cancelled), message, model, data, data_note, range, samples,\n"
    "effects_left_out, attraction {reference_loss, fits, termination, message, seconds,\n"
    "parameters [{name, lower_factor, upper_factor, lower_open, upper_open, fits}]},\n"
    "monte_carlo {runs, completed, successes, success_rate, reference_loss, termination,\n"
    "message, seconds}, seconds. Factors are of the estimate's value (1 = 100 %).\n\n"
    "Exit status: 0 studied, 2 usage, 3 unreadable input, 4 the fits failed.\n";

}  // namespace

int runSensitivity(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  auto valued = evaluationValuedOptions();
  for (const char* o : {"runs", "seed", "threads"}) valued.push_back(o);
  ArgParser args(evaluationFlagOptions(), valued);
  auto usage = [&](const std::string& why) {
    err << "flexarm sensitivity: " << why << "\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << kSensitivityHelp << evaluationOptionsHelp() << kSensitivityJson;
    return kExitOk;
  }
  SensitivityRequest request;
  request.monteCarlo.runs = 100;
  int threads = 2, seed = 1;
  if (args.value("runs") && !args.integer("runs", request.monteCarlo.runs, 0, kMaxSensitivityRuns))
    return usage(args.error());
  if (args.value("seed") && !args.integer("seed", seed, 0, 1 << 30)) return usage(args.error());
  if (args.value("threads") && !args.integer("threads", threads, 1, 64)) return usage(args.error());
  request.monteCarlo.seed = static_cast<unsigned>(seed);
  request.attraction.threads = request.monteCarlo.threads = threads;
  EvaluationInput in;
  if (const int code = evaluationInput(args, "sensitivity", in, err); code != kExitOk) return code;
  const EvaluatedModel* chosen = nullptr;
  for (const auto& m : in.models)
    if (m.physical) chosen = &m;
  if (!chosen) return usage("no physical model: give --session, --model-file or --model");
  request.data = in.data;
  request.model = *chosen;
  std::string why;
  if (!request.isValid(&why)) return usage(why);
  const SensitivityResult r = runSensitivityStudy(request, progressLine(err, "sensitivity"));
  if (args.flag("json")) {
    out << sensitivityResultJson(r).dump(2) << "\n";
  } else {
    out << r.summary() << "\n";
    for (const auto& p : r.attraction.parameters)
      out << "  " << p.name << ": initial values from " << (p.lowerOpen ? "beyond " : "") << 100.0 * p.lowerFactor
          << " % to " << (p.upperOpen ? "beyond " : "") << 100.0 * p.upperFactor << " % of the estimate\n";
  }
  if (r.ok()) return kExitOk;
  if (!args.flag("json")) err << "flexarm sensitivity: " << r.message << "\n";
  return r.code == SensitivityCode::NoData ? kExitBadInput : kExitNumerical;
}

}  // namespace flexarm::cli
