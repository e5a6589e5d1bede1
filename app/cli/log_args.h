#pragma once
// Options shared by every verb that reads a log: format and column mapping for headerless
// tables and .mat files, and ranges given in seconds ("A:B").
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "core/io/log_io.h"

namespace flexarm::cli {

// The options the log reader understands, for a verb's option table ("Reading the log").
std::vector<Option> logReadOptionList();
// Their names and help, for verbs not yet on an option table.
std::vector<std::string> logReadOptionNames();
const char* logReadOptionsHelp();

// Builds reader options from parsed arguments; on a bad value prints to err and returns
// nullopt (the verb exits with kExitUsage).
std::optional<LogReadOptions> logReadOptions(ArgParser& args, std::ostream& err);

// Reads a log; on failure prints "flexarm: FILE:LINE: ..." to err and returns nullopt (the
// verb exits with kExitBadInput). Ranges stored in the log's metadata are applied.
std::optional<IdData> loadLog(const std::string& path, const LogReadOptions& options,
                              std::ostream& err);

// Parses "A:B" in seconds into a sample range of data; false on malformed text.
bool parseTimeRange(const std::string& text, const IdData& data, SampleRange& range,
                    std::string* why);

}  // namespace flexarm::cli
