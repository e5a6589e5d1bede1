// libFuzzer target: the .mat reader. The structure check runs on the bytes in memory; what it
// lets through is written to a file (matio reads only files) and read as a log.
#include <cstdint>
#include <string_view>

#include "core/io/mat_check.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const flexarm::MatCheck check = flexarm::checkMatFile(bytes, 1032ull * size + 65536);
  if (!check.ok) {
    if (check.problem.empty()) __builtin_trap();
    return 0;
  }
  flexarm::fuzz::readAsMatFile(data, size, "fuzz");
  return 0;
}
