// libFuzzer target: the headerless table reader on arbitrary bytes, with and without a time
// column (the first byte picks the column mapping).
#include <cstdint>
#include <string>
#include <string_view>

#include "core/io/log_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  flexarm::LogReadOptions o;
  if (size > 0) {
    o.timeColumn = data[0] % 3;  // 0: none, 1 or 2
    o.inputColumn = o.timeColumn == 1 ? 2 : 1;
    o.outputColumn = o.timeColumn == 2 || o.timeColumn == 1 ? 3 : 2;
    ++data;
    --size;
  }
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const flexarm::LogReadResult r = flexarm::readTableText(text, "fuzz.dat", o);
  if (!r.ok && r.error.problem.empty()) __builtin_trap();
  if (r.ok && !r.data.isValid()) __builtin_trap();
  return 0;
}
