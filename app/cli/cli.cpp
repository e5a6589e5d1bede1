#include "app/cli/cli.h"

#include <ostream>
#include <stdexcept>
#include <string>

namespace flexarm::cli {

const std::vector<Verb>& verbs() {
  static const std::vector<Verb> kVerbs = {
      {"info", "channels, units, sample rate, length, metadata and ranges of a log", runInfo},
      {"preprocess", "differentiate, decimate with anti-alias filter, detrend, cut; write CSV",
       runPreprocess},
      {"model", "physical model: matrices, poles, zeros, notch and peak frequencies", runModel},
      {"simulate", "closed-loop simulation of a model with effects; writes a log and its truth",
       runSimulate},
      {"fit", "estimate ARX/ARMAX/OE/BJ or physical models with std, fit %, notches, peaks",
       runFit},
      {"bode", "frequency response of a fitted model or SPA/ETFE with bands, to CSV", runBode},
      {"compare", "models against data: simulated or k-step predicted output, fit %, deflection",
       runCompare},
      {"residuals", "whiteness and input independence of a model's residuals (99 % bounds)",
       runResiduals},
      {"sensitivity", "domain of attraction of a fit's initial values, then Monte-Carlo starts",
       runSensitivity},
      {"lqg", "LQG design of chapter 8: gains, poles, Nyquist, max |S|, Bode integral",
       runLqg},
      {"run", "replay a saved session headless and write its PDF/HTML report", runRun},
      {"discover", "find the effect a physical model misses and show the gap shrink",
       runDiscover},
      {"recursive", "estimate physical parameters sample by sample (chapter 6's RPEM)",
       runRecursive},
      {"diagnose", "detect and isolate a fault in k_T, J_a or f_m from recursive estimates",
       runDiagnose},
      {"fleet", "every robot's axes over days: new logs diagnosed, stored, trends, maintenance",
       runFleet},
  };
  return kVerbs;
}

bool isVerb(const std::string& word) {
  for (const auto& v : verbs())
    if (word == v.name) return true;
  return false;
}

namespace {

void printHelp(std::ostream& out) {
  out << "FlexArm " << FLEXARM_VERSION
      << " - identification, diagnosis and control of flexible robot arms\n\n"
         "Usage:\n"
         "  flexarm [LOG]               open the window (optionally on a log)\n"
         "  flexarm VERB [options]      run one step without a window\n"
         "  flexarm VERB --help         explain a verb's options\n\nVerbs:\n";
  for (const auto& v : verbs()) {
    std::string name = v.name;
    name.resize(14, ' ');
    out << "  " << name << v.summary << "\n";
  }
  out << "\nExit status: 0 success, 2 usage error, 3 bad input (the message names file, line\n"
         "and problem), 4 numerical failure.\n";
}

}  // namespace

int runCommandLine(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    printHelp(out);
    return kExitOk;
  }
  if (args[0] == "--version") {
    out << "flexarm " << FLEXARM_VERSION << "\n";
    return kExitOk;
  }
  for (const auto& v : verbs()) {
    if (args[0] != v.name) continue;
    // Each verb checks its arguments and reports data problems itself; a value a core
    // function still refuses (std::invalid_argument: a parameter outside its bounds, ...) is
    // a usage error, anything else a numerical failure, both with a sentence, never an abort.
    try {
      return v.run({args.begin() + 1, args.end()}, out, err);
    } catch (const std::invalid_argument& e) {
      err << "flexarm " << v.name << ": " << e.what() << "\n";
      return kExitUsage;
    } catch (const std::exception& e) {
      // A library's own words ("[json.exception.type_error.316] ...") are no message for a user.
      const std::string what = e.what();
      if (what.rfind("[json.exception.", 0) == 0)
        err << "flexarm " << v.name << ": the result could not be written as JSON: a name or text in the input "
            << "is not UTF-8\n";
      else
        err << "flexarm " << v.name << ": " << what << "\n";
      return kExitNumerical;
    }
  }
  err << "flexarm: unknown verb '" << args[0] << "' (flexarm --help lists the verbs)\n";
  return kExitUsage;
}

}  // namespace flexarm::cli
