// libFuzzer target: the FlexArm CSV log reader on arbitrary bytes. It must return a log or a
// ReadError with a sentence; never crash, hang or read out of bounds.
#include <cstdint>
#include <string>
#include <string_view>

#include "core/io/log_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const flexarm::LogReadResult r = flexarm::readFlexArmCsvText(text, "fuzz.csv");
  if (!r.ok && r.error.problem.empty()) __builtin_trap();  // a refusal always says why
  if (r.ok && !r.data.isValid()) __builtin_trap();         // what is accepted is valid
  return 0;
}
