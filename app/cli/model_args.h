#pragma once
// Options shared by the verbs that build a physical model: --model, --param NAME=VALUE,
// --free/--fixed NAME, --output, --arm-accel; and the model as JSON.
#include <iosfwd>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "core/models/physical_models.h"

namespace flexarm::cli {

// The options these helpers read (model, param, free, fixed, output, arm-accel), for a verb's
// option table.
std::vector<Option> modelOptionList();
// Their names and help, for verbs not yet on an option table.
std::vector<std::string> modelValuedOptions();
std::vector<std::string> modelFlagOptions();
std::string modelOptionsHelp();

// The model the options describe, or nullptr after printing "flexarm VERB: ..." to err.
std::unique_ptr<PhysicalModel> modelFromArgs(const ArgParser& args, const std::string& verb,
                                             std::ostream& err);

// Sets the --param NAME=VALUE values on model; false after printing "flexarm VERB: ..." to err.
bool applyParams(const ArgParser& args, PhysicalModel& model, const std::string& verb,
                 std::ostream& err);

// The physical model a JSON file holds: the output of `flexarm fit --json` ("model":
// "three-mass (K = 0)", "parameters": {name: value}) or a model as sessions store it
// ("structure", "parameters": [...]). nullptr with a sentence (to follow the file name).
std::unique_ptr<PhysicalModel> modelFromFile(const std::string& path, std::string* why);

// {"structure", "description", "parameters": [{name, unit, value, lower, upper, free}]}.
nlohmann::json modelJson(const PhysicalModel& model);

}  // namespace flexarm::cli
