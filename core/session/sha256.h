#pragma once
// SHA-256 (FIPS 180-4) of files and strings: the checksum a session keeps of every log so
// that a report names exactly which data produced its numbers.
#include <optional>
#include <string>
#include <string_view>

namespace flexarm {

// Lower-case hexadecimal SHA-256 digest of bytes.
std::string sha256Hex(std::string_view bytes);

// Digest of a file's contents; nullopt (with why) when it cannot be read.
std::optional<std::string> sha256OfFile(const std::string& path, std::string* why);

}  // namespace flexarm
