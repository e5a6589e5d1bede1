// flexarm: with a verb it runs headless (see `flexarm --help`); otherwise it opens the window,
// optionally on a log given as the only argument.
#include <iostream>
#include <string>
#include <vector>

#include "app/cli/cli.h"

#ifdef FLEXARM_WITH_GUI
#include "app/gui_main.h"
#endif

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  const bool headless = !args.empty() && (flexarm::cli::isVerb(args[0]) || args[0] == "--help" ||
                                          args[0] == "-h" || args[0] == "--version" ||
                                          args[0] == "help");
  if (headless) return flexarm::cli::runCommandLine(args, std::cout, std::cerr);
#ifdef FLEXARM_WITH_GUI
  return flexarm::runGui(argc, argv);
#else
  if (!args.empty() && args[0].rfind("-", 0) != 0)
    std::cerr << "flexarm: this build has no window; use a verb (flexarm --help)\n";
  else
    std::cerr << "flexarm: unknown option (flexarm --help)\n";
  return flexarm::cli::kExitUsage;
#endif
}
