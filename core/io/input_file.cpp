#include "core/io/input_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

namespace flexarm {
namespace {

std::string notRegular(mode_t mode) {
  return std::string("is ") + fileKind(mode) +
         ", not a regular file; FlexArm reads logs and sessions from regular files only "
         "(copy the data into a file first)";
}

std::string sizeProblem(std::uint64_t size, std::uint64_t maxBytes) {
  return "the file is " + humanBytes(size) + ", larger than the " + humanBytes(maxBytes) +
         " FlexArm reads at once; cut it into shorter logs or decimate it first";
}

std::string openProblem(int error) {
  if (error == ENOENT || error == ENOTDIR) return "the file does not exist";
  return std::string("cannot open the file: ") + std::strerror(error);
}

}  // namespace

const char* fileKind(unsigned mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a pipe";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string humanBytes(std::uint64_t n) {
  char buf[64];
  if (n >= (1ull << 30))
    std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(n) / (1ull << 30));
  else if (n >= (1ull << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(n) / (1ull << 20));
  else
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(n));
  return buf;
}

void FileBufferDeleter::operator()(char* p) const {
  if (mapped)
    ::munmap(p, mapped);
  else
    delete[] p;
}

void preferHugePages(void* p, std::size_t bytes) {
  constexpr std::uintptr_t kHuge = 2u << 20;
  if (bytes < 4 * kHuge) return;
  const auto b = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const auto e = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
}

namespace {

// A buffer of n + 1 bytes: a huge-page friendly mapping for large files, else new[].
std::unique_ptr<char, FileBufferDeleter> allocateBuffer(std::size_t n) {
  if (n >= (8u << 20)) {
    const std::size_t len = n + 1;
    void* p = ::mmap(nullptr, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p != MAP_FAILED) {
      preferHugePages(p, len);
      return std::unique_ptr<char, FileBufferDeleter>(static_cast<char*>(p), FileBufferDeleter{len});
    }
  }
  return std::unique_ptr<char, FileBufferDeleter>(new char[n + 1], FileBufferDeleter{0});
}

}  // namespace

std::unique_ptr<char, FileBufferDeleter> sparseFileBuffer(std::size_t n) {
  if (n >= (1u << 20)) {  // a private anonymous mapping: no page is zeroed before it is used
    const std::size_t len = n + 1;
    void* p = ::mmap(nullptr, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p != MAP_FAILED)
      return std::unique_ptr<char, FileBufferDeleter>(static_cast<char*>(p), FileBufferDeleter{len});
  }
  return std::unique_ptr<char, FileBufferDeleter>(new char[n + 1](), FileBufferDeleter{0});
}

namespace {

// The checks on what stat says: a regular file of at most maxBytes.
bool acceptable(int statResult, const struct stat& st, std::uint64_t maxBytes, std::uint64_t& size,
                std::string* problem) {
  if (statResult != 0) {
    if (problem) *problem = openProblem(errno);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    if (problem) *problem = notRegular(st.st_mode);
    return false;
  }
  size = static_cast<std::uint64_t>(st.st_size);
  if (size > maxBytes) {
    if (problem) *problem = sizeProblem(size, maxBytes);
    return false;
  }
  return true;
}

}  // namespace

bool checkInputFile(const std::string& path, std::uint64_t maxBytes, std::uint64_t* size,
                    std::string* problem) {
  struct stat st {};
  std::uint64_t bytes = 0;
  if (!acceptable(::stat(path.c_str(), &st), st, maxBytes, bytes, problem)) return false;
  if (size) *size = bytes;
  return true;
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool InputFile::open(const std::string& path, std::uint64_t maxBytes, std::string* problem) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  size_ = 0;
  // O_NONBLOCK: opening a pipe must not wait for a writer; it is refused just below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (problem) *problem = openProblem(errno);
    return false;
  }
  struct stat st {};
  if (!acceptable(::fstat(fd, &st), st, maxBytes, size_, problem)) {
    ::close(fd);
    size_ = 0;
    return false;
  }
  fd_ = fd;
  return true;
}

long long InputFile::readAt(std::uint64_t offset, char* dst, std::size_t n) const {
  for (;;) {
    const ssize_t r = ::pread(fd_, dst, n, static_cast<off_t>(offset));
    if (r < 0 && errno == EINTR) continue;
    return r;
  }
}

std::size_t InputFile::readFully(std::uint64_t offset, char* dst, std::size_t n) const {
  std::size_t got = 0;
  while (got < n) {
    const long long r = readAt(offset + got, dst + got, n - got);
    if (r <= 0) break;
    got += static_cast<std::size_t>(r);
  }
  return got;
}

bool readInputFile(const std::string& path, std::uint64_t maxBytes, FileBytes& out,
                   std::string* problem) {
  InputFile file;
  return file.open(path, maxBytes, problem) && file.readAll(out, problem);
}

bool InputFile::readAll(FileBytes& out, std::string* problem) const {
  const InputFile& file = *this;
  const std::uint64_t bytes = size_;
  out.size = 0;
  out.data = allocateBuffer(static_cast<std::size_t>(bytes));
  // A large file is read in parts by several threads at once: copying from the disk cache is
  // a good part of reading a log, and one core does not saturate the memory.
  const unsigned parts =
      bytes > (16u << 20) ? std::clamp(std::thread::hardware_concurrency(), 1u, 4u) : 1u;
  std::vector<std::size_t> got(parts, 0);
  std::vector<int> errors(parts, 0);
  auto readPart = [&](unsigned k) {
    const std::size_t begin = static_cast<std::size_t>(bytes * k / parts);
    const std::size_t end = static_cast<std::size_t>(bytes * (k + 1) / parts);
    while (begin + got[k] < end) {
      const long long r = file.readAt(begin + got[k], out.data.get() + begin + got[k], end - begin - got[k]);
      if (r < 0) {
        errors[k] = errno;
        return;
      }
      if (r == 0) return;  // the file shrank meanwhile
      got[k] += static_cast<std::size_t>(r);
    }
  };
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < parts; ++k) pool.emplace_back(readPart, k);
  readPart(0);
  for (auto& t : pool) t.join();
  std::size_t total = 0;
  for (unsigned k = 0; k < parts; ++k) {
    if (errors[k] != 0) {
      if (problem) *problem = std::string("reading the file failed: ") + std::strerror(errors[k]);
      out.data.reset();
      return false;
    }
    total += got[k];
    if (got[k] != static_cast<std::size_t>(bytes * (k + 1) / parts - bytes * k / parts)) break;
  }
  // A file that shrank while being read keeps only its first, contiguous part.
  out.data.get()[total] = '\0';
  out.size = total;
  return true;
}

std::string textEncodingProblem(std::string_view head) {
  auto starts = [&](std::initializer_list<unsigned char> bytes) {
    if (head.size() < bytes.size()) return false;
    std::size_t i = 0;
    for (unsigned char b : bytes)
      if (static_cast<unsigned char>(head[i++]) != b) return false;
    return true;
  };
  const char* save =
      "; save it as plain text (ASCII or UTF-8 without byte-order mark, e.g. 'CSV' rather "
      "than 'Unicode text')";
  if (starts({0xFF, 0xFE, 0x00, 0x00}) || starts({0x00, 0x00, 0xFE, 0xFF}))
    return std::string("the file is UTF-32 text (it starts with a UTF-32 byte-order mark), "
                       "which FlexArm does not read") + save;
  if (starts({0xFF, 0xFE}) || starts({0xFE, 0xFF}))
    return std::string("the file is UTF-16 text (it starts with a UTF-16 byte-order mark), "
                       "which FlexArm does not read") + save;
  if (starts({0xEF, 0xBB, 0xBF}))
    return std::string("the file starts with a UTF-8 byte-order mark (BOM), which FlexArm "
                       "logs do not have") + save;
  const std::size_t n = std::min<std::size_t>(head.size(), 4096);
  std::size_t zeros = 0, oddZeros = 0, evenZeros = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (head[i] == '\0') {
      ++zeros;
      (i % 2 ? oddZeros : evenZeros)++;
    }
  const std::string_view first = head.substr(0, n);
  if (const std::size_t cr = first.find('\r');
      zeros == 0 && cr != std::string_view::npos && cr + 1 < first.size() && first.find('\n') == std::string_view::npos)
    return "the file's lines end in a carriage return alone (CR, as classic Mac OS wrote text), which FlexArm "
           "does not read; save it with LF or CR LF line ends (e.g. tr '\\r' '\\n' < old > new)";
  if (zeros == 0) return {};
  if (n >= 4 && (oddZeros >= n / 2 - 1 || evenZeros >= n / 2 - 1) && zeros <= n / 2 + 1)
    return std::string("the file looks like UTF-16 text (every other byte is zero), which "
                       "FlexArm does not read") + save;
  return "the file holds binary data (zero bytes), not text";
}

}  // namespace flexarm
