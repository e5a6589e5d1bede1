// libFuzzer target: the .mat reader. The structure check runs on the bytes in memory; what it
// lets through is written to a file (matio reads only files) and read as a log.
#include <cstdint>
#include <string_view>

#include "core/io/log_source.h"
#include "core/io/mat_check.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const flexarm::MatCheck check = flexarm::checkMatFile(bytes, 1032ull * size + 65536);
  if (!check.ok) {
    if (check.problem.empty()) __builtin_trap();
    return 0;
  }
  const std::string& path = flexarm::fuzz::readAsMatFile(data, size, "fuzz");
  // The import dialog's listing walks every struct field and cell; the first numeric entry
  // it lists is read by its expression (a row of a matrix).
  flexarm::LogReadOptions o;
  o.format = flexarm::LogFormat::Mat;
  const flexarm::SourceListing listing = flexarm::listLogSource(path, o);
  if (!listing.ok && listing.error.problem.empty()) __builtin_trap();
  for (const auto& e : listing.entries)
    if (e.numeric) {
      const std::string expression = e.rows > 1 && e.cols > 1 ? e.expression + "(end,:)" : e.expression;
      const flexarm::SeriesRead s = flexarm::readSourceSeries(path, listing, expression, o);
      if (!s.ok && s.error.problem.empty()) __builtin_trap();
      break;
    }
  return 0;
}
