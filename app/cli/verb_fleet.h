#pragma once
// `flexarm simulate --fleet DIR`: the simulated plant, beside `flexarm fleet` that watches it.
#include <iosfwd>

#include "app/cli/cli.h"

namespace flexarm::cli {

// The options simulate reads for --fleet, and the help lines that explain them.
inline const char* kSimulateFleetOptions[] = {"fleet", "robots", "axes", "days", "wear", "loads", "faults",
                                              "jobs", "alpha", "temperature-swing", "start"};
extern const char* kSimulateFleetHelp;
int runSimulateFleet(ArgParser& args, std::ostream& out, std::ostream& err);

}  // namespace flexarm::cli
