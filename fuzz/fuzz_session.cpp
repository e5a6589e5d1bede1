// libFuzzer target: a session file's JSON, parsed and validated with every part.
#include <cstdint>
#include <string>

#include "core/session/session.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const flexarm::SessionParseResult r = flexarm::parseSession(text);
  if (!r.ok && r.message.empty()) __builtin_trap();
  if (r.ok) (void)flexarm::toJsonText(r.session);  // what is accepted can be written back
  return 0;
}
