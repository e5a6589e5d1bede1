// flexarm residuals (LOG | --session FILE) [model] [--on estimation|validation] [--lags M]
//                   [--json]
#include <nlohmann/json.hpp>
#include <ostream>

#include "core/common/text.h"
#include "app/cli/cli.h"
#include "app/cli/evaluation_args.h"
#include "core/compare/compare_json.h"

namespace flexarm::cli {
namespace {

const char* kResidualsHelp =
    "Usage: flexarm residuals (LOG | --session FILE) [--models NAME | --model-file FILE |\n"
    "                         --model STRUCTURE ...] [--on estimation|validation] [--lags M]\n"
    "                         [--level P] [--json]\n\n"
    "Residual analysis of one model (Ljung's model validation, SITB's resid): the\n"
    "autocorrelation of its errors for lags 1..M and their cross-correlation with the input\n"
    "for lags -M..M, with bounds at the level (99 %), the whiteness test (N sum r^2 against\n"
    "the chi^2(M) quantile) and the test of independence from past inputs (Ljung (16.61)).\n"
    "The errors are the one-step prediction errors (4.5) of a black-box estimate and the\n"
    "output errors y - G u of a physical model (y minus the simulation with its effects), on\n"
    "the data as the model's fit prepared them. With several models (a session's list) the\n"
    "last one is analysed unless --models names one.\n\n"
    "Options:\n"
    "  --on RANGE            estimation (default) or validation\n"
    "  --lags M              largest lag (default 25; the range needs 2 M + 10 samples)\n"
    "  --level P             level of the bounds and tests (default 0.99)\n"
    "  --json                print the result as JSON\n\n";

const char* kResidualsJson =
    "\nJSON: schema, termination, code (ok, no_data, no_range, rate_mismatch, no_residuals,\n"
    "too_short), message, model, data, data_note, range, samples, sample_time_s, errors\n"
    "(one_step_prediction, output_error), lags, autocorrelation, autocorrelation_bound,\n"
    "cross_lags, cross_correlation, cross_correlation_bound, whiteness {statistic, threshold,\n"
    "passed}, independence {statistic, threshold, passed}, verdict, seconds.\n\n"
    "Exit status: 0 analysed (whatever the tests say), 2 usage, 3 unreadable input or data\n"
    "the analysis cannot use (no range, too short), 4 no residuals (an unstable model).\n";

}  // namespace

int runResiduals(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  auto valued = evaluationValuedOptions();
  for (const char* o : {"on", "lags", "level"}) valued.push_back(o);
  ArgParser args(evaluationFlagOptions(), valued);
  auto usage = [&](const std::string& why) {
    err << "flexarm residuals: " << why << "\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << kResidualsHelp << evaluationOptionsHelp() << kResidualsJson;
    return kExitOk;
  }
  ResidualsRequest request;
  if (const auto on = args.value("on")) {
    const auto r = dataRangeFromString(*on);
    if (!r) return usage("--on must be estimation or validation, not " + inQuotes(*on));
    request.range = *r;
  }
  if (args.value("lags") && !args.integer("lags", request.options.maxLag, 1, 100000)) return usage(args.error());
  if (args.value("level") && !args.number("level", request.options.level)) return usage(args.error());
  EvaluationInput in;
  if (const int code = evaluationInput(args, "residuals", in, err); code != kExitOk) return code;
  if (in.models.empty()) return usage("no model: give --session, --model-file or --model");
  request.data = in.data;
  request.model = in.models.back();
  std::string why;
  if (!request.isValid(&why)) return usage(why);
  const ResidualsResult r = flexarm::runResiduals(request);
  if (args.flag("json")) out << residualsResultJson(r).dump(2) << "\n";
  else out << r.summary() << "\n";
  if (r.ok()) return kExitOk;
  if (!args.flag("json")) err << "flexarm residuals: " << r.message << "\n";
  return r.code == ResidualsCode::NoResiduals ? kExitNumerical : kExitBadInput;
}

}  // namespace flexarm::cli
