#pragma once
// Opening input files without trusting them: only regular files are read (a device such as
// /dev/zero, a pipe or a directory is refused before a byte is read), never more than a
// budget derived from the file's real size, and text in an encoding FlexArm does not read
// (UTF-16, a byte-order mark, binary data) is named as such.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace flexarm {

// Releases a FileBytes buffer: a mapping of `mapped` bytes, or new[] when mapped is 0.
struct FileBufferDeleter {
  std::size_t mapped = 0;
  void operator()(char* p) const;
};

// The bytes of a whole file, read once (not zero-filled first: large logs are read at the
// speed of the disk cache).
struct FileBytes {
  std::unique_ptr<char, FileBufferDeleter> data;
  std::size_t size = 0;
  std::string_view view() const { return {data.get(), size}; }
};

// A buffer of n + 1 bytes whose pages cost nothing until first written, for a file of n bytes
// read only in the parts that are needed.
std::unique_ptr<char, FileBufferDeleter> sparseFileBuffer(std::size_t n);

// Asks the kernel to back [p, p + bytes) with huge pages where it can (a large buffer then
// costs hundreds of page faults instead of hundreds of thousands); no effect on small ones.
void preferHugePages(void* p, std::size_t bytes);

// Checks that path names an existing regular file of at most maxBytes and gives its size;
// otherwise false with a sentence ("the file does not exist", "is a character device, not a
// regular file ...", "the file is 3.0 GiB, larger than ...").
bool checkInputFile(const std::string& path, std::uint64_t maxBytes, std::uint64_t* size,
                    std::string* problem);

// Reads a whole regular file of at most maxBytes. The file is opened first and then checked
// (no window between check and open), and at most the size it had when opened is read.
bool readInputFile(const std::string& path, std::uint64_t maxBytes, FileBytes& out,
                   std::string* problem);

// An open regular file of at most maxBytes, for readers that take it in parts rather than
// whole (the same checks as readInputFile). Closed when destroyed.
class InputFile {
 public:
  InputFile() = default;
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  // False with a sentence as readInputFile gives.
  bool open(const std::string& path, std::uint64_t maxBytes, std::string* problem);
  std::uint64_t size() const { return size_; }  // as it was when opened
  // Reads up to n bytes at offset into dst (retrying interrupted reads); the count read, 0 at
  // the end of the file, or -1 with errno set.
  long long readAt(std::uint64_t offset, char* dst, std::size_t n) const;
  // Reads n bytes at offset into dst, as many calls as it takes; the count read, less than n
  // only at the end of the file or on a failed read.
  std::size_t readFully(std::uint64_t offset, char* dst, std::size_t n) const;
  // The whole file as it is now (at most the size it had when opened), as readInputFile gives
  // it; false with a sentence when a read fails.
  bool readAll(FileBytes& out, std::string* problem) const;

 private:
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// A sentence naming the encoding of text that is not plain ASCII/UTF-8 without BOM (UTF-16
// or UTF-32 with or without BOM, a UTF-8 BOM, binary data with NUL bytes), judged from the
// first bytes; empty for plain text.
std::string textEncodingProblem(std::string_view head);

// What a stat mode names when it is not a regular file: "a character device", "a pipe", ...
const char* fileKind(unsigned mode);

// "3.0 GiB", "12.5 MiB", "512 bytes".
std::string humanBytes(std::uint64_t n);

}  // namespace flexarm
