// libFuzzer target: the walk of v7.3 (HDF5) .mat files (core/io/hdf5_check.h) on arbitrary
// bytes, then, for what it lets through with a v7.3 header, the whole .mat reader with matio
// and HDF5 behind it. The walk must refuse with a sentence or let through only a file HDF5
// reads without leaving it, hanging or exhausting memory.
#include <cstdint>
#include <string_view>

#include "core/io/hdf5_check.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  flexarm::Hdf5Limits limits;
  limits.inflateBudget = 64u << 20;
  const flexarm::Hdf5Check check = flexarm::checkHdf5File(bytes, limits);
  if (!check.ok) {
    if (check.problem.empty()) __builtin_trap();  // a refusal always says why
    return 0;
  }
  if (size >= 128 && bytes[124] == 0 && bytes[125] == 2)  // the MATLAB v7.3 header
    flexarm::fuzz::readAsMatFile(data, size, "fuzz73");
  return 0;
}
