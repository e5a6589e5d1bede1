#pragma once
// Shared by `flexarm fit` and `flexarm bode`: the fit options read from the command line into
// the options of the one fit pipeline (core/ident/fit.h), which both verbs run unchanged.
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "core/ident/fit.h"

namespace flexarm::cli {

// --- Physical models ----------------------------------------------------------------------
// Maps a physical structure name (two-mass, three-mass, four-mass, rigid) to a model with its
// nominal parameters. This is the one place where core/models is plugged into the verbs;
// it returns nullptr while no physical model is available in this build.
std::unique_ptr<PhysicalModel> makePhysicalModel(const std::string& name);
bool isPhysicalModelName(const std::string& name);
// ------------------------------------------------------------------------------------------

// Parses "arx:NA,NB,NK", "armax:NA,NB,NC,NK", "oe:NB,NF,NK", "bj:NB,NC,ND,NF,NK" or a
// physical name (its nominal model as the start; and, when allowNonparametric, "spa[:M]" or
// "etfe[:W]"); false with a sentence on malformed text.
bool parseModelSpec(const std::string& text, FitModelSpec& spec, std::string* why,
                    bool allowNonparametric = false);

// Option names and help shared by fit and bode.
std::vector<std::string> fitValuedOptionNames();
std::vector<std::string> fitFlagNames();
const char* fitOptionsHelp();

// Reads LOG and the fit options, runs the pipeline and returns kExitOk, or the exit code
// after printing a message prefixed by "flexarm VERB: " (usage 2, bad input 3, numerical 4).
// files: when given, the file of each estimation and validation experiment, in the order of
// FitOptions (and so of FitResult::estimation and validation).
struct FitFiles {
  std::vector<std::string> estimation, validation;
};
int runFitPipeline(ArgParser& args, const std::string& verb, FitResult& result, std::ostream& err,
                   bool allowNonparametric = false, FitFiles* files = nullptr);

}  // namespace flexarm::cli
