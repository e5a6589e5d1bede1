// libFuzzer target: the fleet store on arbitrary bytes, and a Slurm task's log result on
// arbitrary JSON. The first byte picks which. A store file is opened read-only and every read
// is tried: it must be refused with a sentence or read without a crash, and every log it gives
// back as analysed must hold values FlexArm could have written. A task result is parsed and
// checked as the coordinator checks it before merging.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "core/fleet/store.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool storeFile = data[0] & 1;
  ++data;
  --size;
  if (!storeFile) {
    const auto j = nlohmann::json::parse(data, data + size, nullptr, false);
    if (j.is_discarded()) return 0;
    std::string why;
    const auto r = flexarm::fleetLogResultFromJson(j, &why);
    if (!r) {
      if (why.empty()) __builtin_trap();
      return 0;
    }
    (void)flexarm::isValidFleetLogResult(*r, &why);
    return 0;
  }
  const char* dir = std::getenv("FLEXARM_FUZZ_TMP");
  static const std::string path =
      std::string(dir ? dir : "/tmp") + "/flexarm_fuzz_store_" + std::to_string(::getpid()) + ".sqlite";
  for (const char* tail : {"-wal", "-shm"}) std::remove((path + tail).c_str());
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  std::string why;
  auto store = flexarm::FleetStore::open(path, false, &why);
  if (!store) {
    if (why.empty()) __builtin_trap();
    return 0;
  }
  (void)store->axes();
  (void)store->runs();
  (void)store->storedKeys();
  (void)store->logCount();
  for (const auto& l : store->logs())
    if (l.result.ok && !flexarm::isValidFleetLogResult(l.result, &why)) __builtin_trap();
  return 0;
}
