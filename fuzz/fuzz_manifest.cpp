// libFuzzer target: the fleet manifest reader on arbitrary bytes. A refusal names its problem,
// an accepted manifest is consistent (every entry in one axis, each axis' reference one of its
// entries, every log inside the manifest's folder), and it writes back to text that reads to
// the same entries.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/fleet/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  flexarm::ManifestError e;
  flexarm::ManifestReadOptions o;
  o.maxRows = 2000;
  const auto m = flexarm::parseFleetManifest(text, "/fuzz/plant/fleet.csv", &e, o);
  if (!m) {
    if (e.problem.empty() || e.toString().size() > 1000) __builtin_trap();
    return 0;
  }
  std::size_t entries = 0;
  for (const auto& a : m->axes) {
    entries += a.entries.size();
    if (a.referenceEntry >= m->entries.size()) __builtin_trap();
  }
  if (entries != m->entries.size()) __builtin_trap();
  for (const auto& x : m->entries)
    if (std::filesystem::weakly_canonical(x.path).string().rfind("/fuzz/plant/", 0) != 0) __builtin_trap();
  const auto again = flexarm::parseFleetManifest(flexarm::fleetManifestText(m->entries), "/fuzz/plant/fleet.csv", &e, o);
  if (!again || again->entries.size() != m->entries.size()) __builtin_trap();
  return 0;
}
