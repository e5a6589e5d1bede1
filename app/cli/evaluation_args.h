#pragma once
// Options shared by the verbs that evaluate models on data (`flexarm compare`, `residuals`,
// `sensitivity`): the data (LOG with its ranges, or a session's analysed log and ranges) and
// the models (a session's model list, model files, or one model given by its options).
#include <iosfwd>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "core/compare/compare.h"

namespace flexarm::cli {

std::vector<std::string> evaluationValuedOptions();
std::vector<std::string> evaluationFlagOptions();
// Help lines for the options above.
std::string evaluationOptionsHelp();

struct EvaluationInput {
  EvaluationData data;
  std::vector<EvaluatedModel> models;
};

// Reads the data and the models the options name. Returns kExitOk with `in` set, or the exit
// code after printing "flexarm VERB: ..." to err (kExitUsage for options, kExitBadInput for
// files).
int evaluationInput(ArgParser& args, const std::string& verb, EvaluationInput& in, std::ostream& err);

// The models of `in` whose name is among names (all when names is empty); false after
// printing when a name is not among them.
bool selectModels(EvaluationInput& in, const std::vector<std::string>& names, const std::string& verb,
                  std::ostream& err);

}  // namespace flexarm::cli
