// Writing files so that a failure never leaves a half-written or replaced file: a temporary
// sibling made exclusively under an unpredictable name, every write checked, flushed to the
// disk, then renamed over the target. Every file FlexArm writes goes through here.
#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <random>

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

// A name no other process can guess: ".NAME.tmp-" and 16 random hex digits, in the target's
// folder (a rename within one file system is atomic).
std::string temporarySibling(const std::string& path) {
  static const char* hex = "0123456789abcdef";
  std::uint64_t bits = 0;
  if (::getrandom(&bits, sizeof bits, 0) != static_cast<ssize_t>(sizeof bits)) {
    std::random_device device;
    bits = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }
  std::string suffix(16, '0');
  for (char& c : suffix) {
    c = hex[bits & 15u];
    bits >>= 4;
  }
  const std::size_t slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return folder + "." + name + ".tmp-" + suffix;
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
  if (path.empty() || path.back() == '/') return fail("'" + path + "' names no file to write");
  // The target is replaced, never written through: a link planted at its name (or anything but
  // a regular file) is refused, and the temporary file is made afresh (O_EXCL) under a name no
  // one can plant a link at first (O_NOFOLLOW as well).
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISLNK(st.st_mode))
      return fail(path + " is a symbolic link; FlexArm writes only regular files and does not follow or "
                         "replace a link");
    return fail(path + " is " + fileKind(st.st_mode) +
                ", not a regular file; FlexArm writes only regular files and does not replace it");
  }
  std::string tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 8 && fd < 0; ++attempt) {
    tmp = temporarySibling(path);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) return fail("cannot create a temporary file beside " + path + ": " + std::strerror(errno));
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
