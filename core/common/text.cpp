#include "core/common/text.h"

#include <cstdio>

namespace flexarm {

std::string inQuotes(std::string_view value, std::size_t most) {
  std::string out = "'";
  for (char c : value.substr(0, most)) out += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  if (value.size() <= most) return out + "'";
  return out + "...' (" + std::to_string(value.size()) + " characters)";
}

bool hasControlCharacter(std::string_view text) {
  for (unsigned char c : text)
    if (c < 0x20 || c == 0x7f) return true;
  return false;
}

std::string shortNumber(double value, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  return buf;
}

}  // namespace flexarm
