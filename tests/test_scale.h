#pragma once
// The slowest tests shrink their work under the sanitizers: scripts/sanitize.sh sets
// FLEXARM_TEST_REDUCED=1, the Release run keeps the full sizes. A reduced test still asserts
// the same facts, on fewer cases.
#include <cstdlib>
#include <cstring>

namespace flexarm::test {

inline bool reducedSizes() {
  const char* v = std::getenv("FLEXARM_TEST_REDUCED");
  return v && std::strcmp(v, "1") == 0;
}

}  // namespace flexarm::test
