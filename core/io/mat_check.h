#pragma once
// Structure check of a MATLAB .mat file before matio reads it. matio believes the sizes a
// file states (a 48 KB file claiming 2^31 - 1 elements or a 2 GB variable name made it
// allocate that much), so every size is first checked against the bytes that hold it: an
// element may not reach past its parent or the end of the file, the elements of an array must
// fit its data, a compressed variable may not inflate beyond a budget derived from the file's
// size, and only what FlexArm can use is let through (numeric, logical, char, cell and struct
// arrays; sparse matrices and objects are refused by name).
#include <cstdint>
#include <string>
#include <string_view>

namespace flexarm {

enum class MatKind { Unknown, V4, V5, V73 };

struct MatCheck {
  bool ok = false;
  MatKind kind = MatKind::Unknown;
  std::string problem;  // a sentence when !ok
};

// Checks the bytes of a whole .mat file (level 4, level 5 / v7, or the HDF5-based v7.3 whose
// variables are bounded later from their dimensions). inflateBudget bounds the bytes the
// compressed variables of a v7 file may inflate to, all together.
MatCheck checkMatFile(std::string_view bytes, std::uint64_t inflateBudget);

}  // namespace flexarm
