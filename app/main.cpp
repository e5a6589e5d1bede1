// flexarm: with a verb it runs headless (see `flexarm --help`); otherwise it opens the window,
// optionally on a log given as the only argument (`--screenshot FILE` saves the window once
// the log is shown, then quits).
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "app/cli/cli.h"

#ifdef FLEXARM_WITH_GUI
#include "app/cli/verb_run.h"
#include "app/gui_main.h"
#include "app/report_writer.h"
#endif

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
#ifdef FLEXARM_WITH_GUI
  flexarm::cli::setReportRenderer(&flexarm::writeReportFile);  // `flexarm run --report`
#endif
  const bool headless = !args.empty() && (flexarm::cli::isVerb(args[0]) || args[0] == "--help" ||
                                          args[0] == "-h" || args[0] == "--version" ||
                                          args[0] == "help");
  if (headless) return flexarm::cli::runCommandLine(args, std::cout, std::cerr);

  std::string screenshot, log;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--screenshot" && i + 1 < args.size()) {
      screenshot = args[++i];
    } else if (args[i].rfind("-", 0) == 0 || !log.empty()) {
      std::cerr << "flexarm: unexpected '" << args[i] << "' (flexarm --help)\n";
      return flexarm::cli::kExitUsage;
    } else if (!std::filesystem::exists(args[i])) {
      std::cerr << "flexarm: '" << args[i]
                << "' is neither a verb nor a file (flexarm --help lists the verbs)\n";
      return flexarm::cli::kExitUsage;
    } else {
      log = args[i];
    }
  }
#ifdef FLEXARM_WITH_GUI
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  const char* platform = std::getenv("QT_QPA_PLATFORM");
  if (!(display && *display) && !(wayland && *wayland) && !(platform && *platform)) {
    std::cerr << "flexarm: no display to open the window on (set DISPLAY, run under xvfb-run, "
                 "or use a verb: flexarm --help)\n";
    return flexarm::cli::kExitUsage;
  }
  return flexarm::runGui(argc, argv, log, screenshot);
#else
  std::cerr << "flexarm: this build has no window; use a verb (flexarm --help)\n";
  return flexarm::cli::kExitUsage;
#endif
}
