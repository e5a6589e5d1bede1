#pragma once
// Experiments named by a user, as `flexarm fit --log/--validation-log`, the Fit panel's "More
// experiments" and a session's fit request give them: a log file and the part of it used,
// written FILE or FILE@A:B (seconds). Reading them into FitOptions' experiment lists is one
// implementation for all three; it reads files, so the panel calls it inside its background job.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/ident/fit.h"
#include "core/io/log_io.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

struct ExperimentSource {
  std::string path;
  std::optional<SecondsRange> range;  // unset: the log's stored range of its kind, else all of it
  bool validation = false;            // a validation experiment, else an estimation one
  bool operator==(const ExperimentSource& o) const {
    return path == o.path && range == o.range && validation == o.validation;
  }
};

// Parses FILE or FILE@A:B (a FILE that exists is taken whole, whatever it is named); nullopt
// with a sentence for a malformed range or an empty file name.
std::optional<ExperimentSource> experimentSourceFromText(const std::string& text, bool validation, std::string* why);
// FILE or FILE@A:B.
std::string experimentSourceText(const ExperimentSource& s);
// A list separated by commas or new lines, each FILE[@A:B] an estimation experiment and
// "val: FILE[@A:B]" a validation one, e.g. "b.csv@0:10, val: c.csv"; empty text, none.
std::optional<std::vector<ExperimentSource>> experimentListFromText(const std::string& text, std::string* why);
std::string experimentListText(const std::vector<ExperimentSource>& list);

// Logs read so far, by path: a file named again is read once, so a validation range of an
// estimation log shares that experiment's means (FitOptions::validation).
using ExperimentLogs = std::map<std::string, std::shared_ptr<const IdData>>;

struct ExperimentLoad {
  std::optional<FitExperiment> experiment;
  // On failure: the file cannot be read or has no input or output (badInput), else the range
  // holds no samples of it; message is a sentence ("FILE:LINE: ..." or "FILE: ...", or "the
  // range A:B s holds no samples of the log").
  bool badInput = false;
  std::string message;
};
// Reads the source's log (readLog, then the ranges stored in it) unless logs holds it.
ExperimentLoad loadExperiment(const ExperimentSource& source, const LogReadOptions& read, ExperimentLogs& logs);

// Loads every source and appends it to options' estimation or validation list, in order;
// false with the first failure's sentence (naming the file) in why.
bool appendExperiments(FitOptions& options, const std::vector<ExperimentSource>& sources,
                       const LogReadOptions& read, ExperimentLogs& logs, std::string* why);

}  // namespace flexarm
