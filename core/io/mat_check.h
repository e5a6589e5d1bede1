#pragma once
// Structure check of a MATLAB .mat file before matio reads it. matio believes the sizes a
// file states (a 48 KB file claiming 2^31 - 1 elements or a 2 GB variable name made it
// allocate that much), so every size is first checked against the bytes that hold it: an
// element may not reach past its parent or the end of the file, the elements of an array must
// fit its data, a compressed variable may not inflate beyond a budget derived from the file's
// size, and only what FlexArm can use is let through (numeric, logical, char, cell and struct
// arrays; sparse matrices and objects are refused by name).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class MatKind { Unknown, V4, V5, V73 };

// A top-level variable of a level-5 file as the check found it: its array class (MATLAB's
// numbering: 6 double, 7 single, 10 int16, 12 int32, ...; 1 cell, 2 struct, 4 char), its
// dimensions, and for a numeric array where its real part lies. The data were checked to hold
// at least the elements the dimensions claim.
struct MatVariable {
  std::string name;
  std::uint32_t arrayClass = 0;
  bool complex = false;
  std::vector<std::uint64_t> dims;
  std::uint32_t dataType = 0;           // the level-5 number type the data are stored in
  const unsigned char* data = nullptr;  // into the file's bytes, or into MatCheck::inflated
  std::uint64_t elements = 0;
};

struct MatCheck {
  bool ok = false;
  MatKind kind = MatKind::Unknown;
  std::string problem;  // a sentence when !ok
  // Level 5 only: the variables in file order, so that the reader decodes them from the
  // bytes just checked instead of reading the file again.
  bool swapBytes = false;  // the file was written in the other byte order
  std::vector<MatVariable> variables;
  std::vector<std::unique_ptr<unsigned char[]>> inflated;  // bodies of compressed variables
  // v7.3: variables the walk found but FlexArm cannot read (structs, cells, objects), named
  // with their MATLAB class, for the reader's note.
  std::vector<std::string> skipped;
};

// Bytes per element of a level-5 data type; 0 when the type holds no numbers.
std::uint64_t matTypeSize(std::uint32_t type);

// Brings the file's bytes [offset, offset + n) into the same place of the memory the check
// walks; false when they cannot be read.
using MatLoad = std::function<bool(std::uint64_t offset, std::uint64_t n)>;

// Checks the bytes of a whole .mat file (level 4, level 5 / v7, or the HDF5-based v7.3, walked
// by checkHdf5File in core/io/hdf5_check.h before HDF5 opens it). inflateBudget bounds the bytes the
// compressed variables of a v7 file may inflate to, all together. For a level-5 file the
// result lists its variables, pointing into `bytes` (which must outlive their use).
// With load, `bytes` is memory of the file's size that holds only what load brought in: the
// check loads every byte it reads first, and leaves a level-5 file's numeric data (nearly all
// of a log) to the reader, which can then read them straight to where they go.
MatCheck checkMatFile(std::string_view bytes, std::uint64_t inflateBudget, const MatLoad& load = {});

}  // namespace flexarm
