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

// --- Options ---------------------------------------------------------------------------
// Every verb describes its options in one table: name, kind of value, range or choices,
// default and one help line. The parser checks what is given against it, and the help text is
// written from it, so what `flexarm VERB --help` says is what the parser accepts.
enum class OptionKind {
  Flag,     // --name, no value
  Text,     // --name VALUE, read by the verb
  Number,   // a finite number in [min, max] (either end open when minOpen / maxOpen)
  Integer,  // a whole number in [min, max]
  Choice,   // one of choices
};

struct Option {
  std::string name;  // without "--"
  OptionKind kind = OptionKind::Flag;
  std::string value;  // the value as the help names it ("SPEC", "A:B", "N"); empty for a flag
  std::string help;   // one line, wrapped by the help writer
  std::string defaultValue;  // as text ("100", "auto"); empty: none (a typed getter's fallback)
  double min = -1e308, max = 1e308;
  bool minOpen = false, maxOpen = false;
  std::vector<std::string> choices;
  bool repeatable = false;  // every value is kept (values(), sequence()); else the last one counts
  bool required = false;    // parse() refuses a command line without it (unless --help)
};

Option flagOption(std::string name, std::string help);
Option textOption(std::string name, std::string value, std::string help, bool repeatable = false);
Option integerOption(std::string name, std::string value, long min, long max, std::string defaultValue,
                     std::string help);
Option numberOption(std::string name, std::string value, double min, double max, std::string defaultValue,
                    std::string help);
Option choiceOption(std::string name, std::vector<std::string> choices, std::string defaultValue, std::string help);
// The same option marked required (help says so).
Option required(Option o);
// The range of a Number or Integer option in words, with a leading space (" from 1 to 100000",
// " above 0"); empty when any value goes.
std::string rangeText(const Option& o);

// A verb's options, in the order its help lists them, under headings, between the usage line
// with a description and closing notes.
class OptionTable {
 public:
  OptionTable(std::string usage, std::string description);
  // Starts a group of options under a heading ("" for none), or adds to the current one.
  OptionTable& group(std::string heading);
  OptionTable& add(Option option);
  OptionTable& add(const std::vector<Option>& options);
  // Replaces the option of that name (a verb that shares another's table and says more).
  OptionTable& replace(Option option);
  OptionTable& note(std::string paragraph);  // printed after the options
  OptionTable& block(std::string text);      // printed as it is (own line breaks), after the notes
  const Option* find(const std::string& name) const;
  std::vector<const Option*> options() const;  // every option, --help included
  // Usage, description, every option with its value, help, choices, range and default, notes;
  // lines wrapped at 90 columns.
  std::string help() const;

 private:
  struct Group {
    std::string heading;
    std::vector<Option> options;
  };
  std::string usage_, description_;
  std::vector<Group> groups_;
  std::vector<std::string> notes_;
  std::vector<std::string> blocks_;
};

// The parser of a verb's table. Options are --name VALUE, --name=VALUE or flags (--json);
// repeated options keep every value; the rest are positional arguments.
class ArgParser {
 public:
  explicit ArgParser(OptionTable table);
  // Parses args; on failure returns false and sets error() to a sentence naming the option
  // (an unknown one, a missing value, a number out of its range, a word not among the choices,
  // a required option missing).
  bool parse(const std::vector<std::string>& args);
  const std::string& error() const { return error_; }
  const OptionTable& table() const { return table_; }

  bool flag(const std::string& name) const;
  // The last value given (nullopt when none was).
  std::optional<std::string> value(const std::string& name) const;
  std::vector<std::string> values(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // Every valued option and flag as given, in command-line order (name without "--", value;
  // empty for a flag), for options whose order matters (the last one wins).
  const std::vector<std::pair<std::string, std::string>>& sequence() const { return sequence_; }

  // The value of an option as parse() checked it: the last one given, else the table's
  // default, else 0 (or "").
  double number(const std::string& name) const;
  long integer(const std::string& name) const;
  std::string text(const std::string& name) const;

  // Verbs not yet on a table: flags and valued options by name, without help or checks.
  ArgParser(std::vector<std::string> flags, std::vector<std::string> valued);
  // Their typed access; on a malformed value return false and set error().
  bool number(const std::string& name, double& out);
  bool integer(const std::string& name, long& out);
  // An integer in [min, max]: anything else (a fraction, 1e12, a value that overflows) is
  // refused with a sentence naming the allowed range, never wrapped.
  bool integer(const std::string& name, int& out, int min, int max);
  // A finite number in [min, max], else refused with a sentence naming the option and range.
  bool number(const std::string& name, double& out, double min, double max);

 private:
  OptionTable table_;
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positional_;
  std::vector<std::pair<std::string, std::string>> sequence_;
  std::string error_;
};

// Parses a verb's command line: a usage error prints "flexarm VERB: ..." and where the help is
// to err and gives kExitUsage, --help prints the help to out and gives kExitOk; nullopt: go on.
std::optional<int> parseArguments(ArgParser& args, const std::vector<std::string>& argv, const std::string& verb,
                                  std::ostream& out, std::ostream& err);
// ------------------------------------------------------------------------------------------

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
