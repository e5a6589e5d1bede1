// MATLAB .mat files through matio, after core/io/mat_check has bounded every size the file
// states: vectors named like the FlexArm columns, u/y, or the user's variables.
#include <matio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "core/io/input_file.h"
#include "core/io/log_io.h"
#include "core/io/mat_check.h"
#include "core/io/reader_support.h"

namespace flexarm {
namespace {

using io::failure;

// Reads a real numeric vector variable from an open .mat file.
bool readMatVector(mat_t* mat, const std::string& path, const std::string& name,
                   std::vector<double>& out, LogReadResult& fail, bool required) {
  matvar_t* var = Mat_VarRead(mat, name.c_str());
  if (!var) {
    if (required) fail = failure(path, 0, 0, name, "the variable '" + name + "' is missing or damaged");
    return false;
  }
  struct Free {
    matvar_t* v;
    ~Free() { Mat_VarFree(v); }
  } guard{var};
  if (var->isComplex || var->rank != 2 || (var->dims[0] != 1 && var->dims[1] != 1) ||
      var->data == nullptr) {
    fail = failure(path, 0, 0, name, "the variable must be a real vector");
    return false;
  }
  const std::size_t n = var->dims[0] * var->dims[1];
  out.resize(n);
  auto copy = [&](auto* p) {
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<double>(p[i]);
  };
  switch (var->data_type) {
    case MAT_T_DOUBLE: copy(static_cast<const double*>(var->data)); break;
    case MAT_T_SINGLE: copy(static_cast<const float*>(var->data)); break;
    case MAT_T_INT32: copy(static_cast<const std::int32_t*>(var->data)); break;
    case MAT_T_INT16: copy(static_cast<const std::int16_t*>(var->data)); break;
    default:
      fail = failure(path, 0, 0, name, "the variable is not a numeric vector");
      return false;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(out[i])) {
      fail = failure(path, 0, 0, name,
                     "element " + std::to_string(i + 1) + " is not a finite number");
      return false;
    }
  return true;
}

}  // namespace

LogReadResult readMat(const std::string& path, const LogReadOptions& options) {
  LogReadResult fail;
  std::uint64_t budget = 0;
  {
    // The structure is checked on the bytes, then released: matio reads the file itself.
    FileBytes bytes;
    std::string problem;
    if (!readInputFile(path, options.maxFileBytes, bytes, &problem))
      return failure(path, 0, 0, {}, problem);
    // zlib inflates at most 1032 times its input: no honest variable is larger than that.
    budget = std::min<std::uint64_t>(options.maxFileBytes, 1032ull * bytes.size + 65536);
    const MatCheck check = checkMatFile(bytes.view(), budget);
    if (!check.ok) return failure(path, 0, 0, {}, check.problem);
  }
  // matio prints its own complaints to stderr; FlexArm reports one sentence instead.
  Mat_LogInitFunc("flexarm", [](int, char*) {});
  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  if (!mat)
    return failure(path, 0, 0, {},
                   "not a readable MATLAB .mat file (damaged, or not a .mat file at all)");
  struct Close {
    mat_t* m;
    ~Close() { Mat_Close(m); }
  } guard{mat};

  // Variable names: the FlexArm column names, or u/y, or the user's mapping; with the bytes
  // their elements take (v7.3 files are bounded here, from their dimensions).
  std::vector<std::string> names;
  std::map<std::string, double> bytesOf;
  while (matvar_t* info = Mat_VarReadNextInfo(mat)) {
    if (info->name) {
      names.emplace_back(info->name);
      double elements = 1.0;
      for (int d = 0; d < info->rank && info->dims; ++d) elements *= static_cast<double>(info->dims[d]);
      bytesOf[info->name] = 8.0 * elements;
    }
    Mat_VarFree(info);
  }
  Mat_Rewind(mat);
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
  for (const auto& [name, bytes] : bytesOf)
    if (bytes > static_cast<double>(budget))
      return failure(path, 0, 0, name,
                     "the variable claims " + humanBytes(static_cast<std::uint64_t>(bytes)) +
                         ", more than the " + humanBytes(budget) + " a file of this size can hold");

  IdData data;
  std::vector<double> u, y, t;
  if (!readMatVector(mat, path, uName, u, fail, true)) return fail;
  if (!readMatVector(mat, path, yName, y, fail, true)) return fail;
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
      if (has(n) && readMatVector(mat, path, n, v, ignore, false) && v.size() == 1 &&
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
    if (!readMatVector(mat, path, columns::kTime, t, fail, true)) return fail;
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
    if (readMatVector(mat, path, n, v, ignore, false) && v.size() == data.samples())
      push(n, std::move(v), n == columns::kAngleRef ? ChannelRole::Reference : ChannelRole::None);
  }
  if (data.channel(columns::kMotorVelocity) && uName == columns::kTorqueRef &&
      options.outputVariable.empty() && !outputNamed)
    data.setRole(columns::kMotorVelocity, ChannelRole::Output);
  data.setMeta("source", std::filesystem::path(path).filename().string());
  data.setMeta("format", "MATLAB .mat");
  LogReadResult ok;
  ok.ok = true;
  ok.data = std::move(data);
  return ok;
}

}  // namespace flexarm
