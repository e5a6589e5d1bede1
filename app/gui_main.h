#pragma once
namespace flexarm {
// Starts the window (optionally on the log given as the only argument); returns the exit code.
int runGui(int argc, char** argv);
}  // namespace flexarm
