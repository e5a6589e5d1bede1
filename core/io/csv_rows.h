#pragma once
// The data rows of a FlexArm CSV log, after its header line: a large file is cut into a few
// stretches at line ends and each is read by its own thread. Internal to core/io.
#include <string>
#include <vector>

#include "core/io/text_lines.h"

namespace flexarm::textio {

struct CsvRows {
  std::vector<std::vector<double>> columns;  // one per header column, in the header's order
  std::vector<int> lines;                    // the file's line number of each row
  // The first bad row, when there is one: its line, the field (1-based; 0 when the problem is
  // the whole line) and the problem as a sentence.
  bool holes = false;  // an empty field was read as a hole (NaN)
  bool ok = true;
  int errorLine = 0;
  int errorColumn = 0;
  std::string problem;
};

// Reads every row after the header from `reader`, which is open on `path` and has just
// returned the header line. Blank lines and '#' comments are skipped; a row must hold
// `columns` finite numbers. The rows, their values and the first bad row are the same
// whatever the number of threads: `threads` stretches when given, otherwise one per 8 MB of
// rows, up to the processor's cores (at most 4). With `holesExcept` >= 0 an empty field of any
// column but that one is a hole, NaN, instead of an error.
CsvRows readCsvRows(const std::string& path, LineReader& reader, std::size_t columns,
                    unsigned threads = 0, int holesExcept = -1);

}  // namespace flexarm::textio
