#pragma once
// Text for messages. A message quotes what the user gave so that they see what was read, but
// never a whole file or a megabyte of command line: at most `most` characters, control
// characters (a line break that would forge a second line) shown as '?'.
#include <cstddef>
#include <string>
#include <string_view>

namespace flexarm {

// 'value', or 'first 100 characters...' (123456 characters).
std::string inQuotes(std::string_view value, std::size_t most = 100);

// Whether the text holds a control character (a line break, a tab, DEL): such text cannot be
// a path or a name written into a script, a manifest or a message line.
bool hasControlCharacter(std::string_view text);

// A number in a sentence: %g with `digits` significant digits ("0.0355", "1.5e+05", "nan").
std::string shortNumber(double value, int digits = 3);

}  // namespace flexarm
