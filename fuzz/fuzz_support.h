#pragma once
// What the .mat fuzz targets share: bytes the structure check let through are written to a
// scratch file (matio reads only files) and read as a log, which must succeed or say why.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/io/log_io.h"

namespace flexarm::fuzz {

inline void readAsMatFile(const std::uint8_t* data, std::size_t size, const char* tag) {
  const char* dir = std::getenv("FLEXARM_FUZZ_TMP");
  static const std::string path =
      std::string(dir ? dir : "/tmp") + "/flexarm_" + tag + "_" + std::to_string(::getpid()) + ".mat";
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  LogReadOptions o;
  o.format = LogFormat::Mat;
  const LogReadResult r = readLog(path, o);
  if (!r.ok && r.error.problem.empty()) __builtin_trap();  // a refusal always says why
}

}  // namespace flexarm::fuzz
