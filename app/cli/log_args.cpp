#include "app/cli/log_args.h"

#include <charconv>
#include <cmath>
#include <ostream>

#include "core/io/ranges.h"

namespace flexarm::cli {

std::vector<std::string> logReadOptionNames() {
  return {"format",     "input-column", "output-column", "time-column", "sample-time",
          "input-name", "output-name",  "input-var",     "output-var"};
}

const char* logReadOptionsHelp() {
  return "Reading the log:\n"
         "  --format auto|flexarm-csv|table|mat   how to read LOG (auto: by content)\n"
         "  --input-column N      headerless table: column of the input u (default 1)\n"
         "  --output-column N     headerless table: column of the output y (default 2)\n"
         "  --time-column N       headerless table: column of the time (default none)\n"
         "  --sample-time T       seconds between samples when the file stores no time; a\n"
         "                        .mat file without time_s (or a scalar Ts, dt) needs it, a\n"
         "                        table without a time column takes 1 s and says so\n"
         "  --input-name NAME     channel name for the input (default u; .mat: the variable's\n"
         "                        name, and a variable NAME is the input)\n"
         "  --output-name NAME    channel name for the output (default y; .mat: the\n"
         "                        variable's name, and a variable NAME is the output)\n"
         "  --input-var NAME      .mat: variable holding the input\n"
         "  --output-var NAME     .mat: variable holding the output\n";
}

std::optional<LogReadOptions> logReadOptions(ArgParser& args, std::ostream& err) {
  LogReadOptions o;
  if (auto f = args.value("format")) {
    if (*f == "auto") o.format = LogFormat::Auto;
    else if (*f == "flexarm-csv" || *f == "csv") o.format = LogFormat::FlexArmCsv;
    else if (*f == "table") o.format = LogFormat::Table;
    else if (*f == "mat") o.format = LogFormat::Mat;
    else {
      err << "flexarm: --format must be auto, flexarm-csv, table or mat, not '" << *f << "'\n";
      return std::nullopt;
    }
  }
  if (!args.integer("input-column", o.inputColumn, 1, LogReadOptions::kMaxColumns) ||
      !args.integer("output-column", o.outputColumn, 1, LogReadOptions::kMaxColumns) ||
      !args.integer("time-column", o.timeColumn, 0, LogReadOptions::kMaxColumns) ||
      !args.number("sample-time", o.sampleTime)) {
    err << "flexarm: " << args.error() << "\n";
    return std::nullopt;
  }
  if (auto v = args.value("input-name")) o.inputName = *v;
  if (auto v = args.value("output-name")) o.outputName = *v;
  if (auto v = args.value("input-var")) o.inputVariable = *v;
  if (auto v = args.value("output-var")) o.outputVariable = *v;
  std::string why;
  if (!o.isValid(&why)) {
    err << "flexarm: " << why << "\n";
    return std::nullopt;
  }
  return o;
}

std::optional<IdData> loadLog(const std::string& path, const LogReadOptions& options,
                              std::ostream& err) {
  LogReadResult r = readLog(path, options);
  if (!r.ok) {
    err << "flexarm: " << r.error.toString() << "\n";
    return std::nullopt;
  }
  std::string why;
  if (!applyStoredRanges(r.data, &why)) {
    err << "flexarm: " << path << ": " << why << "\n";
    return std::nullopt;
  }
  return std::move(r.data);
}

bool parseTimeRange(const std::string& text, const IdData& data, SampleRange& range,
                    std::string* why) {
  double t0 = 0, t1 = 0;
  if (!parseSecondsRange(text, t0, t1)) {
    if (why) *why = "a range is written A:B in seconds, e.g. 2.5:10, not '" + text + "'";
    return false;
  }
  range = data.rangeForTimes(t0, t1);
  if (range.empty()) {
    if (why) *why = "the range " + text + " s holds no samples of the log";
    return false;
  }
  return true;
}

}  // namespace flexarm::cli
