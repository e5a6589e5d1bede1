#include "core/io/mat_check.h"

#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "core/common/text.h"
#include "core/io/hdf5_check.h"

namespace flexarm {
namespace {

using Byte = unsigned char;

constexpr std::uint32_t kMiInt8 = 1, kMiInt32 = 5, kMiUint32 = 6, kMiMatrix = 14,
                        kMiCompressed = 15;
constexpr std::uint32_t kOpaque = 17;  // array class of a classdef object
constexpr std::uint64_t kMaxName = 4096;  // MATLAB names have at most 63 characters
constexpr int kMaxDepth = 16;             // cells and structs nested deeper are refused
constexpr std::uint64_t kMaxElements = 1ull << 40;

const char* const kNotMat = "not a readable MATLAB .mat file (damaged, or not a .mat file at all)";

}  // namespace

std::uint64_t matTypeSize(std::uint32_t t) {
  switch (t) {
    case 1: case 2: case 16: return 1;       // int8, uint8, utf8
    case 3: case 4: case 17: return 2;       // int16, uint16, utf16
    case 5: case 6: case 7: case 18: return 4;  // int32, uint32, single, utf32
    case 9: case 12: case 13: return 8;      // double, int64, uint64
    default: return 0;
  }
}

namespace {

std::string sprintfString(const char* format, unsigned long long a, unsigned long long b) {
  char buf[200];
  std::snprintf(buf, sizeof buf, format, a, b);
  return buf;
}

struct Tag {
  std::uint32_t type = 0;
  std::uint64_t nbytes = 0;
  const Byte* data = nullptr;
  std::uint64_t total = 0;  // bytes the element takes, tag and padding included
};

class Level5 {
 public:
  Level5(bool swap, std::uint64_t budget, MatCheck& found, const Byte* base, std::uint64_t size,
         const MatLoad& load)
      : swap_(swap), inflateLeft_(budget), found_(found), base_(base), size_(size), load_(load) {}
  std::string problem;

  // Makes [p, p + n) readable: with a loader, bytes of the file not read yet are read (an
  // inflated body is in memory already).
  bool need(const Byte* p, std::uint64_t n) {
    const std::less<const Byte*> before;  // a total order, also for an inflated body's pointers
    if (!load_ || n == 0 || before(p, base_) || !before(p, base_ + size_)) return true;
    const auto off = static_cast<std::uint64_t>(p - base_);
    if (load_(off, std::min(n, size_ - off))) return true;
    return fail("the file cannot be read (it changed or shrank while being read)");
  }

  std::uint32_t u32(const Byte* p) const {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return swap_ ? __builtin_bswap32(v) : v;
  }

  // The sub-element at p (small or normal form); false when it does not fit before end.
  bool tag(const Byte* p, const Byte* end, Tag& t, const std::string& where) {
    if (end - p < 8) return fail(where + ": an element is cut short");
    if (!need(p, 8)) return false;
    const std::uint32_t first = u32(p);
    if (first >> 16) {  // small data element: type and size in one word, data in the next
      t.type = first & 0xffff;
      t.nbytes = first >> 16;
      t.data = p + 4;
      t.total = 8;
      if (t.nbytes > 4) return fail(where + ": a small element claims more than 4 bytes");
      return true;
    }
    t.type = first;
    t.nbytes = u32(p + 4);
    t.data = p + 8;
    const auto left = static_cast<std::uint64_t>(end - p - 8);
    if (t.nbytes > left)
      return fail(where + sprintfString(": an element claims %llu bytes where only %llu remain",
                                        t.nbytes, left));
    t.total = 8 + ((t.nbytes + 7) & ~std::uint64_t{7});
    if (t.total > left + 8) t.total = left + 8;  // the last element may lack its padding
    return true;
  }

  // The contents of one miMATRIX element, [p, end), described in *out as it is checked (no
  // description when out is null).
  bool matrix(const Byte* p, const Byte* end, const std::string& where0, int depth,
              MatVariable* out = nullptr) {
    if (p == end) return true;  // an empty array
    if (depth > kMaxDepth) return fail(where0 + ": cells or structs nested too deeply");
    Tag flags, dims, name;
    if (!tag(p, end, flags, where0)) return false;
    if (flags.type != kMiUint32 || flags.nbytes != 8)
      return fail(where0 + ": the array flags are damaged");
    if (!need(flags.data, 8)) return false;
    const std::uint32_t word = u32(flags.data);
    const std::uint32_t cls = word & 0xff;
    const bool complex = (word & (1u << 11)) != 0;
    p += flags.total;
    if (out) {
      out->arrayClass = cls;
      out->complex = complex;
    }
    if (cls == kOpaque) return opaque(p, end, where0, out);
    if (!tag(p, end, dims, where0)) return false;
    if (dims.type != kMiInt32 || dims.nbytes % 4 != 0 || dims.nbytes < 8 || dims.nbytes > 4 * 32)
      return fail(where0 + ": the dimensions are damaged");
    if (!need(dims.data, dims.nbytes)) return false;
    std::uint64_t count = 1;
    for (std::uint64_t i = 0; i < dims.nbytes / 4; ++i) {
      const auto d = static_cast<std::int32_t>(u32(dims.data + 4 * i));
      if (d < 0) return fail(where0 + ": a negative dimension");
      if (out) out->dims.push_back(static_cast<std::uint64_t>(d));
      count = d == 0 ? 0 : count * static_cast<std::uint64_t>(d);
      if (count > kMaxElements) return fail(where0 + ": the array claims more elements than the file can hold");
    }
    p += dims.total;
    std::string text;
    if (!nameTag(p, end, where0, name, text)) return false;
    const std::string where = name.nbytes ? "variable " + inQuotes(text) : where0;
    p += name.total;
    if (out) {
      if (name.nbytes) out->name = text;  // a field keeps the name its struct gives it
      out->elements = count;
    }
    const auto left = static_cast<std::uint64_t>(end - p);
    switch (cls) {
      case 1: {  // cell: count nested arrays
        if (count > left / 8) return fail(where + ": the cell array claims more cells than its bytes hold");
        for (std::uint64_t i = 0; i < count; ++i)
          if (!nested(p, end, where, depth, child(out, {}))) return false;
        return true;
      }
      case 2: {  // struct: field-name length, names, then count * fields nested arrays
        Tag len, names;
        if (!tag(p, end, len, where)) return false;
        if (len.type != kMiInt32 || len.nbytes != 4) return fail(where + ": the struct is damaged");
        if (!need(len.data, 4)) return false;
        const std::uint64_t l = u32(len.data);
        p += len.total;
        if (!tag(p, end, names, where)) return false;
        if (l == 0 || l > kMaxName || names.type != kMiInt8 || names.nbytes % l != 0)
          return fail(where + ": the struct's field names are damaged");
        p += names.total;
        const std::uint64_t fields = names.nbytes / l;
        const auto rest = static_cast<std::uint64_t>(end - p);
        if (fields && count > rest / 8 / fields)
          return fail(where + ": the struct claims more fields than its bytes hold");
        if (out && fields) {
          if (fields > nodesLeft_) return fail(where + ": the struct has more fields than FlexArm lists");
          if (!need(names.data, names.nbytes)) return false;
          for (std::uint64_t f = 0; f < fields; ++f) {
            const auto* n = reinterpret_cast<const char*>(names.data + f * l);
            out->fields.emplace_back(n, strnlen(n, l));
          }
        }
        for (std::uint64_t i = 0; i < count * fields; ++i)
          if (!nested(p, end, where, depth, child(out, out && fields ? out->fields[i % fields] : std::string())))
            return false;
        return true;
      }
      case 3: {  // object: a struct with a class name, which FlexArm does not read
        Tag className;
        std::string classText;
        if (!nameTag(p, end, where, className, classText)) return false;
        return skip(out, "a MATLAB object of class " + classText);
      }
      case 5: return skip(out, "a sparse matrix (save the signals as full numeric vectors)");
      case 4: case 6: case 7: case 8: case 9: case 10: case 11: case 12: case 13: case 14: case 15: {
        for (int part = 0; part < (complex ? 2 : 1); ++part) {
          if (p == end && count == 0) return true;
          Tag data;
          if (!tag(p, end, data, where)) return false;
          const std::uint64_t size = matTypeSize(data.type);
          if (size == 0) return fail(where + ": the data have an unknown number type");
          if (count > data.nbytes / size)
            return fail(where + sprintfString(": the array claims %llu elements but its data hold %llu",
                                              count, data.nbytes / size));
          if (out && part == 0) {
            out->dataType = data.type;
            out->data = data.data;
          }
          p += data.total;
        }
        return true;
      }
      default: return skip(out, "an array class FlexArm does not read (a function handle or an opaque object)");
    }
  }

  // An opaque object (class 17, as MATLAB stores classdef objects such as a Robotics Toolbox
  // SerialLink): its name, type system and class name, then contents FlexArm does not read.
  bool opaque(const Byte* p, const Byte* end, const std::string& where0, MatVariable* out) {
    Tag name, system, className;
    std::string text, systemText, classText;
    if (!nameTag(p, end, where0, name, text)) return false;
    p += name.total;
    const std::string where = name.nbytes ? "variable " + inQuotes(text) : where0;
    if (!nameTag(p, end, where, system, systemText)) return false;
    p += system.total;
    if (!nameTag(p, end, where, className, classText)) return false;
    if (out && name.nbytes) out->name = text;
    return skip(out, "a MATLAB object of class " + classText);
  }

  // A name tag (miINT8 text of at most kMaxName bytes) at p, its text up to a NUL as matio
  // reads it.
  bool nameTag(const Byte* p, const Byte* end, const std::string& where, Tag& t, std::string& text) {
    if (!tag(p, end, t, where)) return false;
    if (t.type != kMiInt8 || t.nbytes > kMaxName)
      return fail(where + ": the variable name is damaged or longer than 4096 characters");
    if (!need(t.data, t.nbytes)) return false;
    const auto* chars = reinterpret_cast<const char*>(t.data);
    text.assign(chars, strnlen(chars, t.nbytes));
    return true;
  }

  // Marks the array described in out as skipped (what FlexArm does not read); always true.
  static bool skip(MatVariable* out, const std::string& why) {
    if (out) out->unreadable = why;
    return true;
  }

  // The description of the next child of parent (a field named `name` or a cell), or null
  // when parent is not described or the file has used up its listing budget.
  MatVariable* child(MatVariable* parent, const std::string& name) {
    if (!parent) return nullptr;
    if (nodesLeft_ == 0) {
      parent->childrenCut = true;
      return nullptr;
    }
    --nodesLeft_;
    parent->children.emplace_back();
    parent->children.back().name = name;
    return &parent->children.back();
  }

  // One nested miMATRIX element at p, described in out; advances p.
  bool nested(const Byte*& p, const Byte* end, const std::string& where, int depth, MatVariable* out) {
    Tag t;
    if (!tag(p, end, t, where)) return false;
    if (t.type != kMiMatrix) return fail(where + ": a cell or field is not an array");
    if (!matrix(t.data, t.data + t.nbytes, where, depth + 1, out)) return false;
    p += t.total;
    return true;
  }

  // A compressed variable: inflated within the budget, then checked as an array.
  bool compressed(const Byte* p, std::uint64_t n, const std::string& where) {
    if (!need(p, n)) return false;
    z_stream z{};
    if (inflateInit(&z) != Z_OK) return fail(where + ": cannot start decompressing");
    struct End {
      z_stream* z;
      ~End() { inflateEnd(z); }
    } ender{&z};
    Byte head[8];
    z.next_in = const_cast<Byte*>(p);
    z.avail_in = static_cast<uInt>(std::min<std::uint64_t>(n, 0xffffffffu));
    z.next_out = head;
    z.avail_out = 8;
    int rc = inflate(&z, Z_SYNC_FLUSH);
    if (z.avail_out != 0 || (rc != Z_OK && rc != Z_STREAM_END))
      return fail(where + ": a compressed variable is damaged");
    if (u32(head) != kMiMatrix) return fail(where + ": a compressed element is not an array");
    const std::uint64_t inner = u32(head + 4);
    if (inner > inflateLeft_)
      return fail(where + sprintfString(": a compressed variable claims to inflate to %llu bytes, "
                                        "more than the %llu this file's size allows",
                                        inner, inflateLeft_));
    inflateLeft_ -= inner;
    std::unique_ptr<Byte[]> body(new Byte[inner ? inner : 1]);
    z.next_out = body.get();
    z.avail_out = static_cast<uInt>(inner);
    if (inner) {
      rc = inflate(&z, Z_FINISH);
      if (z.avail_out != 0 || (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR))
        return fail(where + ": a compressed variable is damaged or cut short");
    }
    MatVariable v;
    if (!matrix(body.get(), body.get() + inner, where, 0, &v)) return false;
    keep(std::move(v), inner != 0);
    found_.inflated.push_back(std::move(body));
    return true;
  }

  bool file(const Byte* p, std::uint64_t n) {
    std::uint64_t off = 128;
    int index = 0;
    while (n - off >= 8) {
      const std::string where = "variable " + std::to_string(++index);
      if (!need(p + off, 8)) return false;
      const std::uint32_t type = u32(p + off);
      const std::uint64_t nbytes = u32(p + off + 4);
      if (nbytes > n - off - 8)
        return fail(where + sprintfString(" claims %llu bytes but the file has only %llu left "
                                          "(damaged or cut short)",
                                          nbytes, n - off - 8));
      if (type == kMiMatrix) {
        MatVariable v;
        if (!matrix(p + off + 8, p + off + 8 + nbytes, where, 0, &v)) return false;
        keep(std::move(v), nbytes != 0);
      }
      if (type == kMiCompressed && !compressed(p + off + 8, nbytes, where)) return false;
      off += 8 + nbytes;
    }
    return true;
  }

 private:
  // A described variable joins the list (an empty miMATRIX element has nothing to describe).
  // An unreadable one is named among the skipped.
  void keep(MatVariable&& v, bool any) {
    if (!any) return;
    if (!v.unreadable.empty())
      found_.skipped.push_back((v.name.empty() ? std::string("a nameless variable") : v.name) + " (" +
                               v.unreadable + ")");
    found_.variables.push_back(std::move(v));
  }
  bool fail(const std::string& text) {
    problem = text;
    return false;
  }
  bool swap_;
  std::uint64_t inflateLeft_;
  MatCheck& found_;
  const Byte* base_;
  std::uint64_t size_;
  const MatLoad& load_;
  std::uint64_t nodesLeft_ = MatCheck::kMaxNodes;
};

// Level 4: records of five int32 (type MOPT, rows, columns, imaginary flag, name length),
// the name and the data.
bool level4(const Byte* p, std::uint64_t n, std::string& problem) {
  std::uint64_t off = 0;
  bool swap = false;
  int index = 0;
  while (off < n) {
    ++index;
    if (n - off < 20) {
      problem = kNotMat;
      return false;
    }
    auto word = [&](int i) {
      std::uint32_t v;
      std::memcpy(&v, p + off + 4 * i, 4);
      return static_cast<std::int32_t>(swap ? __builtin_bswap32(v) : v);
    };
    if (index == 1 && (word(0) < 0 || word(0) > 4052)) swap = true;
    const std::int32_t type = word(0), rows = word(1), cols = word(2), imag = word(3), namelen = word(4);
    const int m = type / 1000, o = type / 100 % 10, prec = type / 10 % 10, t = type % 10;
    if (type < 0 || m > 1 || o != 0 || prec > 5 || t > 2 || rows < 0 || cols < 0 || imag < 0 ||
        imag > 1 || namelen < 1 || namelen > static_cast<std::int32_t>(kMaxName)) {
      problem = kNotMat;
      return false;
    }
    // M names the byte order the numbers were written in (0 little-endian, 1 big-endian), and
    // matio reads the rest of the header in it: a type that reads right only in the other order
    // makes matio take the name length (and sizes) the wrong way round, gigabytes for a few bytes.
    constexpr bool bigEndianHost = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;
    if (m != ((swap != bigEndianHost) ? 1 : 0)) {
      problem = "variable " + std::to_string(index) + " states " + (m ? "big" : "little") +
                "-endian numbers but its header is written the other way: damaged, or not a .mat file";
      return false;
    }
    // A sparse matrix (t = 2) is stored as rows of (i, j, value) or (i, j, re, im): any other
    // number of columns is not one, and matio would size its arrays by the rows alone.
    if (t == 2 && cols != (imag ? 4 : 3) && cols != 4) {
      problem = "variable " + std::to_string(index) + " is a sparse matrix stored with " + std::to_string(cols) +
                " columns (a level-4 sparse matrix has 3 or 4): damaged, or not a .mat file";
      return false;
    }
    static const std::uint64_t sizes[] = {8, 4, 4, 2, 2, 1};
    const std::uint64_t bytes = static_cast<std::uint64_t>(rows) * static_cast<std::uint64_t>(cols) *
                                sizes[prec] * (imag ? 2u : 1u);
    if (20 + static_cast<std::uint64_t>(namelen) > n - off || bytes > n - off - 20 - static_cast<std::uint64_t>(namelen)) {
      problem = "variable " + std::to_string(index) + sprintfString(
          " claims %llu bytes of data but the file has only %llu left (damaged or cut short)",
          bytes, n - off - 20 - std::min<std::uint64_t>(n - off - 20, static_cast<std::uint64_t>(namelen)));
      return false;
    }
    off += 20 + static_cast<std::uint64_t>(namelen) + bytes;
  }
  return true;
}

}  // namespace

namespace {

// A v7.3 file is walked by hdf5_check before HDF5 opens it. Its compressed data may inflate to
// 64 times the file's size (at least 64 MiB): a log of real signals compresses a few times,
// and only a file made to exhaust memory asks for more.
bool checkV73(std::string_view bytes, std::uint64_t inflateBudget, const MatLoad& load, MatCheck& r) {
  Hdf5Limits limits;
  limits.inflateBudget = std::min<std::uint64_t>(inflateBudget, std::max<std::uint64_t>(64u << 20, 64 * bytes.size()));
  const Hdf5Check h = checkHdf5File(bytes, limits, load);
  r.problem = h.problem;
  for (const Hdf5Variable& v : h.variables)
    if (!v.numeric) r.skipped.push_back(v.name + " (" + (v.matlabClass.empty() ? std::string(v.dataset ? "not numeric" : "a group") : v.matlabClass) + ")");
  return h.ok;
}

}  // namespace

MatCheck checkMatFile(std::string_view bytes, std::uint64_t inflateBudget, const MatLoad& load) {
  MatCheck r;
  const auto* p = reinterpret_cast<const Byte*>(bytes.data());
  const std::uint64_t n = bytes.size();
  if (load && !load(0, std::min<std::uint64_t>(n, 128))) {
    r.problem = "the file cannot be read";
    return r;
  }
  if (n >= 128 && ((p[126] == 'I' && p[127] == 'M') || (p[126] == 'M' && p[127] == 'I'))) {
    // Written as a 16-bit 'MI': read back as "IM" the file has this machine's byte order.
    const bool swap = p[126] == 'M';
    const unsigned version = swap ? (p[124] << 8 | p[125]) : (p[125] << 8 | p[124]);
    if (version == 0x0200) {
      r.kind = MatKind::V73;
      r.ok = checkV73(bytes, inflateBudget, load, r);
      return r;
    }
    if (version == 0x0100) {
      r.kind = MatKind::V5;
      r.swapBytes = swap;
      Level5 walker(swap, inflateBudget, r, p, n, load);
      r.ok = walker.file(p, n);
      r.problem = walker.problem;
      if (!r.ok) {
        r.variables.clear();
        r.inflated.clear();
      }
      return r;
    }
  }
  r.kind = MatKind::V4;
  if (load && !load(0, n)) {  // a level-4 file is walked whole
    r.problem = "the file cannot be read";
    return r;
  }
  if (n == 0) {
    r.problem = kNotMat;
    return r;
  }
  r.ok = level4(p, n, r.problem);
  return r;
}

}  // namespace flexarm
