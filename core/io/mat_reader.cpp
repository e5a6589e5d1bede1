// MATLAB .mat files, after core/io/mat_check has bounded every size the file states: vectors
// named like the FlexArm columns, u/y, or the user's variables. Level-5 files (MATLAB's default,
// SciPy's savemat) are decoded from the bytes the check walked; matio reads level 4 and v7.3.
#include <matio.h>

#include <Eigen/Core>

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <type_traits>
#include <vector>

#include "core/common/parallel.h"
#include "core/io/input_file.h"
#include "core/io/log_io.h"
#include "core/io/log_source.h"
#include "core/io/mat_check.h"
#include "core/io/mat_expression.h"
#include "core/io/reader_support.h"

namespace flexarm {
namespace {

using io::failure;

// A vector of n elements, sized, whose memory the kernel may back with huge pages: a channel
// of a large log then costs a few page faults instead of thousands (most of reading a .mat
// file that is already in the disk cache).
template <class T>
void sizeOnHugePages(std::vector<T>& v, std::size_t n) {
  v.clear();
  v.reserve(n);
  preferHugePages(v.data(), n * sizeof(T));
  v.resize(n);
}

// The stored number of type Stored at p as a double, through the variable's class: MATLAB's
// conversion to an integer class rounds and saturates (NaN to 0), single rounds to float.
template <class Class, class Stored>
double convert(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(Stored)];
  std::memcpy(b, p, sizeof b);
  if (swap) std::reverse(b, b + sizeof b);
  Stored s;
  std::memcpy(&s, b, sizeof s);
  const auto x = static_cast<double>(s);
  if constexpr (std::is_integral_v<Class>) {
    if (std::isnan(x)) return 0.0;
    return std::clamp(std::round(x), static_cast<double>(std::numeric_limits<Class>::min()),
                      static_cast<double>(std::numeric_limits<Class>::max()));
  } else {
    return static_cast<double>(static_cast<Class>(x));
  }
}

template <class Class, class Stored>
void decodeAll(const unsigned char* p, bool swap, double* out, std::size_t n) {
  if constexpr (std::is_same_v<Class, double> && std::is_same_v<Stored, double>) {
    if (!swap) {
      std::memcpy(out, p, n * sizeof(double));
      return;
    }
  }
  for (std::size_t i = 0; i < n; ++i) out[i] = convert<Class, Stored>(p + i * sizeof(Stored), swap);
}

// The n elements at data (stored as the level-5 number type `type`) as doubles, through the
// variable's class; false for a number type that holds no numbers (text stored in a numeric
// array).
template <class Class>
bool decodeLevel5(const unsigned char* p, std::uint32_t type, bool swap, double* out, std::size_t n) {
  switch (type) {
    case 1: decodeAll<Class, std::int8_t>(p, swap, out, n); return true;
    case 2: decodeAll<Class, std::uint8_t>(p, swap, out, n); return true;
    case 3: decodeAll<Class, std::int16_t>(p, swap, out, n); return true;
    case 4: decodeAll<Class, std::uint16_t>(p, swap, out, n); return true;
    case 5: decodeAll<Class, std::int32_t>(p, swap, out, n); return true;
    case 6: decodeAll<Class, std::uint32_t>(p, swap, out, n); return true;
    case 7: decodeAll<Class, float>(p, swap, out, n); return true;
    case 9: decodeAll<Class, double>(p, swap, out, n); return true;
    case 12: decodeAll<Class, std::int64_t>(p, swap, out, n); return true;
    case 13: decodeAll<Class, std::uint64_t>(p, swap, out, n); return true;
    default: return false;
  }
}

// The level-5 number type matio holds a numeric class's data in after reading it.
std::uint32_t storedTypeOf(unsigned cls) {
  switch (cls) {
    case MAT_C_DOUBLE: return 9;
    case MAT_C_SINGLE: return 7;
    case MAT_C_INT8: return 1;
    case MAT_C_UINT8: return 2;
    case MAT_C_INT16: return 3;
    case MAT_C_UINT16: return 4;
    case MAT_C_INT32: return 5;
    case MAT_C_UINT32: return 6;
    case MAT_C_INT64: return 12;
    case MAT_C_UINT64: return 13;
    default: return 0;
  }
}

// A variable matio describes (with its data when it was read), as the check describes a
// level-5 one: the same tree for the expressions to walk.
void fromMatio(matvar_t* v, MatVariable& out, std::uint64_t& nodesLeft) {
  if (v->name) out.name = v->name;
  out.arrayClass = static_cast<std::uint32_t>(v->class_type);
  out.complex = v->isComplex != 0;
  out.elements = 1;
  for (int d = 0; d < v->rank && v->dims; ++d) {
    out.dims.push_back(v->dims[d]);
    out.elements = v->dims[d] == 0 ? 0 : out.elements * v->dims[d];
  }
  switch (v->class_type) {
    case MAT_C_STRUCT: {
      const unsigned fields = Mat_VarGetNumberOfFields(v);
      char* const* names = Mat_VarGetStructFieldnames(v);
      for (unsigned f = 0; f < fields && names; ++f) out.fields.emplace_back(names[f] ? names[f] : "");
      if (!v->data) return;
      for (std::uint64_t e = 0; e < out.elements; ++e)
        for (unsigned f = 0; f < fields; ++f) {
          matvar_t* field = Mat_VarGetStructFieldByIndex(v, f, e);
          if (!field || nodesLeft == 0) {
            out.childrenCut = true;
            return;
          }
          --nodesLeft;
          out.children.emplace_back();
          fromMatio(field, out.children.back(), nodesLeft);
          out.children.back().name = out.fields[f];
        }
      return;
    }
    case MAT_C_CELL: {
      if (!v->data) return;
      for (std::uint64_t e = 0; e < out.elements; ++e) {
        matvar_t* cell = Mat_VarGetCell(v, static_cast<int>(std::min<std::uint64_t>(e, INT_MAX)));
        if (!cell || nodesLeft == 0) {
          out.childrenCut = true;
          return;
        }
        --nodesLeft;
        out.children.emplace_back();
        fromMatio(cell, out.children.back(), nodesLeft);
        out.children.back().name.clear();
      }
      return;
    }
    case MAT_C_OBJECT: case MAT_C_OPAQUE: out.unreadable = "a MATLAB object"; return;
    case MAT_C_SPARSE: out.unreadable = "a sparse matrix (save the signals as full numeric vectors)"; return;
    case MAT_C_FUNCTION: out.unreadable = "a function handle"; return;
    default:
      if (v->data && !v->isComplex) {
        out.dataType = storedTypeOf(static_cast<unsigned>(v->class_type));
        out.data = static_cast<const unsigned char*>(v->data);
      }
      return;
  }
}

// Where a checked level-5 file's bytes are: `base` holds what the check loaded, and the rest
// (numeric data) is read from the file when a variable is read.
struct Level5Source {
  const InputFile* file = nullptr;  // null: base holds the whole file
  const unsigned char* base = nullptr;
  std::uint64_t size = 0;
  MatLoad load;
};

// The variables of a checked file: a level-5 file is decoded from the bytes the check has
// just walked (one read of the file); level 4 and the HDF5-based v7.3 are read by matio,
// whose variables are described first and read whole when an expression names them.
class MatVariables {
 public:
  MatVariables(const MatCheck& check, mat_t* mat, Level5Source source = {})
      : check_(check), mat_(mat), source_(std::move(source)) {
    if (!mat_) return;
    std::uint64_t nodes = MatCheck::kMaxNodes;
    while (matvar_t* info = Mat_VarReadNextInfo(mat_)) {
      if (info->name) {
        described_.emplace_back();
        fromMatio(info, described_.back(), nodes);
      }
      Mat_VarFree(info);
    }
    Mat_Rewind(mat_);
  }
  ~MatVariables() {
    for (matvar_t* v : read_) Mat_VarFree(v);
  }
  MatVariables(const MatVariables&) = delete;
  MatVariables& operator=(const MatVariables&) = delete;

  const std::vector<MatVariable>& variables() const { return mat_ ? described_ : check_.variables; }

  // matio's files: reads the variable `name` whole (its size bounded by the caller), so its
  // numbers can be read. False when matio cannot read it.
  bool load(const std::string& name) {
    if (!mat_) return true;
    for (MatVariable& v : described_) {
      if (v.name != name) continue;
      if (v.data || !v.children.empty() || v.elements == 0) return true;  // read already
      matvar_t* var = Mat_VarRead(mat_, name.c_str());
      if (!var) return false;
      read_.push_back(var);
      MatVariable full;
      std::uint64_t nodes = MatCheck::kMaxNodes;
      fromMatio(var, full, nodes);
      v = std::move(full);
      return true;
    }
    return true;
  }

  // The selected elements as doubles, straight into out (count of them). False when the data
  // cannot be read.
  bool read(const MatSelection& s, double* out) {
    const MatVariable& v = *s.array;
    if (!v.data) return false;
    const std::uint64_t size = matTypeSize(v.dataType);
    if (size == 0) return false;
    const unsigned char* first = v.data + s.start * size;
    if (s.stride == 1) return readAs(v.arrayClass, first, v.dataType, out, static_cast<std::size_t>(s.count));
    // A row of a matrix: the span from the first to the last element, then every stride-th.
    const std::uint64_t span = (s.count - 1) * s.stride + 1;
    std::vector<double> all(static_cast<std::size_t>(span));
    if (!readAs(v.arrayClass, first, v.dataType, all.data(), all.size())) return false;
    for (std::uint64_t i = 0; i < s.count; ++i) out[i] = all[static_cast<std::size_t>(i * s.stride)];
    return true;
  }

 private:
  bool readAs(std::uint32_t cls, const unsigned char* p, std::uint32_t type, double* out, std::size_t n) {
    switch (cls) {
      case MAT_C_DOUBLE: return readAs<double>(p, type, out, n);
      case MAT_C_SINGLE: return readAs<float>(p, type, out, n);
      case MAT_C_INT8: return readAs<std::int8_t>(p, type, out, n);
      case MAT_C_UINT8: return readAs<std::uint8_t>(p, type, out, n);
      case MAT_C_INT16: return readAs<std::int16_t>(p, type, out, n);
      case MAT_C_UINT16: return readAs<std::uint16_t>(p, type, out, n);
      case MAT_C_INT32: return readAs<std::int32_t>(p, type, out, n);
      case MAT_C_UINT32: return readAs<std::uint32_t>(p, type, out, n);
      case MAT_C_INT64: return readAs<std::int64_t>(p, type, out, n);
      case MAT_C_UINT64: return readAs<std::uint64_t>(p, type, out, n);
      default: return false;
    }
  }

  template <class T>
  bool readAs(const unsigned char* p, std::uint32_t type, double* out, std::size_t n) {
    if (mat_) return decodeLevel5<T>(p, type, false, out, n);  // matio's data, in memory
    const unsigned char* base = source_.base;
    const std::less<const unsigned char*> before;  // a total order, also for inflated bodies
    if (source_.file && !before(p, base) && before(p, base + source_.size)) {
      // Data the check left in the file: doubles in this machine's byte order go straight
      // to `out` (a large variable in parts on every core: one core does not saturate the
      // memory), anything else is loaded and decoded.
      const auto offset = static_cast<std::uint64_t>(p - base);
      const std::uint64_t bytes = n * matTypeSize(type);
      if (bytes > source_.size - offset) return false;
      if (std::is_same_v<T, double> && type == 9 && !check_.swapBytes) {
        std::atomic<bool> ok{true};
        parallelRanges(n, threadsFor(bytes, 2u << 20), [&](std::size_t from, std::size_t to) {
          const std::size_t bytesHere = (to - from) * sizeof(double);
          if (source_.file->readFully(offset + from * sizeof(double), reinterpret_cast<char*>(out + from),
                                      bytesHere) != bytesHere)
            ok = false;
        });
        return ok;
      }
      if (!source_.load(offset, bytes)) return false;
    }
    return decodeLevel5<T>(p, type, check_.swapBytes, out, n);
  }

  const MatCheck& check_;
  mat_t* mat_ = nullptr;
  Level5Source source_;
  std::vector<MatVariable> described_;  // matio's variables
  std::vector<matvar_t*> read_;         // matio's variables read whole (their data are used)
};

// The bytes the numbers of a variable take as doubles, its fields and cells included.
double bytesAsDoubles(const MatVariable& v) {
  if (isNumericMatClass(v.arrayClass)) return 8.0 * static_cast<double>(v.elements);
  double sum = 0.0;
  for (const auto& c : v.children) sum += bytesAsDoubles(c);
  return sum;
}

// A signal the mapping names: its expression, whether the user gave it (not a default).
struct Wanted {
  std::string expression;
  bool given = false;
};

// Reads the vector an expression names straight into `out`, after checking its size against
// the budget; fail names the expression.
bool readMatSeries(MatVariables& vars, const std::string& path, const std::string& text,
                   std::uint64_t budget, std::vector<double>& out, LogReadResult& fail) {
  std::string why;
  const std::optional<MatExpression> e = parseMatExpression(text, &why);
  if (!e) {
    fail = failure(path, 0, 0, text, "not an expression FlexArm reads (" + why + ")");
    return false;
  }
  for (const MatVariable& v : vars.variables())
    if (v.name == e->variable && bytesAsDoubles(v) > static_cast<double>(budget)) {
      fail = failure(path, 0, 0, e->variable,
                     "the variable claims " + humanBytes(static_cast<std::uint64_t>(bytesAsDoubles(v))) +
                         ", more than the " + humanBytes(budget) + " a file of this size can hold");
      return false;
    }
  if (!vars.load(e->variable)) {
    fail = failure(path, 0, 0, e->variable, "the variable's data cannot be read (the file is damaged)");
    return false;
  }
  MatSelection s;
  if (!selectMatVector(vars.variables(), *e, s, &why)) {
    fail = failure(path, 0, 0, text, why);
    return false;
  }
  if (s.array->complex) {
    fail = failure(path, 0, 0, text, "the variable holds complex numbers; FlexArm reads real signals");
    return false;
  }
  const auto n = static_cast<std::size_t>(s.count);
  sizeOnHugePages(out, n);
  if (!vars.read(s, out.data())) {
    fail = failure(path, 0, 0, text, "the variable's data cannot be read (the file is damaged)");
    return false;
  }
  // x - x is 0 for a finite x and NaN otherwise: one vectorized sum finds any non-finite one.
  const Eigen::Map<const Eigen::ArrayXd> x(out.data(), static_cast<Eigen::Index>(n));
  if (!std::isfinite((x - x).sum())) {
    const auto bad = std::find_if(out.begin(), out.end(), [](double v) { return !std::isfinite(v); });
    fail = failure(path, 0, 0, text,
                   "element " + std::to_string(bad - out.begin() + 1) + " is not a finite number");
    return false;
  }
  return true;
}

// A plain variable name that is a whole real vector (for the file's other channels and the
// sample time scalars), read quietly: false when it is anything else.
bool readPlainVector(MatVariables& vars, const MatVariable& v, std::uint64_t budget, std::vector<double>& out) {
  if (v.name.empty() || !v.unreadable.empty() || !isNumericMatClass(v.arrayClass) || v.complex) return false;
  if (v.dims.size() != 2 || (v.dims[0] != 1 && v.dims[1] != 1) || v.elements == 0) return false;
  LogReadResult ignore;
  const std::string name = v.name;  // loading may replace v
  return readMatSeries(vars, "", name, budget, out, ignore);
}

// The log the options ask for, from the variables of a checked file.
// `skipped`: what the file's check skipped besides the variables it describes as unreadable.
LogReadResult readMatVariables(MatVariables& vars, const std::string& path, const LogReadOptions& options,
                               std::uint64_t budget, const std::vector<std::string>& skipped);

}  // namespace

LogReadResult readMat(const std::string& path, const LogReadOptions& options) {
  InputFile file;
  std::string problem;
  if (!file.open(path, options.maxFileBytes, &problem)) return failure(path, 0, 0, {}, problem);
  return io::readMatFile(file, path, options);
}

namespace {

// Checks the file's structure, then lets `use` read its variables (a level-5 file decoded from
// the bytes the check walked, others through matio) within the budget. False with a sentence
// when the file is not a readable .mat file.
bool withVariables(const InputFile& file, const std::string& path, const LogReadOptions& options,
                   const std::function<void(MatVariables&, std::uint64_t budget, const MatCheck&)>& use,
                   std::string& problem) {
  // Only the parts the check reads (tags, names, dimensions, compressed variables) are read
  // into memory, in blocks; the numeric data go straight from the file to the signals.
  const auto size = static_cast<std::size_t>(file.size());
  std::unique_ptr<char, FileBufferDeleter> bytes = sparseFileBuffer(size);
  constexpr std::uint64_t kBlock = 64u << 10;
  std::vector<char> loaded((size + kBlock - 1) / kBlock, 0);
  MatLoad load = [&](std::uint64_t offset, std::uint64_t n) {
    if (n == 0) return true;
    if (offset > size || n > size - offset) return false;
    for (std::uint64_t b = offset / kBlock; b <= (offset + n - 1) / kBlock; ++b) {
      if (loaded[b]) continue;
      const std::uint64_t from = b * kBlock, count = std::min<std::uint64_t>(kBlock, size - from);
      if (file.readFully(from, bytes.get() + from, count) != count) return false;
      loaded[b] = 1;
    }
    return true;
  };
  const std::string_view view(bytes.get(), size);
  // zlib inflates at most 1032 times its input: no honest variable is larger than that.
  const std::uint64_t budget = std::min<std::uint64_t>(options.maxFileBytes, 1032ull * size + 65536);
  const MatCheck check = checkMatFile(view, budget, load);
  if (!check.ok) {
    problem = check.problem;
    return false;
  }
  mat_t* mat = nullptr;
  if (check.kind != MatKind::V5) {
    bytes.reset();  // matio reads the file itself
    // matio prints its own complaints to stderr; FlexArm reports one sentence instead.
    Mat_LogInitFunc("flexarm", [](int, char*) {});
    mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
    if (!mat) {
      problem = "not a readable MATLAB .mat file (damaged, or not a .mat file at all)";
      return false;
    }
  }
  struct Close {
    mat_t* m;
    ~Close() {
      if (m) Mat_Close(m);
    }
  } guard{mat};
  MatVariables vars(check, mat,
                    Level5Source{&file, reinterpret_cast<const unsigned char*>(bytes.get()), size, load});
  use(vars, budget, check);
  return true;
}

// The listing's entry of a variable, field or cell named by `expression`.
SourceEntry entryOf(const MatVariable& v, const std::string& label, const std::string& expression) {
  constexpr std::uint64_t kMaxListed = 200;  // elements of a struct array or cells shown
  SourceEntry e;
  e.label = label;
  e.expression = expression;
  e.shape = v.dims.empty() ? std::string() : matShapeText(v.dims);
  e.kind = matClassName(v.arrayClass);
  e.unreadable = v.unreadable;
  e.numeric = v.unreadable.empty() && isNumericMatClass(v.arrayClass) && !v.complex && v.elements > 0;
  if (e.numeric && !v.dims.empty()) {
    e.rows = v.dims[0];
    e.cols = v.dims[0] ? v.elements / v.dims[0] : 0;
  }
  if (v.arrayClass == 2 && !v.fields.empty()) {
    const std::size_t f = v.fields.size();
    if (v.elements == 1) {
      for (std::size_t i = 0; i < f && i < v.children.size(); ++i)
        e.children.push_back(entryOf(v.children[i], v.fields[i], expression + "." + v.fields[i]));
    } else {
      for (std::uint64_t k = 0; k < v.elements && k < kMaxListed && (k + 1) * f <= v.children.size(); ++k) {
        const std::string at = "(" + std::to_string(k + 1) + ")";
        SourceEntry element;
        element.label = at;
        element.expression = expression + at;
        element.kind = "struct";
        element.shape = "1 x 1";
        for (std::size_t i = 0; i < f; ++i)
          element.children.push_back(entryOf(v.children[k * f + i], v.fields[i], expression + at + "." + v.fields[i]));
        e.children.push_back(std::move(element));
      }
    }
  }
  if (v.arrayClass == 1)
    for (std::uint64_t k = 0; k < v.children.size() && k < kMaxListed; ++k) {
      const std::string at = "{" + std::to_string(k + 1) + "}";
      e.children.push_back(entryOf(v.children[k], at, expression + at));
    }
  return e;
}

}  // namespace

LogReadResult io::readMatFile(const InputFile& file, const std::string& path, const LogReadOptions& options) {
  LogReadResult result;
  std::string problem;
  if (!withVariables(file, path, options,
                     [&](MatVariables& vars, std::uint64_t budget, const MatCheck& check) {
                       result = readMatVariables(vars, path, options, budget, check.skipped);
                     },
                     problem))
    return failure(path, 0, 0, {}, problem);
  return result;
}

SourceListing io::listMatSource(const std::string& path, const LogReadOptions& options) {
  SourceListing listing;
  listing.format = LogFormat::Mat;
  InputFile file;
  std::string problem;
  const auto fail = [&] {
    listing.error = ReadError{path, 0, 0, {}, problem};
    return listing;
  };
  if (!file.open(path, options.maxFileBytes, &problem)) return fail();
  const bool ok = withVariables(file, path, options,
                                [&](MatVariables& vars, std::uint64_t, const MatCheck& check) {
                                  for (const MatVariable& v : vars.variables()) {
                                    if (v.name.empty()) continue;
                                    listing.entries.push_back(entryOf(v, v.name, v.name));
                                    if (!v.unreadable.empty())
                                      listing.notes.push_back("skipped " + v.name + " (" + v.unreadable + ")");
                                  }
                                  for (const auto& s : check.skipped)
                                    if (std::find(listing.notes.begin(), listing.notes.end(), "skipped " + s) ==
                                        listing.notes.end())
                                      listing.notes.push_back("skipped " + s);
                                },
                                problem);
  if (!ok) return fail();
  listing.ok = true;
  return listing;
}

SeriesRead io::readMatExpression(const std::string& path, const std::string& expression,
                                 const LogReadOptions& options) {
  SeriesRead out;
  InputFile file;
  std::string problem;
  if (!file.open(path, options.maxFileBytes, &problem)) {
    out.error = ReadError{path, 0, 0, {}, problem};
    return out;
  }
  LogReadResult fail;
  const bool ok = withVariables(file, path, options,
                                [&](MatVariables& vars, std::uint64_t budget, const MatCheck&) {
                                  out.ok = readMatSeries(vars, path, expression, budget, out.values, fail);
                                },
                                problem);
  if (!ok) out.error = ReadError{path, 0, 0, {}, problem};
  else if (!out.ok) out.error = fail.error;
  return out;
}

namespace {

LogReadResult readMatVariables(MatVariables& vars, const std::string& path, const LogReadOptions& options,
                               std::uint64_t budget, const std::vector<std::string>& checkSkipped) {
  LogReadResult fail;
  // Which variables: the mapping's expressions, else the FlexArm column names, else u/y; a
  // channel name the user chose (not the default u / y) names the variable when no variable
  // was named, and the channel either way.
  std::vector<std::string> names;
  for (const MatVariable& v : vars.variables())
    if (!v.name.empty() && v.unreadable.empty()) names.push_back(v.name);
  auto has = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) != names.end(); };
  // What FlexArm does not read is skipped and named, not refused with the file.
  std::vector<std::string> skippedList;
  for (const MatVariable& v : vars.variables())
    if (!v.unreadable.empty())
      skippedList.push_back((v.name.empty() ? std::string("a nameless variable") : v.name) + " (" + v.unreadable + ")");
  for (const auto& s : checkSkipped)
    if (std::find(skippedList.begin(), skippedList.end(), s) == skippedList.end()) skippedList.push_back(s);
  std::string skipped;
  for (const auto& s : skippedList) skipped += (skipped.empty() ? "" : ", ") + s;
  if (names.empty())
    return failure(path, 0, 0, {},
                   "the .mat file holds no variables FlexArm can read" +
                       (skipped.empty() ? std::string() : " (skipped: " + skipped + ")"));
  const LogMapping& m = options.mapping;
  const LogReadOptions defaults;
  const bool inputNamed = options.inputName != defaults.inputName && !options.inputName.empty();
  const bool outputNamed = options.outputName != defaults.outputName && !options.outputName.empty();
  Wanted in{m.input, !m.input.empty()}, out{m.output, !m.output.empty()};
  if (in.expression.empty() && inputNamed && has(options.inputName)) in.expression = options.inputName;
  if (out.expression.empty() && outputNamed && has(options.outputName)) out.expression = options.outputName;
  if (in.expression.empty()) in.expression = has(columns::kTorqueRef) ? columns::kTorqueRef : "u";
  if (out.expression.empty()) out.expression = has(columns::kMotorAngle) ? columns::kMotorAngle : "y";
  const std::string timeExpr = !m.time.empty() ? m.time : has(columns::kTime) ? columns::kTime : "";
  const std::string armExpr = !m.arm.empty() ? m.arm : has(columns::kArmAngle) ? columns::kArmAngle : "";
  const std::string refExpr = m.reference;
  for (const Wanted* w : {&in, &out})
    if (!w->given && !has(w->expression)) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      LogReadResult r = failure(path, 0, 0, w->expression,
                                "the variable '" + w->expression + "' is missing; the file holds " + list +
                                    (skipped.empty() ? std::string() : "; skipped: " + skipped) +
                                    " (name the input and output with --input-var and --output-var, e.g. "
                                    "--input-var 'rec.tau(1,:)')");
      r.needsMapping = true;
      return r;
    }

  IdData data;
  std::vector<double> u, y, t, a, ref;
  if (!readMatSeries(vars, path, in.expression, budget, u, fail)) return fail;
  if (!readMatSeries(vars, path, out.expression, budget, y, fail)) return fail;
  if (!armExpr.empty() && !readMatSeries(vars, path, armExpr, budget, a, fail)) return fail;
  if (!refExpr.empty() && !readMatSeries(vars, path, refExpr, budget, ref, fail)) return fail;
  for (const auto& [expr, v] : {std::pair<const std::string&, const std::vector<double>&>{out.expression, y},
                                {armExpr, a},
                                {refExpr, ref}})
    if (!expr.empty() && v.size() != u.size())
      return failure(path, 0, 0, expr,
                     "has " + std::to_string(v.size()) + " samples but '" + in.expression + "' has " +
                         std::to_string(u.size()));
  if (u.size() < 2) return failure(path, 0, 0, in.expression, "at least two samples are needed");
  data.sampleTime = options.sampleTime;
  // The sample time: the time variable, else the one given, else a scalar the file stores
  // under a usual name; never a silent guess.
  if (timeExpr.empty() && !(options.sampleTime > 0.0)) {
    for (const char* n : {"Ts", "ts", "dt", "sample_time", "sample_time_s", "Ts_s"}) {
      std::vector<double> v;
      for (const MatVariable& var : vars.variables())
        if (var.name == n && readPlainVector(vars, var, budget, v) && v.size() == 1 &&
            v[0] >= IdData::kMinSampleTime && v[0] <= 1e6) {
          data.sampleTime = v[0];
          data.setMeta("sample_time", std::string("from the variable ") + n);
          break;
        }
      if (data.sampleTime > 0.0) break;
    }
    if (!(data.sampleTime > 0.0)) {
      LogReadResult r = failure(path, 0, 0, {},
                                "the file stores no time (no variable time_s, Ts or dt): give the "
                                "sample time, e.g. --sample-time 0.0005 for 2 kHz, or name the time "
                                "with --time-var");
      r.needsSampleTime = true;
      return r;
    }
  }
  if (!timeExpr.empty()) {
    if (!readMatSeries(vars, path, timeExpr, budget, t, fail)) return fail;
    if (t.size() != u.size())
      return failure(path, 0, 0, timeExpr,
                     "has " + std::to_string(t.size()) + " samples but '" + in.expression + "' has " +
                         std::to_string(u.size()));
    auto sampleOf = [](std::size_t i) { return static_cast<int>(std::min<std::size_t>(i + 1, 2147483647u)); };
    auto allSamples = [&] {
      std::vector<int> idx(t.size());
      for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = sampleOf(i);
      return idx;
    };
    if (!io::checkTime(path, t, sampleOf, allSamples, 0, timeExpr, options, data, fail)) {
      fail.error.problem = "sample " + std::to_string(fail.error.line) + ": " + fail.error.problem;
      fail.error.line = 0;
      return fail;
    }
  }
  auto push = [&](const std::string& name, std::vector<double> v, ChannelRole role) {
    Channel c{name, unitFromColumnName(name), role, std::move(v)};
    data.channels.push_back(std::move(c));
    return static_cast<int>(data.channels.size() - 1);
  };
  MappedChannels found;
  found.input = push(inputNamed ? options.inputName : channelNameFor(in.expression), std::move(u), ChannelRole::Input);
  found.output = push(outputNamed ? options.outputName : channelNameFor(out.expression), std::move(y), ChannelRole::Output);
  if (!armExpr.empty()) found.arm = push(channelNameFor(armExpr), std::move(a), ChannelRole::None);
  if (!refExpr.empty()) found.reference = push(channelNameFor(refExpr), std::move(ref), ChannelRole::Reference);
  found.referenceSource = refExpr;
  found.inputSource = in.expression;
  found.outputSource = out.expression;
  found.armSource = armExpr;
  if (data.channels[static_cast<std::size_t>(found.output)].name == data.channels[static_cast<std::size_t>(found.input)].name)
    return failure(path, 0, 0, out.expression, "the input and the output are the same signal");
  // The file's other whole vectors of the same length are channels too.
  for (const MatVariable& v : vars.variables()) {
    const std::string name = v.name;
    if (name == in.expression || name == out.expression || name == timeExpr || name == armExpr || name == refExpr)
      continue;
    if ((inputNamed && name == options.inputName) || (outputNamed && name == options.outputName)) continue;
    if (data.indexOf(name) >= 0) continue;
    std::vector<double> vec;
    if (readPlainVector(vars, v, budget, vec) && vec.size() == data.samples())
      push(name, std::move(vec), name == columns::kAngleRef ? ChannelRole::Reference : ChannelRole::None);
  }
  if (data.channel(columns::kMotorVelocity) && in.expression == columns::kTorqueRef && !out.given &&
      !outputNamed && !m.convertsOutput())
    data.setRole(columns::kMotorVelocity, ChannelRole::Output);
  data.setMeta("source", std::filesystem::path(path).filename().string());
  data.setMeta("format", "MATLAB .mat");
  LogReadResult ok;
  std::string why;
  if (!applyMapping(data, found, m, true, ok.warnings, &why)) return failure(path, 0, 0, {}, why);
  if (!skippedList.empty()) {
    data.setMeta("skipped", skipped);
    for (const auto& s : skippedList) ok.warnings.push_back("skipped " + s + ": FlexArm does not read it");
  }
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

}  // namespace
}  // namespace flexarm
