#pragma once
// The headless command line: `flexarm VERB [options]`. Each verb is a function that parses
// its own arguments, prints JSON with --json, and returns one of the exit codes below.
// Nothing here uses Qt, so the same verbs run in a build without the GUI.
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace flexarm::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,      // unknown verb or option, missing or malformed argument
  kExitBadInput = 3,   // unreadable or malformed input file
  kExitNumerical = 4,  // the computation failed (diverged, singular, ...)
};

using VerbFunction = int (*)(const std::vector<std::string>& args, std::ostream& out,
                             std::ostream& err);

struct Verb {
  const char* name;
  const char* summary;  // one line for `flexarm --help`
  VerbFunction run;
};

// All verbs, in the order `flexarm --help` lists them.
const std::vector<Verb>& verbs();

// Runs `flexarm ARGS...` (args excludes the program name). Returns the exit code.
int runCommandLine(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

// True when args name a verb (the executable then runs without a window).
bool isVerb(const std::string& word);

// A small option parser shared by the verbs. Options are --name VALUE, --name=VALUE or
// flags (--json); repeated options keep every value; the rest are positional arguments.
class ArgParser {
 public:
  // flags: options that take no value; valued: options that take one value.
  ArgParser(std::vector<std::string> flags, std::vector<std::string> valued);
  // Parses args; on failure returns false and sets error() to a sentence.
  bool parse(const std::vector<std::string>& args);
  const std::string& error() const { return error_; }

  bool flag(const std::string& name) const;
  std::optional<std::string> value(const std::string& name) const;
  std::vector<std::string> values(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // Every valued option and flag as given, in command-line order (name without "--", value;
  // empty for a flag), for options whose order matters (the last one wins).
  const std::vector<std::pair<std::string, std::string>>& sequence() const { return sequence_; }

  // Typed access; on a malformed value return false and set error().
  bool number(const std::string& name, double& out);
  bool integer(const std::string& name, long& out);
  // An integer in [min, max]: anything else (a fraction, 1e12, a value that overflows) is
  // refused with a sentence naming the allowed range, never wrapped.
  bool integer(const std::string& name, int& out, int min, int max);

 private:
  std::vector<std::string> flags_, valued_;
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positional_;
  std::vector<std::pair<std::string, std::string>> sequence_;
  std::string error_;
};

// The non-empty items of a comma-separated list ("k_T,J_a,f_m").
std::vector<std::string> splitList(const std::string& text);

// Verbs. Each lives in its own verb_*.cpp.
int runInfo(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runPreprocess(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runModel(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runSimulate(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runFit(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runBode(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runLqg(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runRun(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runDiscover(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runRecursive(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runDiagnose(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runFleet(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runCompare(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runResiduals(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int runSensitivity(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace flexarm::cli
