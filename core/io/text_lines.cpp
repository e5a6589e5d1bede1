#include "core/io/text_lines.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

namespace flexarm::textio {

std::string trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return std::string(s.substr(b, e - b));
}

bool isBlank(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c == ' ' || c == '\t' || c == '\r'; });
}

FieldStatus parseNumber(std::string_view field, double& value) {
  std::size_t b = 0, e = field.size();
  while (b < e && (field[b] == ' ' || field[b] == '\t')) ++b;
  while (e > b && (field[e - 1] == ' ' || field[e - 1] == '\t')) --e;
  if (b == e) return FieldStatus::Empty;
  const char* first = field.data() + b;
  const char* last = field.data() + e;
  if (*first == '+') ++first;  // from_chars does not accept a leading '+'
  auto res = std::from_chars(first, last, value);
  if (res.ec == std::errc::result_out_of_range) return FieldStatus::NotFinite;
  if (res.ec != std::errc() || res.ptr != last) return FieldStatus::NotNumber;
  if (!std::isfinite(value)) return FieldStatus::NotFinite;
  return FieldStatus::Ok;
}

std::string fieldProblem(FieldStatus s, std::string_view field) {
  switch (s) {
    case FieldStatus::Empty: return "the field is empty";
    case FieldStatus::NotNumber: return "'" + trim(field) + "' is not a number";
    case FieldStatus::NotFinite: return "'" + trim(field) + "' is not a finite number";
    case FieldStatus::Ok: break;
  }
  return {};
}

void splitFields(std::string_view line, char delimiter, std::vector<std::string_view>& out) {
  out.clear();
  if (delimiter) {
    std::size_t start = 0;
    for (;;) {
      std::size_t p = line.find(delimiter, start);
      if (p == std::string_view::npos) {
        out.push_back(line.substr(start));
        return;
      }
      out.push_back(line.substr(start, p - start));
      start = p + 1;
    }
  }
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= line.size()) break;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
}

bool parsePlainRow(std::string_view line, std::vector<double>& row) {
  const char* p = line.data();
  const char* const end = p + line.size();
  const std::size_t n = row.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto res = std::from_chars(p, end, row[i]);
    if (res.ec != std::errc() || !std::isfinite(row[i])) return false;
    p = res.ptr;
    if (i + 1 < n) {
      if (p == end || *p != ',') return false;
      ++p;
    }
  }
  return p == end;
}

LineReader::~LineReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool LineReader::open(const std::string& path, std::uint64_t offset) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) return false;
  if (offset > 0 && ::lseek(fd_, static_cast<off_t>(offset), SEEK_SET) < 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    errno = e;
    return false;
  }
  base_ = offset;
  return true;
}

bool LineReader::next(std::string_view& line) {
  for (;;) {
    const char* b = buffer_.data() + begin_;
    if (const void* nl = std::memchr(b, '\n', end_ - begin_)) {
      line = std::string_view(b, static_cast<std::size_t>(static_cast<const char*>(nl) - b));
      begin_ += line.size() + 1;
      break;
    }
    if (atEnd_ || fd_ < 0) {
      if (begin_ == end_) return false;
      line = std::string_view(b, end_ - begin_);
      begin_ = end_;
      break;
    }
    fill();
  }
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  ++number_;
  return true;
}

std::string LineReader::error() const { return error_ ? std::strerror(error_) : std::string(); }

// Keeps the unfinished line at the front of the buffer and reads after it.
void LineReader::fill() {
  std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
  base_ += begin_;
  end_ -= begin_;
  begin_ = 0;
  if (end_ == buffer_.size()) buffer_.resize(2 * buffer_.size());
  for (;;) {
    const ssize_t got = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) error_ = errno;
    if (got <= 0)
      atEnd_ = true;
    else
      end_ += static_cast<std::size_t>(got);
    return;
  }
}

}  // namespace flexarm::textio
