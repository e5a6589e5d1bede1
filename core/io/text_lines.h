#pragma once
// Reading the text logs (FlexArm CSV, headerless tables): a file line by line through one
// buffer, and the fields of a line as numbers. Internal to core/io.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm::textio {

// s without the blanks (' ', '\t', '\r') at both ends.
std::string trim(std::string_view s);
// Whether s holds nothing but blanks (' ', '\t', '\r').
bool isBlank(std::string_view s);

enum class FieldStatus { Ok, Empty, NotNumber, NotFinite };

// One field as a finite number: blanks around it and a leading '+' are allowed.
FieldStatus parseNumber(std::string_view field, double& value);
// The problem with a field that parseNumber refused, as a sentence.
std::string fieldProblem(FieldStatus s, std::string_view field);
// Splits on the delimiter (',' for CSV) or on runs of blanks (delimiter 0).
void splitFields(std::string_view line, char delimiter, std::vector<std::string_view>& out);

// A data line of exactly row.size() finite numbers separated by single commas, with no
// blanks or signs '+' (the rows as FlexArm writes them), parsed into row; false for any other
// line, which the field-by-field path (splitFields, parseNumber) then reads or names as bad.
// Where both accept a line they give the same values: both parse each number with
// std::from_chars, which stops at a comma.
bool parsePlainRow(std::string_view line, std::vector<double>& row);

// Reads a text file line by line through one buffer of a megabyte (a longer line grows it),
// never holding the whole file: the view of a line stays valid until the next call. Lines are
// counted from 1 (from where reading started); the '\r' of a "\r\n" line end is dropped.
class LineReader {
 public:
  LineReader() = default;
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;
  ~LineReader();
  // Opens the file to read from byte `offset` on; false (errno set) when it cannot be opened.
  bool open(const std::string& path, std::uint64_t offset = 0);
  bool next(std::string_view& line);
  int number() const { return number_; }
  // The byte in the file where the next line starts.
  std::uint64_t offset() const { return base_ + begin_; }
  // The system's reason when reading stopped on an error; empty when it did not.
  std::string error() const;

 private:
  void fill();

  int fd_ = -1;
  std::vector<char> buffer_ = std::vector<char>(std::size_t{1} << 20);
  std::uint64_t base_ = 0;  // the file offset of buffer_[0]
  std::size_t begin_ = 0, end_ = 0;
  bool atEnd_ = false;
  int error_ = 0;
  int number_ = 0;
};

}  // namespace flexarm::textio
