#pragma once
// Shared by `flexarm fit` and `flexarm bode`: the fit options read from the command line into
// the options of the one fit pipeline (core/ident/fit.h), which both verbs run unchanged.
#include <iosfwd>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "core/ident/fit.h"
#include "core/ident/fit_json.h"

namespace flexarm::cli {

// The options of the fit pipeline (model, effects, parameters, method, data; the log reader's
// are logReadOptionList's). nonparametric: --model takes spa[:M] and etfe[:W] as well (bode).
std::vector<Option> fitOptionList(bool nonparametric);

// Reads LOG and the fit options, runs the pipeline and returns kExitOk, or the exit code
// after printing a message prefixed by "flexarm VERB: " (usage 2, bad input 3, numerical 4).
// logs: the file of each estimation and validation experiment, in the order of FitOptions (and
// so of FitResult::estimation and validation).
int runFitPipeline(ArgParser& args, const std::string& verb, FitResult& result, std::ostream& err,
                   bool allowNonparametric = false, FitLogNames* logs = nullptr);

}  // namespace flexarm::cli
