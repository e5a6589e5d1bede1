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
#include <limits>
#include <map>
#include <type_traits>
#include <vector>

#include "core/common/parallel.h"
#include "core/io/input_file.h"
#include "core/io/log_io.h"
#include "core/io/mat_check.h"
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

// One variable's shape and class (MATLAB's numbering, which matio's MAT_C_* follow).
struct VarInfo {
  bool complex = false;
  std::vector<std::uint64_t> dims;
  unsigned arrayClass = 0;
};

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

// The n elements of a checked level-5 variable as doubles; false for a number type that holds
// no numbers (text stored in a numeric array).
template <class Class>
bool decodeLevel5(const MatVariable& v, bool swap, double* out, std::size_t n) {
  const unsigned char* p = v.data;
  switch (v.dataType) {
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

// The variables of a checked file: a level-5 file is decoded from the bytes the check has
// just walked (one read of the file); level 4 and the HDF5-based v7.3 are read by matio.
// Where a checked level-5 file's bytes are: `base` holds what the check loaded, and the rest
// (numeric data) is read from the file when a variable is read.
struct Level5Source {
  const InputFile* file = nullptr;  // null: base holds the whole file
  const unsigned char* base = nullptr;
  std::uint64_t size = 0;
  MatLoad load;
};

class MatVariables {
 public:
  MatVariables(const MatCheck& check, mat_t* mat, Level5Source source = {})
      : check_(check), mat_(mat), source_(std::move(source)) {}
  ~MatVariables() { Mat_VarFree(var_); }
  MatVariables(const MatVariables&) = delete;
  MatVariables& operator=(const MatVariables&) = delete;

  // Every variable's name and the bytes its elements take as doubles (a v7.3 file is bounded
  // here, from its dimensions).
  void list(std::vector<std::string>& names, std::map<std::string, double>& bytesOf) {
    const auto add = [&](const std::string& name, double elements) {
      names.push_back(name);
      bytesOf[name] = 8.0 * elements;
    };
    if (!mat_) {
      for (const MatVariable& v : check_.variables) {
        double elements = 1.0;
        for (auto d : v.dims) elements *= static_cast<double>(d);
        if (!v.name.empty()) add(v.name, elements);
      }
      return;
    }
    while (matvar_t* info = Mat_VarReadNextInfo(mat_)) {
      if (info->name) {
        double elements = 1.0;
        for (int d = 0; d < info->rank && info->dims; ++d) elements *= static_cast<double>(info->dims[d]);
        add(info->name, elements);
      }
      Mat_VarFree(info);
    }
    Mat_Rewind(mat_);
  }

  // Finds `name`; false when the file has no such variable (or matio cannot describe it).
  bool find(const std::string& name, VarInfo& info) {
    if (!mat_) {
      for (const MatVariable& v : check_.variables)
        if (v.name == name) {
          level5_ = &v;
          info = {v.complex, v.dims, v.arrayClass};
          return true;
        }
      return false;
    }
    Mat_VarFree(var_);
    var_ = Mat_VarReadInfo(mat_, name.c_str());
    if (!var_) return false;
    info.complex = var_->isComplex != 0;
    info.arrayClass = static_cast<unsigned>(var_->class_type);
    info.dims.clear();
    for (int d = 0; d < var_->rank && var_->dims; ++d) info.dims.push_back(var_->dims[d]);
    return true;
  }

  // The n elements of the variable found last, as doubles, straight into out (matio converts
  // what the file stores to the variable's class; other classes than double go through one
  // buffer of their own). False when the data cannot be read.
  bool read(double* out, std::size_t n) {
    const unsigned cls = mat_ ? static_cast<unsigned>(var_->class_type) : level5_->arrayClass;
    switch (cls) {
      case MAT_C_DOUBLE: return readAs<double>(out, n);
      case MAT_C_SINGLE: return readAs<float>(out, n);
      case MAT_C_INT32: return readAs<std::int32_t>(out, n);
      case MAT_C_INT16: return readAs<std::int16_t>(out, n);
      default: return false;
    }
  }

 private:
  template <class T>
  bool readAs(double* out, std::size_t n) {
    if (!mat_) {
      const MatVariable& v = *level5_;
      const unsigned char* base = source_.base;
      const std::less<const unsigned char*> before;  // a total order, also for inflated bodies
      if (source_.file && !before(v.data, base) && before(v.data, base + source_.size)) {
        // Data the check left in the file: doubles in this machine's byte order go straight
        // to `out` (a large variable in parts on every core: one core does not saturate the
        // memory), anything else is loaded and decoded.
        const auto offset = static_cast<std::uint64_t>(v.data - base);
        const std::uint64_t bytes = n * matTypeSize(v.dataType);
        if (bytes > source_.size - offset) return false;
        if (std::is_same_v<T, double> && v.dataType == 9 && !check_.swapBytes) {
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
      return decodeLevel5<T>(v, check_.swapBytes, out, n);
    }
    constexpr bool direct = std::is_same_v<T, double>;
    std::vector<T> own(direct ? 0 : n);
    void* into = direct ? static_cast<void*>(out) : static_cast<void*>(own.data());
    if (n > static_cast<std::size_t>(INT_MAX) ||
        Mat_VarReadDataLinear(mat_, var_, into, 0, 1, static_cast<int>(n)) != 0)
      return false;
    if constexpr (!direct) std::copy(own.begin(), own.end(), out);
    return true;
  }

  const MatCheck& check_;
  mat_t* mat_ = nullptr;
  Level5Source source_;
  matvar_t* var_ = nullptr;
  const MatVariable* level5_ = nullptr;
};

bool isReadableClass(unsigned cls) {
  return cls == MAT_C_DOUBLE || cls == MAT_C_SINGLE || cls == MAT_C_INT32 || cls == MAT_C_INT16;
}

// Reads a real numeric vector variable straight into `out`. The sizes were bounded by
// checkMatFile and the budget.
bool readMatVector(MatVariables& vars, const std::string& path, const std::string& name,
                   std::vector<double>& out, LogReadResult& fail, bool required) {
  VarInfo var;
  if (!vars.find(name, var)) {
    if (required) fail = failure(path, 0, 0, name, "the variable '" + name + "' is missing or damaged");
    return false;
  }
  if (var.complex || var.dims.size() != 2 || (var.dims[0] != 1 && var.dims[1] != 1) ||
      var.dims[0] * var.dims[1] == 0) {
    fail = failure(path, 0, 0, name, "the variable must be a real vector");
    return false;
  }
  if (!isReadableClass(var.arrayClass)) {
    fail = failure(path, 0, 0, name, "the variable is not a numeric vector");
    return false;
  }
  const std::size_t n = var.dims[0] * var.dims[1];
  sizeOnHugePages(out, n);
  if (!vars.read(out.data(), n)) {
    fail = failure(path, 0, 0, name, "the variable's data cannot be read (the file is damaged)");
    return false;
  }
  // x - x is 0 for a finite x and NaN otherwise: one vectorized sum finds any non-finite one.
  const Eigen::Map<const Eigen::ArrayXd> x(out.data(), static_cast<Eigen::Index>(n));
  if (!std::isfinite((x - x).sum())) {
    const auto bad = std::find_if(out.begin(), out.end(), [](double v) { return !std::isfinite(v); });
    fail = failure(path, 0, 0, name,
                   "element " + std::to_string(bad - out.begin() + 1) + " is not a finite number");
    return false;
  }
  return true;
}

}  // namespace

LogReadResult readMat(const std::string& path, const LogReadOptions& options) {
  InputFile file;
  std::string problem;
  if (!file.open(path, options.maxFileBytes, &problem)) return failure(path, 0, 0, {}, problem);
  return io::readMatFile(file, path, options);
}

LogReadResult io::readMatFile(const InputFile& file, const std::string& path, const LogReadOptions& options) {
  LogReadResult fail;
  // The structure is checked on the file's bytes, which a level-5 file is then decoded from.
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
  if (!check.ok) return failure(path, 0, 0, {}, check.problem);
  mat_t* mat = nullptr;
  if (check.kind != MatKind::V5) {
    bytes.reset();  // matio reads the file itself
    // matio prints its own complaints to stderr; FlexArm reports one sentence instead.
    Mat_LogInitFunc("flexarm", [](int, char*) {});
    mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
    if (!mat)
      return failure(path, 0, 0, {},
                     "not a readable MATLAB .mat file (damaged, or not a .mat file at all)");
  }
  struct Close {
    mat_t* m;
    ~Close() {
      if (m) Mat_Close(m);
    }
  } guard{mat};
  MatVariables vars(check, mat,
                    Level5Source{&file, reinterpret_cast<const unsigned char*>(bytes.get()), size, load});

  // Variable names: the FlexArm column names, or u/y, or the user's mapping; with the bytes
  // their elements take.
  std::vector<std::string> names;
  std::map<std::string, double> bytesOf;
  vars.list(names, bytesOf);
  auto has = [&](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  // A channel name the user chose (not the default u / y) names the variable when no variable
  // was named, and the channel either way.
  const LogReadOptions defaults;
  const bool inputNamed = options.inputName != defaults.inputName && !options.inputName.empty();
  const bool outputNamed = options.outputName != defaults.outputName && !options.outputName.empty();
  std::string uName = options.inputVariable, yName = options.outputVariable;
  if (uName.empty() && inputNamed && has(options.inputName)) uName = options.inputName;
  if (yName.empty() && outputNamed && has(options.outputName)) yName = options.outputName;
  if (uName.empty()) uName = has(columns::kTorqueRef) ? columns::kTorqueRef : "u";
  if (yName.empty()) yName = has(columns::kMotorAngle) ? columns::kMotorAngle : "y";
  if (names.empty())
    return failure(path, 0, 0, {}, "the .mat file holds no variables FlexArm can read");
  for (const auto* wanted : {&uName, &yName})
    if (!has(*wanted)) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      return failure(path, 0, 0, *wanted,
                     "the variable '" + *wanted + "' is missing; the file holds " + list +
                         " (name the input and output with --input-var and --output-var)");
    }
  for (const auto& [name, claimed] : bytesOf)
    if (claimed > static_cast<double>(budget))
      return failure(path, 0, 0, name,
                     "the variable claims " + humanBytes(static_cast<std::uint64_t>(claimed)) +
                         ", more than the " + humanBytes(budget) + " a file of this size can hold");

  IdData data;
  std::vector<double> u, y, t;
  if (!readMatVector(vars, path, uName, u, fail, true)) return fail;
  if (!readMatVector(vars, path, yName, y, fail, true)) return fail;
  if (u.size() != y.size())
    return failure(path, 0, 0, yName,
                   "has " + std::to_string(y.size()) + " samples but '" + uName + "' has " +
                       std::to_string(u.size()));
  if (u.size() < 2) return failure(path, 0, 0, uName, "at least two samples are needed");
  data.sampleTime = options.sampleTime;
  // The sample time: the time variable, else the one given, else a scalar the file stores
  // under a usual name; never a silent guess.
  if (!has(columns::kTime) && !(options.sampleTime > 0.0)) {
    for (const char* n : {"Ts", "ts", "dt", "sample_time", "sample_time_s", "Ts_s"}) {
      std::vector<double> v;
      LogReadResult ignore;
      if (has(n) && readMatVector(vars, path, n, v, ignore, false) && v.size() == 1 &&
          v[0] >= IdData::kMinSampleTime && v[0] <= 1e6) {
        data.sampleTime = v[0];
        data.setMeta("sample_time", std::string("from the variable ") + n);
        break;
      }
    }
    if (!(data.sampleTime > 0.0)) {
      LogReadResult r = failure(path, 0, 0, {},
                                "the file stores no time (no variable time_s, Ts or dt): give the "
                                "sample time, e.g. --sample-time 0.0005 for 2 kHz");
      r.needsSampleTime = true;
      return r;
    }
  }
  if (has(columns::kTime)) {
    if (!readMatVector(vars, path, columns::kTime, t, fail, true)) return fail;
    if (t.size() != u.size())
      return failure(path, 0, 0, columns::kTime, "has a different length than the signals");
    auto sampleOf = [](std::size_t i) { return static_cast<int>(std::min<std::size_t>(i + 1, 2147483647u)); };
    auto allSamples = [&] {
      std::vector<int> idx(t.size());
      for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = sampleOf(i);
      return idx;
    };
    if (!io::checkTime(path, t, sampleOf, allSamples, 0, columns::kTime, options, data, fail)) {
      fail.error.problem = "sample " + std::to_string(fail.error.line) + ": " + fail.error.problem;
      fail.error.line = 0;
      return fail;
    }
  }
  auto push = [&](const std::string& name, std::vector<double> v, ChannelRole role) {
    Channel c{name, unitFromColumnName(name), role, std::move(v)};
    data.channels.push_back(std::move(c));
  };
  push(inputNamed ? options.inputName : uName, std::move(u), ChannelRole::Input);
  push(outputNamed ? options.outputName : yName, std::move(y), ChannelRole::Output);
  for (const auto& n : names) {
    if (n == uName || n == yName || n == columns::kTime) continue;
    if ((inputNamed && n == options.inputName) || (outputNamed && n == options.outputName)) continue;
    std::vector<double> v;
    LogReadResult ignore;
    if (readMatVector(vars, path, n, v, ignore, false) && v.size() == data.samples())
      push(n, std::move(v), n == columns::kAngleRef ? ChannelRole::Reference : ChannelRole::None);
  }
  if (data.channel(columns::kMotorVelocity) && uName == columns::kTorqueRef &&
      options.outputVariable.empty() && !outputNamed)
    data.setRole(columns::kMotorVelocity, ChannelRole::Output);
  data.setMeta("source", std::filesystem::path(path).filename().string());
  data.setMeta("format", "MATLAB .mat");
  if (!check.skipped.empty()) {  // v7.3 variables that are not numeric arrays, named and ignored
    std::string list;
    for (const auto& v : check.skipped) list += (list.empty() ? "" : ", ") + v;
    data.setMeta("skipped_variables", list);
  }
  LogReadResult ok;
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

}  // namespace flexarm
