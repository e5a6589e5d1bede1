#include "app/cli/log_args.h"

#include <charconv>
#include <cmath>
#include <ostream>

#include "core/common/text.h"
#include "core/io/ranges.h"

namespace flexarm::cli {

std::vector<Option> logReadOptionList() {
  const long columns = LogReadOptions::kMaxColumns;
  return {
      textOption("format", "auto|flexarm-csv|table|mat", "how to read LOG (auto: by content)"),
      integerOption("input-column", "N", 1, columns, "1", "headerless table: column of the input u"),
      integerOption("output-column", "N", 1, columns, "2", "headerless table: column of the output y"),
      integerOption("time-column", "N", 0, columns, "0", "headerless table: column of the time (0: none)"),
      numberOption("sample-time", "T", 0.0, 1e308, "", "seconds between samples when the file stores no time; a "
                                                      ".mat file without time_s (or a scalar Ts, dt) needs it, a "
                                                      "table without a time column takes 1 s and says so"),
      textOption("input-name", "NAME", "channel name for the input (default u; .mat: the variable's name, and a "
                                       "variable NAME is the input)"),
      textOption("output-name", "NAME", "channel name for the output (default y; .mat: the variable's name, and a "
                                        "variable NAME is the output)"),
      textOption("input-var", "EXPR", "the input: a .mat variable or MATLAB expression (rec.act_torque_abs_nm(1,:), "
                                      "data(:,2)), a CSV header name (torque_motor_Nm) or a table's 'column N'"),
      textOption("output-var", "EXPR", "the output, named the same ways"),
      textOption("time-var", "EXPR", "the time in s, named the same ways (rec.time_cont, t_s)"),
      textOption("arm-var", "EXPR", "the arm-side encoder, read as arm_angle_rad"),
      textOption("ref-var", "EXPR", "a closed loop's position reference, in the output's unit and side: "
                                    "angle_ref_rad (position_ref_m)"),
      textOption("output-unit", "U", "the output's unit: rad, deg, rev (rad/s, deg/s, rpm for a velocity) or, for a "
                                     "prismatic axis, m, mm (m/s, mm/s); converted, and named motor_angle_rad "
                                     "(motor_velocity_rad_s, motor_position_m, motor_velocity_m_s)"),
      textOption("arm-unit", "U", "the arm encoder's unit: rad, deg or rev"),
      choiceOption("output-side", {"motor", "arm"}, "", "arm when a motor encoder is stored scaled to the arm side "
                                                         "(motor angle = value / gear ratio)"),
      textOption("gear-ratio", "R", "arm/motor as the log's gear_ratio, e.g. 1/256.86"),
      numberOption("input-scale", "K", -1e308, 1e308, "", "the input times K is the torque in N m (force in N), "
                                                         "e.g. 35.15 for a drive command in V at 35.15 N/V"),
  };
}

std::vector<std::string> logReadOptionNames() {
  std::vector<std::string> names;
  for (const auto& o : logReadOptionList()) names.push_back(o.name);
  return names;
}

const char* logReadOptionsHelp() {
  static const std::string text = [] {
    OptionTable t("", "");
    t.group("Reading the log").add(logReadOptionList());
    return t.help();
  }();
  return text.c_str();
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
  LogMapping& m = o.mapping;
  if (auto v = args.value("input-var")) m.input = *v;
  if (auto v = args.value("output-var")) m.output = *v;
  if (auto v = args.value("time-var")) m.time = *v;
  if (auto v = args.value("arm-var")) m.arm = *v;
  if (auto v = args.value("ref-var")) m.reference = *v;
  for (const auto& [option, unit] : {std::pair<const char*, std::optional<SignalUnit>*>{"output-unit", &m.outputUnit},
                                     {"arm-unit", &m.armUnit}})
    if (auto v = args.value(option)) {
      *unit = signalUnitFromString(*v);
      if (!*unit) {
        err << "flexarm: --" << option << " must be rad, deg, rev, rad/s, deg/s, rpm, m, mm, m/s or mm/s, not '"
            << *v << "'\n";
        return std::nullopt;
      }
    }
  if (auto v = args.value("output-side")) {
    m.outputSide = encoderSideFromString(*v);
    if (!m.outputSide) {
      err << "flexarm: --output-side must be motor or arm, not '" << *v << "'\n";
      return std::nullopt;
    }
  }
  if (auto v = args.value("gear-ratio")) m.gearRatio = *v;
  if (!args.number("input-scale", m.inputScale)) {
    err << "flexarm: " << args.error() << "\n";
    return std::nullopt;
  }
  std::string why;
  if (!o.isValid(&why)) {
    err << "flexarm: " << why;
    if (const auto r = parseGearRatio(m.gearRatio, nullptr); r && *r > 1.0)
      err << "; give --gear-ratio " << invertedGearRatio(m.gearRatio);
    err << "\n";
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
  for (const auto& w : r.warnings) err << "flexarm: warning: " << path << ": " << w << "\n";
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
    if (why) *why = "a range is written A:B in seconds, e.g. 2.5:10, not " + inQuotes(text);
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
