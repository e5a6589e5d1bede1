// Writing files so that a failure never leaves a half-written or replaced file: a temporary
// sibling, every write checked, flushed to the disk, then renamed over the target.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>

#include "core/io/input_file.h"
#include "core/io/log_io.h"

namespace flexarm {
namespace {

std::string writeProblem(const std::string& path, int error) {
  std::string s = "writing " + path + " failed: " + std::strerror(error);
  if (error == ENOSPC || error == EDQUOT) s += " (the disk is full)";
  if (error == EFBIG) s += " (the file is larger than this system allows)";
  return s + "; the previous file, if any, is unchanged";
}

}  // namespace

bool writeFileAtomically(
    const std::string& path,
    const std::function<void(const std::function<void(std::string_view)>&)>& produce,
    std::string* why) {
  auto fail = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    return fail(path + " is " + fileKind(st.st_mode) +
                ", not a regular file; FlexArm writes only regular files and does not replace it");
  static std::atomic<unsigned> counter{0};
  const std::string tmp =
      path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) return fail("cannot create " + tmp + ": " + std::strerror(errno));
  int error = 0;
  auto sink = [&](std::string_view bytes) {
    while (!bytes.empty() && error == 0) {
      const ssize_t w = ::write(fd, bytes.data(), bytes.size());
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) {
        error = errno;
        break;
      }
      bytes.remove_prefix(static_cast<std::size_t>(w));
    }
  };
  produce(sink);
  if (error == 0 && ::fsync(fd) != 0) error = errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlink(tmp.c_str());
    return fail(writeProblem(path, error));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return fail("cannot rename " + tmp + " to " + path + ": " + std::strerror(e));
  }
  return true;
}

bool writeFileAtomically(const std::string& path, const std::string& text, std::string* why) {
  return writeFileAtomically(
      path, [&](const std::function<void(std::string_view)>& sink) { sink(text); }, why);
}

bool writeFlexArmCsv(const IdData& data, const std::string& path, ReadError* error) {
  std::string why;
  if (!data.isValid(&why)) {
    if (error) *error = ReadError{path, 0, 0, {}, "refusing to write invalid data: " + why};
    return false;
  }
  auto produce = [&](const std::function<void(std::string_view)>& sink) {
    std::string out;
    out.reserve(1 << 20);
    out += "# flexarm-log: 1\n";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.12g", 1.0 / data.sampleTime);
    out += std::string("# sample_rate_hz: ") + buf + "\n";
    for (const auto& [k, v] : data.metadata) {
      if (k == "flexarm-log" || k == "sample_rate_hz") continue;
      std::string value = v;
      std::replace(value.begin(), value.end(), '\n', ' ');
      out += "# " + k + ": " + value + "\n";
    }
    out += columns::kTime;
    for (const auto& c : data.channels) out += "," + c.name;
    out += '\n';
    const std::size_t n = data.samples();
    for (std::size_t i = 0; i < n; ++i) {
      // Time with fixed decimals avoids long binary tails such as 0.30000000000000004.
      int len = std::snprintf(buf, sizeof buf, "%.9f", data.timeAt(i));
      out.append(buf, static_cast<std::size_t>(len));
      for (const auto& c : data.channels) {
        out += ',';
        auto res = std::to_chars(buf, buf + sizeof buf, c.values[i]);
        out.append(buf, res.ptr);
      }
      out += '\n';
      if (out.size() > (1u << 20) - 4096) {  // written in pieces of about 1 MiB
        sink(out);
        out.clear();
      }
    }
    sink(out);
  };
  if (!writeFileAtomically(path, produce, &why)) {
    if (error) *error = ReadError{path, 0, 0, {}, why};
    return false;
  }
  return true;
}

}  // namespace flexarm
