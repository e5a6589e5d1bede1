// The walk of an HDF5 file described in hdf5_check.h, after the HDF5 file format
// specification (version 3.0): superblock versions 0-3, object header versions 1 and 2, groups
// as symbol tables (B-tree version 1 and local heap) or link messages, data layout versions
// 1-4, filter pipelines, attributes and the global heap behind variable-length attributes.
// Everything else a file could use (dense storage in fractal heaps, chunk indexes other than
// the version-1 B-tree, a single chunk or an implicit index) is refused by name: MATLAB does not
// write it.
#include "core/common/text.h"
#include "core/io/hdf5_check.h"

#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <utility>

namespace flexarm {
namespace {

using Byte = unsigned char;
constexpr std::uint64_t kUndefined = ~0ull;
constexpr int kMaxBtreeLevel = 64;
constexpr std::uint64_t kMaxMessages = 65536;   // of one object header, all chunks together
constexpr std::uint64_t kMaxNameBytes = 65536;  // of one link or attribute name
constexpr std::uint64_t kMaxReferenceBytes = 64u << 20;  // object references read and followed
constexpr int kMaxTypeNesting = 8;

struct Refused {
  std::string problem;
};

[[noreturn]] void refuse(std::string problem) { throw Refused{std::move(problem)}; }

std::string human(std::uint64_t n) {
  char buf[40];
  if (n >= (1ull << 30)) std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(n) / (1ull << 30));
  else if (n >= (1ull << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(n) / (1ull << 20));
  else std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(n));
  return buf;
}

std::uint64_t saturatingProduct(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > kUndefined / a) return kUndefined;
  return a * b;
}

// Little-endian fields of a structure of known length; running past its end is refused.
class Cursor {
 public:
  Cursor(const Byte* p, std::uint64_t n, std::string what) : p_(p), left_(n), what_(std::move(what)) {}
  std::uint64_t left() const { return left_; }
  const Byte* here() const { return p_; }
  const Byte* take(std::uint64_t n) {
    if (n > left_) refuse(what_ + " is cut short (the file is damaged)");
    const Byte* at = p_;
    p_ += n;
    left_ -= n;
    return at;
  }
  void skip(std::uint64_t n) { take(n); }
  std::uint64_t uint(int bytes) {
    const Byte* b = take(static_cast<std::uint64_t>(bytes));
    std::uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = v << 8 | b[i];
    return v;
  }
  unsigned u8() { return static_cast<unsigned>(uint(1)); }
  unsigned u16() { return static_cast<unsigned>(uint(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(uint(4)); }
  Cursor sub(std::uint64_t n, const std::string& what) { return Cursor(take(n), n, what); }

 private:
  const Byte* p_;
  std::uint64_t left_;
  std::string what_;
};

struct Link {
  std::string name;
  std::uint64_t address = kUndefined;
};

struct Type {
  unsigned cls = 0;
  std::uint64_t size = 0;
  bool vlen = false;       // holds variable-length data somewhere
  bool topVlen = false;    // is itself a variable-length sequence or string
  std::uint64_t vlenBaseSize = 1;
  bool objectReference = false;
};

struct Layout {
  int cls = -1;  // 0 compact, 1 contiguous, 2 chunked
  std::uint64_t address = kUndefined, size = 0;
  const Byte* compact = nullptr;
  std::vector<std::uint64_t> chunk;  // chunk dimensions, the element size last (versions 1-3)
  int index = 0;                     // version 4: 1 single chunk, 2 implicit; 0: B-tree version 1
  std::uint64_t filteredSize = 0;    // version 4 single filtered chunk
};

struct Object {
  bool group = false, dataset = false;
  std::vector<Link> links;
  bool hasSpace = false, hasType = false;
  std::vector<std::uint64_t> dims;
  std::uint64_t elements = 1;
  Type type;
  Layout layout;
  std::vector<unsigned> filters;  // ids in pipeline order
  std::vector<unsigned> shuffleSizes;
  std::string matlabClass;
  bool sparse = false;
  std::vector<std::uint64_t> references;  // objects the data refer to
};

class Walker {
 public:
  Walker(std::string_view bytes, const Hdf5Limits& limits, const Hdf5Load& load)
      : file_(reinterpret_cast<const Byte*>(bytes.data())), size_(bytes.size()), limits_(limits), load_(load) {}

  void run(Hdf5Check& out) {
    superblock();
    std::vector<std::uint64_t> stack;
    visit(root_, "/", 0, stack);
    const Object& root = objects_.at(root_);
    if (!root.group) refuse("the root object is not a group (the file is damaged)");
    if (root.links.size() > static_cast<std::size_t>(limits_.maxVariables))
      refuse("the file holds " + std::to_string(root.links.size()) + " variables, more than the " +
             std::to_string(limits_.maxVariables) + " FlexArm reads from one file");
    for (const Link& l : root.links) {
      if (l.name == "#refs#" || l.name == "#subsystem#") continue;
      const Object& o = objects_.at(l.address);
      Hdf5Variable v;
      v.name = l.name;
      v.matlabClass = o.matlabClass;
      v.dataset = o.dataset;
      v.dims = o.dims;
      static const std::set<std::string> numeric = {"double", "single", "int8",  "uint8",  "int16", "uint16",
                                                    "int32",  "uint32", "int64", "uint64", "logical"};
      v.numeric = o.dataset && (o.type.cls == 0 || o.type.cls == 1) && !o.sparse &&
                  (o.matlabClass.empty() || numeric.count(o.matlabClass) > 0);
      out.variables.push_back(std::move(v));
    }
    out.inflatedBytes = inflated_;
  }

 private:
  // The file's bytes [offset, offset + n): inside the file, loaded.
  const Byte* at(std::uint64_t offset, std::uint64_t n, const std::string& what) {
    if (offset > size_ || n > size_ - offset)
      refuse(what + " lies outside the file (at byte " + std::to_string(offset) + ", " + std::to_string(n) +
             " bytes, in a file of " + std::to_string(size_) + "): the file is damaged or points elsewhere");
    if (load_ && n > 0 && !load_(offset, n)) refuse("the file cannot be read");
    return file_ + offset;
  }
  // A file address (relative to the base address) as an offset into the file.
  std::uint64_t absolute(std::uint64_t address, const std::string& what) {
    if (address == kUndefined || address > size_ || base_ > size_ - address)
      refuse(what + " points outside the file (the file is damaged or points elsewhere)");
    return base_ + address;
  }
  const Byte* atAddress(std::uint64_t address, std::uint64_t n, const std::string& what) {
    return at(absolute(address, what), n, what);
  }
  std::uint64_t offsetField(Cursor& c) { return c.uint(so_); }
  std::uint64_t lengthField(Cursor& c) { return c.uint(sl_); }
  // An address read with the size of offsets: all ones is "undefined".
  static std::uint64_t normalized(std::uint64_t a, int bytes) {
    return bytes < 8 && a == (1ull << (8 * bytes)) - 1 ? kUndefined : a;
  }
  std::uint64_t address(Cursor& c) { return normalized(offsetField(c), so_); }

  void superblock() {
    static const Byte signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    std::uint64_t at0 = kUndefined;
    for (std::uint64_t o = 0; o + 8 <= size_; o = o == 0 ? 512 : 2 * o)
      if (std::memcmp(at(o, 8, "the superblock"), signature, 8) == 0) {
        at0 = o;
        break;
      }
    if (at0 == kUndefined) refuse("not an HDF5 file: a MATLAB v7.3 file holds an HDF5 file after its header");
    Cursor c(at(at0, std::min<std::uint64_t>(size_ - at0, 256), "the superblock"),
             std::min<std::uint64_t>(size_ - at0, 256), "the superblock");
    c.skip(8);
    const unsigned version = c.u8();
    if (version > 3) refuse("the HDF5 superblock has version " + std::to_string(version) + ", newer than FlexArm checks");
    if (version <= 1) {
      c.skip(4);  // free-space, root group and shared header versions, reserved
      so_ = static_cast<int>(c.u8());
      sl_ = static_cast<int>(c.u8());
      checkSizes();
      c.skip(1);
      c.skip(4);  // B-tree K values
      c.skip(4);  // consistency flags
      if (version == 1) c.skip(4);  // indexed storage K, reserved
      base_ = offsetField(c);
      c.skip(static_cast<std::uint64_t>(so_));  // free space info
      c.skip(static_cast<std::uint64_t>(so_));  // end of file
      const std::uint64_t driver = address(c);
      if (driver != kUndefined)
        refuse("the file names a file driver (its driver information block): such a file spreads over "
               "other files, which FlexArm does not open");
      // The root group's symbol table entry.
      c.skip(static_cast<std::uint64_t>(so_));  // link name offset
      root_ = address(c);
    } else {
      so_ = static_cast<int>(c.u8());
      sl_ = static_cast<int>(c.u8());
      checkSizes();
      c.skip(1);  // flags
      base_ = offsetField(c);
      const std::uint64_t extension = address(c);
      c.skip(static_cast<std::uint64_t>(so_));  // end of file
      root_ = address(c);
      if (extension != kUndefined) {
        Object ext;
        parseHeader(extension, ext, "the superblock extension");
      }
    }
    // HDF5 takes addresses from where it found the superblock, whatever the base address says.
    base_ = at0;
    if (root_ == kUndefined) refuse("the file has no root group (it is damaged)");
  }

  void checkSizes() {
    for (int s : {so_, sl_})
      if (s != 2 && s != 4 && s != 8) refuse("the HDF5 superblock states a field size of " + std::to_string(s) + " bytes");
  }

  // Walks the object at address and everything its links and references reach. Every arrival
  // counts (a shared object once per path to it), so a reader that walks the tree the same way
  // stays within the limits too.
  void visit(std::uint64_t address, const std::string& path, int depth, std::vector<std::uint64_t>& stack) {
    if (++visits_ > static_cast<std::uint64_t>(limits_.maxObjects))
      refuse("the file's links reach more than " + std::to_string(limits_.maxObjects) +
             " objects (counted along every path), more than a log holds");
    if (depth > limits_.maxDepth)
      refuse(path + " is nested " + std::to_string(depth) + " levels deep, more than the " +
             std::to_string(limits_.maxDepth) + " FlexArm follows");
    if (std::find(stack.begin(), stack.end(), address) != stack.end())
      refuse("a link cycle: " + path + " leads back to an object on its own path, so reading it would never end");
    auto it = objects_.find(address);
    if (it == objects_.end()) {
      Object parsed;
      parseHeader(address, parsed, path);
      if (parsed.dataset) finishDataset(parsed, path);
      it = objects_.emplace(address, std::move(parsed)).first;
    }
    stack.push_back(address);
    // A std::map keeps its elements in place while children are added.
    const std::vector<Link>& links = it->second.links;
    const std::vector<std::uint64_t>& references = it->second.references;
    for (const Link& l : links) visit(l.address, (path == "/" ? "/" : path + "/") + l.name, depth + 1, stack);
    for (std::size_t k = 0; k < references.size(); ++k)
      visit(references[k], path + " (reference " + std::to_string(k + 1) + ")", depth + 1, stack);
    stack.pop_back();
  }

  // --- object headers -------------------------------------------------------------------------

  void parseHeader(std::uint64_t address, Object& o, const std::string& path) {
    const std::string what = "the object header of " + path;
    const std::uint64_t start = absolute(address, what);
    const Byte* p = at(start, std::min<std::uint64_t>(16, size_ - std::min(size_, start)), what);
    if (size_ - start < 16) refuse(what + " is cut short (the file is damaged)");
    std::vector<std::pair<std::uint64_t, std::uint64_t>> chunks;  // absolute offset, length
    bool v2 = false;
    if (std::memcmp(p, "OHDR", 4) == 0) {
      v2 = true;
      Cursor c(at(start, std::min<std::uint64_t>(size_ - start, 40), what), std::min<std::uint64_t>(size_ - start, 40), what);
      c.skip(4);
      if (c.u8() != 2) refuse(what + " has an unknown version");
      const unsigned flags = c.u8();
      if (flags & 0x20) c.skip(16);
      if (flags & 0x10) c.skip(4);
      const std::uint64_t length = c.uint(1 << (flags & 3));
      v2Order_ = (flags & 0x04) != 0;
      const std::uint64_t first = start + static_cast<std::uint64_t>(c.here() - p);
      chunks.emplace_back(first, length);
    } else {
      if (p[0] != 1) refuse(what + " is not an object header (the file is damaged, or a link points into data)");
      Cursor c(p, 16, what);
      c.skip(4);
      c.skip(4);  // reference count
      const std::uint64_t length = c.u32();
      chunks.emplace_back(start + 16, length);
    }
    std::set<std::uint64_t> seenChunks;
    std::uint64_t messages = 0;
    for (std::size_t k = 0; k < chunks.size(); ++k) {
      const auto [offset, length] = chunks[k];
      if (!seenChunks.insert(offset).second) refuse(what + " continues into itself (a cycle of continuation blocks)");
      if (chunks.size() > 4096) refuse(what + " has more than 4096 continuation blocks");
      Cursor c(at(offset, length, what), length, what);
      const bool blockV2 = v2;
      if (k > 0 && v2) {  // a continuation block: its signature, messages and checksum
        if (length < 8 || std::memcmp(c.here(), "OCHK", 4) != 0) refuse(what + " has a damaged continuation block");
        c = Cursor(c.here() + 4, length - 8, what);
      }
      while (c.left() >= (blockV2 ? 4u : 8u)) {
        unsigned type, flags;
        std::uint64_t n;
        if (blockV2) {
          type = c.u8();
          n = c.u16();
          flags = c.u8();
          if (v2Order_) {
            if (c.left() < 2) break;
            c.skip(2);
          }
        } else {
          type = c.u16();
          n = c.u16();
          flags = c.u8();
          c.skip(3);
        }
        if (++messages > kMaxMessages) refuse(what + " holds more than " + std::to_string(kMaxMessages) + " messages");
        Cursor body = c.sub(n, what);
        if ((flags & 0x02) && type != 0) refuse(what + " holds a shared message (kept in another object), which FlexArm does not follow");
        message(type, body, o, path, chunks);
      }
    }
    if (o.hasSpace && o.hasType && o.layout.cls >= 0) o.dataset = true;
    else if (o.hasSpace || o.layout.cls >= 0) refuse(path + " is a dataset without its dataspace, datatype or layout (the file is damaged)");
  }

  void message(unsigned type, Cursor& c, Object& o, const std::string& path,
               std::vector<std::pair<std::uint64_t, std::uint64_t>>& chunks) {
    switch (type) {
      case 0x01: dataspace(c, o.dims, o.elements, path); o.hasSpace = true; return;
      case 0x02: linkInfo(c, o, path); return;
      case 0x03: o.type = datatype(c, path, 0); o.hasType = true; return;
      case 0x06: link(c, o, path); return;
      case 0x07:
        refuse(path + " keeps its data in another file (HDF5 external storage); FlexArm reads only the file "
                      "it was given");
      case 0x08: layout(c, o.layout, path); return;
      case 0x0B: filters(c, o, path); return;
      case 0x0C: attribute(c, o, path); return;
      case 0x0F: refuse("the file keeps messages in a shared message table, which FlexArm does not follow");
      case 0x10: {
        const std::uint64_t a = address(c);
        const std::uint64_t n = lengthField(c);
        chunks.emplace_back(absolute(a, "a continuation of " + path), n);
        return;
      }
      case 0x11: symbolTable(c, o, path); return;
      case 0x14:
        refuse("the file names a file driver (its driver information message): such a file spreads over "
               "other files, which FlexArm does not open");
      case 0x15: {
        const unsigned version = c.u8();
        const unsigned flags = c.u8();
        if (version != 0) refuse(path + " has an attribute information message of unknown version");
        if (flags & 1) c.skip(2);
        if (address(c) != kUndefined)
          refuse(path + " keeps its attributes in a fractal heap (dense storage), which FlexArm does not check");
        return;
      }
      default: return;  // NIL, fill values, times, comments, reference counts, group info
    }
  }

  void dataspace(Cursor& c, std::vector<std::uint64_t>& dims, std::uint64_t& elements, const std::string& path) {
    const unsigned version = c.u8();
    const unsigned rank = c.u8();
    const unsigned flags = c.u8();
    unsigned kind = rank == 0 ? 0 : 1;
    if (version == 1) {
      c.skip(5);
    } else if (version == 2) {
      kind = c.u8();
    } else {
      refuse(path + " has a dataspace of unknown version " + std::to_string(version));
    }
    if (rank > 32) refuse(path + " has " + std::to_string(rank) + " dimensions, more than HDF5 allows (32)");
    dims.clear();
    elements = kind == 2 ? 0 : 1;
    for (unsigned d = 0; d < rank; ++d) {
      dims.push_back(lengthField(c));
      elements = saturatingProduct(elements, dims.back());
    }
    if (flags & 1) c.skip(static_cast<std::uint64_t>(rank) * static_cast<std::uint64_t>(sl_));
  }

  Type datatype(Cursor& c, const std::string& path, int nesting) {
    if (nesting > kMaxTypeNesting) refuse(path + " has a datatype nested more than " + std::to_string(kMaxTypeNesting) + " deep");
    Type t;
    const unsigned head = c.u8();
    t.cls = head & 15;
    const unsigned version = head >> 4;
    const Byte* bits = c.take(3);
    t.size = c.u32();
    const std::string what = path + "'s datatype";
    switch (t.cls) {
      case 0: c.skip(4); break;                       // fixed point
      case 1: c.skip(12); break;                      // floating point
      case 2: c.skip(2); break;                       // time
      case 3: break;                                  // string
      case 4: c.skip(4); break;                       // bit field
      case 5: c.skip(bits[0]); break;                 // opaque: its tag
      case 6: {                                       // compound
        const unsigned members = static_cast<unsigned>(bits[0] | bits[1] << 8);
        for (unsigned m = 0; m < members; ++m) {
          std::uint64_t nameBytes = 0;
          while (c.take(1)[0] != 0)
            if (++nameBytes > kMaxNameBytes) refuse(what + " has a member name longer than " + std::to_string(kMaxNameBytes));
          if (version < 3) c.skip((8 - (nameBytes + 1) % 8) % 8);
          if (version < 3) {
            c.skip(4);
            if (version == 1) c.skip(28);
          } else {
            c.skip(t.size < (1u << 8) ? 1 : t.size < (1u << 16) ? 2 : t.size < (1u << 24) ? 3 : 4);
          }
          const Type member = datatype(c, path, nesting + 1);
          t.vlen = t.vlen || member.vlen;
          t.objectReference = t.objectReference || member.objectReference;
        }
        break;
      }
      case 7:                                         // reference
        if ((bits[0] & 15) != 0)
          refuse(path + " holds region references, which FlexArm does not follow");
        t.objectReference = true;
        break;
      case 8: {                                       // enumeration
        const unsigned members = static_cast<unsigned>(bits[0] | bits[1] << 8);
        const Type base = datatype(c, path, nesting + 1);
        for (unsigned m = 0; m < members; ++m) {
          std::uint64_t nameBytes = 0;
          while (c.take(1)[0] != 0)
            if (++nameBytes > kMaxNameBytes) refuse(what + " has a member name longer than " + std::to_string(kMaxNameBytes));
          if (version < 3) c.skip((8 - (nameBytes + 1) % 8) % 8);
        }
        c.skip(saturatingProduct(members, base.size));
        break;
      }
      case 9: {                                       // variable length
        const Type base = datatype(c, path, nesting + 1);
        if (base.vlen || base.objectReference) refuse(what + " nests variable-length data or references, which FlexArm does not follow");
        t.vlen = t.topVlen = true;
        t.vlenBaseSize = std::max<std::uint64_t>(1, base.size);
        break;
      }
      case 10: {                                      // array
        const unsigned rank = c.u8();
        if (version < 3) c.skip(3);
        c.skip(4ull * rank);
        if (version < 3) c.skip(4ull * rank);
        const Type base = datatype(c, path, nesting + 1);
        t.vlen = base.vlen;
        t.objectReference = base.objectReference;
        break;
      }
      default: refuse(what + " is of an unknown class " + std::to_string(t.cls));
    }
    if (t.size == 0 && t.cls != 9) refuse(what + " has elements of 0 bytes (the file is damaged)");
    return t;
  }

  void layout(Cursor& c, Layout& l, const std::string& path) {
    const unsigned version = c.u8();
    if (version == 1 || version == 2) {
      const unsigned rank = c.u8();
      l.cls = static_cast<int>(c.u8());
      c.skip(5);
      if (l.cls != 0) l.address = address(c);
      for (unsigned d = 0; d < rank; ++d) l.chunk.push_back(c.u32());
      if (l.cls == 0) {
        l.size = c.u32();
        l.compact = c.take(l.size);
      } else if (l.cls == 1) {
        l.size = 1;
        for (auto d : l.chunk) l.size = saturatingProduct(l.size, d);
        l.chunk.clear();
      }
      if (l.cls > 2) refuse(path + " has a data layout of unknown class");
      return;
    }
    if (version != 3 && version != 4) refuse(path + " has a data layout of unknown version " + std::to_string(version));
    l.cls = static_cast<int>(c.u8());
    switch (l.cls) {
      case 0:
        l.size = c.u16();
        l.compact = c.take(l.size);
        return;
      case 1:
        l.address = address(c);
        l.size = lengthField(c);
        return;
      case 2:
        break;
      case 3:
        refuse(path + " is a virtual dataset (its data are mapped from other files); FlexArm reads only the "
                      "file it was given");
      default: refuse(path + " has a data layout of unknown class " + std::to_string(l.cls));
    }
    if (version == 3) {
      const unsigned rank = c.u8();
      l.address = address(c);
      for (unsigned d = 0; d < rank; ++d) l.chunk.push_back(c.u32());
      return;
    }
    const unsigned flags = c.u8();
    const unsigned rank = c.u8();
    const int width = static_cast<int>(c.u8());
    if (width < 1 || width > 8) refuse(path + "'s chunk dimensions are stored in " + std::to_string(width) + " bytes");
    for (unsigned d = 0; d < rank; ++d) l.chunk.push_back(c.uint(width));
    l.index = static_cast<int>(c.u8());
    if (l.index == 1) {
      if (flags & 2) {
        l.filteredSize = lengthField(c);
        c.skip(4);
      }
      l.address = address(c);
    } else if (l.index == 2) {
      l.address = address(c);
    } else {
      refuse(path + " indexes its chunks with a structure (type " + std::to_string(l.index) +
             ") FlexArm does not check; MATLAB's own files use a version-1 B-tree");
    }
  }

  void filters(Cursor& c, Object& o, const std::string& path) {
    const unsigned version = c.u8();
    const unsigned count = c.u8();
    if (count > 32) refuse(path + " names " + std::to_string(count) + " filters, more than HDF5 allows (32)");
    if (version == 1) c.skip(6);
    else if (version != 2) refuse(path + " has a filter pipeline of unknown version");
    for (unsigned f = 0; f < count; ++f) {
      const unsigned id = c.u16();
      unsigned nameLength = 0;
      if (version == 1 || id >= 256) nameLength = c.u16();
      c.skip(2);  // flags
      const unsigned values = c.u16();
      c.skip(version == 1 ? (nameLength + 7) / 8 * 8 : nameLength);
      std::vector<std::uint32_t> data;
      for (unsigned v = 0; v < values; ++v) data.push_back(c.u32());
      if (version == 1 && values % 2 == 1) c.skip(4);
      if (id != 1 && id != 2 && id != 3)
        refuse(path + " is compressed with filter " + std::to_string(id) +
               (id >= 256 ? " (a plug-in library HDF5 would load)" : "") +
               "; FlexArm reads only deflate, shuffle and Fletcher-32");
      o.filters.push_back(id);
      if (id == 2) o.shuffleSizes.push_back(data.empty() ? 0u : data[0]);
    }
  }

  std::string name(Cursor& c, std::uint64_t n, const std::string& what) {
    if (n > kMaxNameBytes) refuse(what + " has a name of " + std::to_string(n) + " bytes");
    const Byte* p = c.take(n);
    std::string s(reinterpret_cast<const char*>(p), n);
    if (const auto nul = s.find('\0'); nul != std::string::npos) s.resize(nul);
    return s;
  }

  void addLink(Object& o, std::string linkName, std::uint64_t target, const std::string& path) {
    if (linkName.empty() || linkName.find('/') != std::string::npos || linkName == "." )
      refuse(path + " holds a link with an impossible name " + inQuotes(linkName));
    o.group = true;
    o.links.push_back({std::move(linkName), target});
    if (o.links.size() > static_cast<std::size_t>(limits_.maxObjects))
      refuse(path + " holds more than " + std::to_string(limits_.maxObjects) + " links");
  }

  void link(Cursor& c, Object& o, const std::string& path) {
    if (c.u8() != 1) refuse(path + " has a link message of unknown version");
    const unsigned flags = c.u8();
    unsigned type = 0;
    if (flags & 0x08) type = c.u8();
    if (flags & 0x04) c.skip(8);
    if (flags & 0x10) c.skip(1);
    const std::uint64_t length = c.uint(1 << (flags & 3));
    std::string linkName = name(c, length, path);
    if (type == 1)
      refuse((path == "/" ? "/" : path + "/") + linkName +
             " is a soft link (to a path); FlexArm follows only the hard links MATLAB writes");
    if (type == 64)
      refuse((path == "/" ? "/" : path + "/") + linkName +
             " is an external link to another file; FlexArm reads only the file it was given");
    if (type != 0) refuse((path == "/" ? "/" : path + "/") + linkName + " is a user-defined link, which FlexArm does not follow");
    addLink(o, std::move(linkName), address(c), path);
  }

  void linkInfo(Cursor& c, Object& o, const std::string& path) {
    if (c.u8() != 0) refuse(path + " has a link information message of unknown version");
    const unsigned flags = c.u8();
    if (flags & 1) c.skip(8);
    o.group = true;
    if (address(c) != kUndefined)
      refuse(path + " keeps its links in a fractal heap (dense storage of a group with many links), which "
                    "FlexArm does not check; MATLAB's own files keep them in a symbol table");
  }

  // --- symbol-table groups --------------------------------------------------------------------

  void symbolTable(Cursor& c, Object& o, const std::string& path) {
    const std::uint64_t btree = address(c), heap = address(c);
    o.group = true;
    // The heap holding the names.
    const std::string heapWhat = "the name heap of " + path;
    Cursor h(atAddress(heap, 8 + 2ull * static_cast<std::uint64_t>(sl_) + static_cast<std::uint64_t>(so_), heapWhat),
             8 + 2ull * static_cast<std::uint64_t>(sl_) + static_cast<std::uint64_t>(so_), heapWhat);
    if (std::memcmp(h.take(4), "HEAP", 4) != 0) refuse(heapWhat + " is not a local heap (the file is damaged)");
    h.skip(4);
    const std::uint64_t heapSize = lengthField(h);
    const std::uint64_t freeList = lengthField(h);
    const std::uint64_t data = address(h);
    const Byte* names = atAddress(data, heapSize, heapWhat);
    // Its free list, as HDF5 follows it: blocks inside the heap, each once (a cycle would make
    // HDF5 walk it forever).
    std::set<std::uint64_t> blocks;
    for (std::uint64_t b = normalized(freeList, sl_); b != kUndefined && b != 1;) {
      if (b > heapSize || 2 * static_cast<std::uint64_t>(sl_) > heapSize - b || !blocks.insert(b).second)
        refuse(heapWhat + " has a free list that leaves the heap or runs in a circle (the file is damaged)");
      Cursor f(names + b, 2 * static_cast<std::uint64_t>(sl_), heapWhat);
      const std::uint64_t next = normalized(lengthField(f), sl_);
      const std::uint64_t length = lengthField(f);
      if (length < 2 * static_cast<std::uint64_t>(sl_) || length > heapSize - b)
        refuse(heapWhat + " has a free block reaching past its end (the file is damaged)");
      b = next;
    }
    std::set<std::uint64_t> nodes;
    btreeGroup(btree, names, heapSize, o, path, nodes, 0);
  }

  // A version-1 B-tree node of the given type (0 groups, 1 chunks), met once: its level, its
  // entries and a cursor over its keys (of keyBytes) and children, key first.
  Cursor btreeNode(std::uint64_t node, unsigned type, std::uint64_t keyBytes, const std::string& what,
                   std::set<std::uint64_t>& nodes, int depth, unsigned& level, unsigned& entries) {
    if (depth > kMaxBtreeLevel) refuse(what + " is deeper than " + std::to_string(kMaxBtreeLevel) + " levels");
    if (!nodes.insert(node).second) refuse(what + " refers to one of its nodes twice (a cycle)");
    const std::uint64_t head = 8 + 2ull * static_cast<std::uint64_t>(so_);
    Cursor h(atAddress(node, head, what), head, what);
    if (std::memcmp(h.take(4), "TREE", 4) != 0) refuse(what + " is not a B-tree node (the file is damaged)");
    if (h.u8() != type) refuse(what + " is a B-tree of the wrong kind");
    level = h.u8();
    entries = h.u16();
    const std::uint64_t body = (entries + 1ull) * keyBytes + entries * static_cast<std::uint64_t>(so_);
    return Cursor(atAddress(node, head + body, what) + head, body, what);
  }

  void btreeGroup(std::uint64_t node, const Byte* names, std::uint64_t heapSize, Object& o, const std::string& path,
                  std::set<std::uint64_t>& nodes, int depth) {
    unsigned level = 0, entries = 0;
    Cursor c = btreeNode(node, 0, static_cast<std::uint64_t>(sl_), "the group index of " + path, nodes, depth,
                         level, entries);
    for (unsigned e = 0; e < entries; ++e) {
      lengthField(c);
      const std::uint64_t child = address(c);
      if (level > 0) btreeGroup(child, names, heapSize, o, path, nodes, depth + 1);
      else symbolNode(child, names, heapSize, o, path);
    }
  }

  void symbolNode(std::uint64_t node, const Byte* names, std::uint64_t heapSize, Object& o, const std::string& path) {
    const std::string what = "a symbol node of " + path;
    if (!symbolNodes_.insert(node).second) refuse(what + " is listed twice (a cycle)");
    Cursor h(atAddress(node, 8, what), 8, what);
    if (std::memcmp(h.take(4), "SNOD", 4) != 0) refuse(what + " is not a symbol table node (the file is damaged)");
    h.skip(2);
    const unsigned count = h.u16();
    const std::uint64_t entry = 2ull * static_cast<std::uint64_t>(so_) + 24;
    Cursor c(atAddress(node, 8 + count * entry, what) + 8, count * entry, what);
    for (unsigned k = 0; k < count; ++k) {
      const std::uint64_t nameOffset = offsetField(c);
      const std::uint64_t header = address(c);
      const std::uint32_t cache = c.u32();
      c.skip(4);
      c.skip(16);  // scratch: cached addresses, which the walk of the child's own header checks
      if (nameOffset >= heapSize) refuse(what + " names a link outside its name heap (the file is damaged)");
      const Byte* start = names + nameOffset;
      const Byte* end = static_cast<const Byte*>(std::memchr(start, 0, heapSize - nameOffset));
      if (!end) refuse(what + " has a link name without its end (the file is damaged)");
      std::string linkName(reinterpret_cast<const char*>(start), static_cast<std::size_t>(end - start));
      if (cache == 2)
        refuse((path == "/" ? "/" : path + "/") + linkName +
               " is a soft link (to a path); FlexArm follows only the hard links MATLAB writes");
      addLink(o, std::move(linkName), header, path);
    }
  }

  // --- attributes ----------------------------------------------------------------------------

  void attribute(Cursor& c, Object& o, const std::string& path) {
    const unsigned version = c.u8();
    if (version < 1 || version > 3) refuse(path + " has an attribute of unknown version");
    const unsigned flags = c.u8();
    if (version >= 2 && (flags & 3)) refuse(path + " has an attribute with a shared datatype or dataspace, which FlexArm does not follow");
    const std::uint64_t nameSize = c.u16(), typeSize = c.u16(), spaceSize = c.u16();
    if (version == 3) c.skip(1);
    auto pad = [version](std::uint64_t n) { return version == 1 ? (n + 7) / 8 * 8 : n; };
    Cursor nameField = c.sub(pad(nameSize), path);
    const std::string attributeName = name(nameField, nameSize, path + "'s attribute");
    const std::string what = path + "'s attribute " + attributeName;
    Cursor typeField = c.sub(pad(typeSize), what);
    const Type type = datatype(typeField, what, 0);
    Cursor spaceField = c.sub(pad(spaceSize), what);
    std::vector<std::uint64_t> dims;
    std::uint64_t elements = 1;
    dataspace(spaceField, dims, elements, what);
    const std::uint64_t elementBytes = type.topVlen ? 4 + static_cast<std::uint64_t>(so_) + 4 : type.size;
    const std::uint64_t need = saturatingProduct(elements, elementBytes);
    if (need > c.left()) refuse(what + " claims " + human(need) + " of data but holds " + human(c.left()));
    const Byte* data = c.take(need);
    if (type.vlen && !type.topVlen) refuse(what + " holds variable-length data inside another type, which FlexArm does not follow");
    if (type.objectReference) refuse(what + " holds object references, which FlexArm does not follow");
    if (type.topVlen) {
      Cursor v(data, need, what);
      for (std::uint64_t e = 0; e < elements; ++e) {
        const std::uint64_t length = v.u32();
        const std::uint64_t collection = address(v);
        const std::uint32_t index = v.u32();
        if (length > 0) globalHeapObject(collection, index, saturatingProduct(length, type.vlenBaseSize), what);
      }
    }
    if (attributeName == "MATLAB_class" && type.cls == 3) {
      o.matlabClass.assign(reinterpret_cast<const char*>(data), static_cast<std::size_t>(std::min<std::uint64_t>(need, 256)));
      if (const auto nul = o.matlabClass.find('\0'); nul != std::string::npos) o.matlabClass.resize(nul);
    }
    if (attributeName == "MATLAB_sparse") o.sparse = true;
  }

  void globalHeapObject(std::uint64_t collection, std::uint32_t index, std::uint64_t bytes, const std::string& what) {
    const std::string heapWhat = "the global heap " + what + " points into";
    const std::uint64_t head = 8 + static_cast<std::uint64_t>(sl_);
    Cursor h(atAddress(collection, head, heapWhat), head, heapWhat);
    if (std::memcmp(h.take(4), "GCOL", 4) != 0) refuse(heapWhat + " is not a global heap collection (the file is damaged)");
    h.skip(4);
    const std::uint64_t size = lengthField(h);
    if (size < head) refuse(heapWhat + " is too small (the file is damaged)");
    auto& objects = heaps_[collection];
    if (objects.empty()) {
      objects[0] = 0;  // walked
      // As HDF5 walks it: each object's header, then its data rounded up to 8 bytes; the free
      // space (object 0) counts its header in its size. An object that does not move the walk
      // on (a free space of size 0) made HDF5 loop forever.
      const std::uint64_t header = 8 + static_cast<std::uint64_t>(sl_);
      Cursor c(atAddress(collection, size, heapWhat) + head, size - head, heapWhat);
      while (c.left() >= header) {
        const unsigned id = c.u16();
        c.skip(6);
        const std::uint64_t n = lengthField(c);
        const std::uint64_t need = id > 0 ? header + (n + 7) / 8 * 8 : n;
        if (need < header || n > need || need - header > c.left())
          refuse(heapWhat + " holds an object that reaches past its end or does not advance (the file is damaged)");
        c.skip(need - header);
        if (id > 0) objects[id] = n;
      }
    }
    const auto it = objects.find(index);
    if (index == 0 || it == objects.end()) refuse(what + " points to a global heap object that does not exist");
    if (it->second < bytes) refuse(what + " claims " + human(bytes) + " of a global heap object of " + human(it->second));
  }

  // --- datasets --------------------------------------------------------------------------------

  void finishDataset(Object& o, const std::string& path) {
    if (o.type.vlen) refuse(path + " holds variable-length data, which no MATLAB variable does");
    const std::uint64_t bytes = saturatingProduct(o.elements, o.type.size);
    inflated_ = std::min(kUndefined - 1, inflated_ + std::min(bytes, kUndefined / 2));
    if (bytes == kUndefined || inflated_ > limits_.inflateBudget)
      refuse(path + " would take " + (bytes == kUndefined ? std::string("more bytes than can be counted") : human(bytes)) +
             " in memory uncompressed (all datasets so far " + human(inflated_) + "), more than the " +
             human(limits_.inflateBudget) + " FlexArm allows for a file of " + human(size_) +
             ": its data are made to exhaust memory, or it is damaged");
    const Layout& l = o.layout;
    if (l.cls == 0) {
      if (l.size < bytes) refuse(path + " claims " + human(bytes) + " but holds " + human(l.size));
    } else if (l.cls == 1) {
      if (l.address != kUndefined) {
        atAddress(l.address, std::max(l.size, bytes), "the data of " + path);
      }
    } else {
      chunked(o, path);
    }
    if (o.type.objectReference) readReferences(o, path);
  }

  std::uint64_t chunkBytes(const Object& o, const std::string& path) const {
    const Layout& l = o.layout;
    if (l.chunk.empty()) refuse(path + " has chunks without dimensions (the file is damaged)");
    std::uint64_t n = 1;
    for (std::size_t d = 0; d + 1 < l.chunk.size(); ++d) {  // the last is the element size
      if (l.chunk[d] == 0) refuse(path + " has chunks of size 0 (the file is damaged)");
      n = saturatingProduct(n, l.chunk[d]);
    }
    n = saturatingProduct(n, o.type.size);
    if (n > (1ull << 32)) refuse(path + " has chunks of " + human(n) + ", more than HDF5 allows");
    return n;
  }

  void chunkStored(std::uint64_t address, std::uint64_t stored, std::uint64_t chunk, bool filtered,
                   const std::string& path) {
    if (++chunks_ > limits_.maxChunks)
      refuse("the file's datasets hold more than " + std::to_string(limits_.maxChunks) + " chunks");
    atAddress(address, stored, "a chunk of " + path);
    if (filtered) {
      if (stored == 0 || static_cast<double>(chunk) > limits_.maxCompressionRatio * static_cast<double>(stored))
        refuse("a chunk of " + path + " claims to inflate from " + human(stored) + " to " + human(chunk) +
               ", more than deflate can (the file is damaged or made to exhaust memory)");
    } else if (stored < chunk) {
      refuse("a chunk of " + path + " holds " + human(stored) + " of its " + human(chunk) + " (the file is damaged)");
    }
  }

  void chunked(Object& o, const std::string& path) {
    const Layout& l = o.layout;
    const std::uint64_t chunk = chunkBytes(o, path);
    if (l.chunk.size() != o.dims.size() + 1)
      refuse(path + "'s chunks have " + std::to_string(l.chunk.size() - 1) + " dimensions but its data " +
             std::to_string(o.dims.size()) + " (the file is damaged)");
    const bool filtered = !o.filters.empty();
    if (l.index == 1) {
      chunkStored(l.address, filtered ? l.filteredSize : chunk, chunk, filtered, path);
      return;
    }
    if (l.index == 2) {
      if (filtered) refuse(path + " has an implicit chunk index with filters (the file is damaged)");
      if (l.address != kUndefined) {
        std::uint64_t count = 1;
        for (std::size_t d = 0; d < o.dims.size(); ++d)
          count = saturatingProduct(count, (o.dims[d] + l.chunk[d] - 1) / l.chunk[d]);
        atAddress(l.address, saturatingProduct(count, chunk), "the data of " + path);
      }
      return;
    }
    if (l.address == kUndefined) return;  // nothing written yet: fill values
    std::set<std::uint64_t> nodes;
    btreeChunks(l.address, o, path, chunk, filtered, nodes, 0, nullptr);
  }

  // Walks a chunk B-tree (version 1, type 1); with sink, hands it each chunk's address, size,
  // filter mask and offsets.
  using ChunkSink = std::function<void(std::uint64_t address, std::uint64_t stored, std::uint32_t mask,
                                       const std::vector<std::uint64_t>& offsets)>;
  void btreeChunks(std::uint64_t node, const Object& o, const std::string& path, std::uint64_t chunk, bool filtered,
                   std::set<std::uint64_t>& nodes, int depth, const ChunkSink* sink) {
    const std::size_t rank = o.layout.chunk.size();
    unsigned level = 0, entries = 0;
    Cursor c = btreeNode(node, 1, 8 + 8ull * rank, "the chunk index of " + path, nodes, depth, level, entries);
    std::vector<std::uint64_t> offsets(rank);
    for (unsigned e = 0; e < entries; ++e) {
      const std::uint64_t stored = c.u32();
      const std::uint32_t mask = c.u32();
      for (auto& x : offsets) x = c.uint(8);
      const std::uint64_t child = address(c);
      if (level > 0) {
        btreeChunks(child, o, path, chunk, filtered, nodes, depth + 1, sink);
        continue;
      }
      for (std::size_t d = 0; d + 1 < rank; ++d)
        if (offsets[d] % o.layout.chunk[d] != 0 || offsets[d] >= std::max<std::uint64_t>(o.dims[d], 1))
          refuse("a chunk of " + path + " lies outside its data (the file is damaged)");
      const std::uint64_t all = (std::uint64_t{1} << o.filters.size()) - 1;  // at most 32 filters
      const bool applied = filtered && (mask & all) != all;
      chunkStored(child, stored, chunk, applied, path);
      if (sink) (*sink)(child, stored, mask, offsets);
    }
  }

  // The object references of a dataset of them (MATLAB's cells and objects keep their
  // contents in #refs# this way): read, undone of their filters, and kept for the walk.
  void readReferences(Object& o, const std::string& path) {
    const std::uint64_t width = static_cast<std::uint64_t>(so_);
    if (o.type.cls != 7 || o.type.size != width) refuse(path + " holds references inside another type, which FlexArm does not follow");
    const std::uint64_t bytes = saturatingProduct(o.elements, width);
    if (bytes > kMaxReferenceBytes) refuse(path + " holds more references than FlexArm follows");
    if (bytes == 0) return;  // no elements, no references
    std::vector<Byte> data(static_cast<std::size_t>(bytes), 0);
    const Layout& l = o.layout;
    if (l.cls == 0) {
      if (l.size < bytes) refuse(path + " claims " + human(bytes) + " of references but holds " + human(l.size));
      std::memcpy(data.data(), l.compact, static_cast<std::size_t>(bytes));
    } else if (l.cls == 1) {
      if (l.address != kUndefined) std::memcpy(data.data(), atAddress(l.address, bytes, path), static_cast<std::size_t>(bytes));
    } else if (l.index == 0 && l.address != kUndefined) {
      readChunkedReferences(o, path, data);
    } else if (l.address != kUndefined) {
      refuse(path + " keeps its references in a chunk layout FlexArm does not read");
    }
    for (std::uint64_t k = 0; k < o.elements; ++k) {
      std::uint64_t a = 0;
      for (std::uint64_t b = width; b-- > 0;) a = a << 8 | data[static_cast<std::size_t>(k * width + b)];
      a = normalized(a, so_);
      if (a == 0 || a == kUndefined) continue;  // a null reference
      o.references.push_back(a);
      if (o.references.size() > static_cast<std::size_t>(limits_.maxObjects))
        refuse(path + " holds more than " + std::to_string(limits_.maxObjects) + " references");
    }
  }

  void readChunkedReferences(const Object& o, const std::string& path, std::vector<Byte>& out) {
    const std::uint64_t chunk = chunkBytes(o, path);
    const std::uint64_t element = o.type.size;
    const std::size_t rank = o.dims.size();
    ChunkSink sink = [&](std::uint64_t address, std::uint64_t stored, std::uint32_t mask,
                         const std::vector<std::uint64_t>& offsets) {
      const Byte* raw = atAddress(address, stored, "a chunk of " + path);
      std::vector<Byte> work(raw, raw + stored);
      for (std::size_t f = o.filters.size(); f-- > 0;) {
        if (mask & (1u << f)) continue;
        if (o.filters[f] == 1) {
          std::vector<Byte> inflated(static_cast<std::size_t>(chunk));
          uLongf n = static_cast<uLongf>(chunk);
          if (uncompress(inflated.data(), &n, work.data(), static_cast<uLong>(work.size())) != Z_OK || n != chunk)
            refuse("a chunk of " + path + " does not inflate (the file is damaged)");
          work.swap(inflated);
        } else if (o.filters[f] == 3) {
          if (work.size() < 4) refuse("a chunk of " + path + " is cut short (the file is damaged)");
          work.resize(work.size() - 4);
        } else if (o.filters[f] == 2) {
          std::vector<Byte> plain(work.size());
          const std::size_t n = work.size() / element;
          for (std::size_t b = 0; b < element; ++b)
            for (std::size_t i = 0; i < n; ++i) plain[i * element + b] = work[b * n + i];
          work.swap(plain);
        }
      }
      if (work.size() < chunk) refuse("a chunk of " + path + " is cut short (the file is damaged)");
      // Copies the chunk's elements that lie inside the data to their places (row-major).
      const std::uint64_t count = chunk / element;
      std::vector<std::uint64_t> at(rank, 0);
      for (std::uint64_t i = 0; i < count; ++i) {
        std::uint64_t rest = i, linear = 0;
        bool inside = true;
        for (std::size_t d = rank; d-- > 0;) {
          at[d] = offsets[d] + rest % o.layout.chunk[d];
          rest /= o.layout.chunk[d];
          inside = inside && at[d] < o.dims[d];
        }
        if (!inside) continue;
        for (std::size_t d = 0; d < rank; ++d) linear = linear * o.dims[d] + at[d];
        std::memcpy(out.data() + linear * element, work.data() + i * element, static_cast<std::size_t>(element));
      }
    };
    std::set<std::uint64_t> nodes;
    btreeChunks(o.layout.address, o, path, chunk, !o.filters.empty(), nodes, 0, &sink);
  }

  const Byte* file_;
  std::uint64_t size_;
  const Hdf5Limits& limits_;
  const Hdf5Load& load_;
  int so_ = 8, sl_ = 8;
  std::uint64_t base_ = 0, root_ = kUndefined;
  bool v2Order_ = false;
  std::map<std::uint64_t, Object> objects_;
  std::set<std::uint64_t> symbolNodes_;
  std::map<std::uint64_t, std::map<std::uint32_t, std::uint64_t>> heaps_;
  std::uint64_t visits_ = 0, chunks_ = 0, inflated_ = 0;
};

}  // namespace

Hdf5Check checkHdf5File(std::string_view bytes, const Hdf5Limits& limits, const Hdf5Load& load) {
  Hdf5Check out;
  try {
    Walker walker(bytes, limits, load);
    walker.run(out);
    out.ok = true;
  } catch (const Refused& r) {
    out = Hdf5Check{};
    out.problem = r.problem;
  } catch (const std::bad_alloc&) {
    out = Hdf5Check{};
    out.problem = "the file's structure needs more memory than FlexArm gives a check";
  }
  return out;
}

}  // namespace flexarm
