// libFuzzer target: the .mat reader. The structure check runs on the bytes in memory; what it
// lets through is written to a file (matio reads only files) and read as a log.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include "core/io/log_io.h"
#include "core/io/log_source.h"
#include "core/io/mat_check.h"

namespace {
std::string scratchFile() {
  const char* dir = std::getenv("FLEXARM_FUZZ_TMP");
  return std::string(dir ? dir : "/tmp") + "/flexarm_fuzz_" + std::to_string(::getpid()) + ".mat";
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const flexarm::MatCheck check = flexarm::checkMatFile(bytes, 1032ull * size + 65536);
  if (!check.ok) {
    if (check.problem.empty()) __builtin_trap();
    return 0;
  }
  static const std::string path = scratchFile();
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  flexarm::LogReadOptions o;
  o.format = flexarm::LogFormat::Mat;
  const flexarm::LogReadResult r = flexarm::readLog(path, o);
  if (!r.ok && r.error.problem.empty()) __builtin_trap();
  // The import dialog's listing walks every struct field and cell; the first numeric entry
  // it lists is read by its expression (a row of a matrix).
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
