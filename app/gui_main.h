#pragma once
#include <string>

namespace flexarm {
// Starts the window, optionally on a log; with a screenshot path it saves the window once the
// log is shown and quits. Returns the exit code.
int runGui(int argc, char** argv, const std::string& log, const std::string& screenshot);
}  // namespace flexarm
