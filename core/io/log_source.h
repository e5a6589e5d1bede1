#pragma once
// What a log file offers for import, for the import dialog: the variables of a .mat file (a
// tree of structs, struct arrays and cells, each with its shape and class), the columns of a
// CSV file with a header or of a headerless table; and one signal read by the name a mapping
// uses for it (a MATLAB expression, a header name, "column N"), for a preview.
#include <cstdint>
#include <string>
#include <vector>

#include "core/io/log_io.h"

namespace flexarm {

struct SourceEntry {
  std::string label;       // "act_torque_abs_nm", "rec", "(2)", "{3}", "t_s", "column 3"
  std::string expression;  // what the mapping takes: "rec.act_torque_abs_nm", "t_s", "column 3"
  std::string shape;       // "6 x 2501"
  std::string kind;        // MATLAB's class ("double", "struct", "cell", "object"), or "number"
  std::string unreadable;  // why FlexArm skips it; empty when it reads it
  bool numeric = false;    // real numbers: a vector, or a matrix to take a row or column of
  std::uint64_t rows = 0, cols = 0;  // of a numeric array (more dimensions: rows x the rest)
  std::vector<SourceEntry> children;
};

struct SourceListing {
  bool ok = false;
  ReadError error;
  LogFormat format = LogFormat::Auto;  // Mat, FlexArmCsv (a file with a header) or Table
  std::vector<SourceEntry> entries;
  std::vector<std::string> notes;      // what was skipped, and why
  // A text file's columns, one per entry in order, as read (previews come from here).
  std::vector<std::vector<double>> columns;
};

// Lists what path holds. A .mat file is described without reading its numbers; a text file is
// read whole (within options.maxFileBytes), so that previews need no second read.
SourceListing listLogSource(const std::string& path, const LogReadOptions& options = {});

struct SeriesRead {
  bool ok = false;
  std::vector<double> values;
  ReadError error;  // names the file and the expression
};

// The signal `name` names: a column of a text file's listing, or a .mat expression read from
// the file (rec.act_pos_mot_deg(2,:)).
SeriesRead readSourceSeries(const std::string& path, const SourceListing& listing,
                            const std::string& name, const LogReadOptions& options = {});

namespace io {
// The .mat parts of the two (mat_reader.cpp).
SourceListing listMatSource(const std::string& path, const LogReadOptions& options);
SeriesRead readMatExpression(const std::string& path, const std::string& expression,
                             const LogReadOptions& options);
}  // namespace io

}  // namespace flexarm
