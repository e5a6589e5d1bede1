#pragma once
// Structure check of an HDF5-based MATLAB v7.3 .mat file, walked by FlexArm itself before the
// HDF5 library (through matio) opens anything. HDF5 follows what a file says: a dataset whose
// data live in an external file reads any file on the machine, an external link or a soft
// link opens another file or path, a hard link back to a parent group recurses without end,
// a filter number names a plug-in library to load, and a compressed chunk inflates to
// whatever its header claims. The walk reads the superblock, every object header reachable
// from the root group (through symbol tables, link messages and object references), their
// dataspaces, datatypes, layouts, filter pipelines and attributes, and the chunk indexes of
// chunked datasets, and lets the file through only when
//   - every address and size lies inside the file itself: no external storage, no external,
//     soft or user-defined links, no file driver that spreads it over other files, no virtual
//     dataset and no shared or committed message pointing elsewhere;
//   - the groups form a tree of bounded depth and size: a link cycle is named, and so are
//     more variables, objects or nesting levels than a log can have;
//   - the only filters are deflate, shuffle and Fletcher-32 (HDF5's built-ins), and the bytes
//     every dataset and chunk would take, inflated, fit a budget derived from the file's
//     size, checked before anything is decompressed.
// Variables FlexArm cannot read (structs, cells, objects, strings) are listed so that the
// reader can skip them with a note.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

struct Hdf5Limits {
  int maxDepth = 16;            // groups inside groups (a MATLAB struct is a group)
  int maxVariables = 1000;      // links in the root group
  int maxObjects = 100000;      // objects reached, counted along every path (a shared object
                                // twice), so that a reader walking the tree stays bounded too
  std::uint64_t maxChunks = 1u << 20;   // chunks of all datasets together
  std::uint64_t inflateBudget = 0;      // bytes all datasets may take uncompressed, together
  double maxCompressionRatio = 1032.0;  // of one compressed chunk (deflate's own bound)
};

// A root-group variable as the walk found it.
struct Hdf5Variable {
  std::string name;
  std::string matlabClass;  // its MATLAB_class attribute ("double", "struct", ...); may be empty
  bool dataset = false;     // false: a group (a MATLAB struct or object)
  std::vector<std::uint64_t> dims;  // of a dataset, as HDF5 stores them
  bool numeric = false;     // a real numeric array FlexArm can read
};

struct Hdf5Check {
  bool ok = false;
  std::string problem;  // a sentence naming the object (its path in the file) when !ok
  std::vector<Hdf5Variable> variables;
  std::uint64_t inflatedBytes = 0;  // what every dataset would take uncompressed
};

// Brings the file's bytes [offset, offset + n) into the memory `bytes` views; false when they
// cannot be read (see MatLoad in mat_check.h).
using Hdf5Load = std::function<bool(std::uint64_t offset, std::uint64_t n)>;

// Walks the HDF5 file held (or, with load, loaded part by part) in bytes; the MATLAB header's
// 512-byte user block may precede the superblock.
Hdf5Check checkHdf5File(std::string_view bytes, const Hdf5Limits& limits, const Hdf5Load& load = {});

}  // namespace flexarm
