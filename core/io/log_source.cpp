#include "core/io/log_source.h"

#include <algorithm>
#include <filesystem>

#include "core/common/text.h"
#include "core/io/input_file.h"
#include "core/io/reader_support.h"

namespace flexarm {
namespace {

bool isMatFile(const std::string& path, std::string_view head) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".mat" || head.substr(0, 6) == "MATLAB";
}

// The offset of the first line that is not blank or a comment ('#', '%'), or npos.
std::size_t firstDataLine(std::string_view text) {
  io::LineCursor cursor(text);
  std::string_view line;
  std::size_t at = 0;
  while (cursor.next(line)) {
    const std::size_t b = line.find_first_not_of(" \t\r");
    if (b != std::string_view::npos && line[b] != '#' && line[b] != '%') return at + b;
    at = cursor.offset();
  }
  return std::string_view::npos;
}

}  // namespace

SourceListing listLogSource(const std::string& path, const LogReadOptions& options) {
  SourceListing listing;
  InputFile file;
  FileBytes bytes;
  std::string problem;
  char head[128] = {};
  const auto fail = [&] {
    listing.error = ReadError{path, 0, 0, {}, problem};
    return listing;
  };
  if (!file.open(path, options.maxFileBytes, &problem)) return fail();
  if (isMatFile(path, std::string_view(head, file.readFully(0, head, sizeof head))))
    return io::listMatSource(path, options);
  if (!file.readAll(bytes, &problem)) return fail();
  const std::string_view text = bytes.view();
  // A text file: its columns read as a headerless table. A header line becomes a comment
  // (same length, so every line keeps its number in messages) and gives the names.
  const std::size_t first = firstDataLine(text);
  std::vector<std::string> names;
  std::string copy;
  std::string_view rows = text;
  if (first != std::string_view::npos) {
    const char c = text[first];
    const bool numeric = (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
    if (!numeric) {
      const std::size_t end = std::min(text.find('\n', first), text.size());
      std::vector<std::string_view> fields;
      io::splitFields(text.substr(first, end - first), ',', fields);
      for (const auto& f : fields) names.push_back(io::trim(f));
      copy.assign(text);
      copy[first] = '#';
      rows = copy;
    }
  }
  listing.format = names.empty() ? LogFormat::Table : LogFormat::FlexArmCsv;
  LogReadOptions table;
  table.maxFileBytes = options.maxFileBytes;
  LogReadResult r = readTableText(rows, path, table);
  if (!r.ok) {
    listing.error = r.error;
    return listing;
  }
  if (!names.empty() && names.size() != r.data.channels.size()) {
    listing.error = ReadError{path, 0, 0, {},
                              "the header has " + std::to_string(names.size()) + " names but the rows " +
                                  std::to_string(r.data.channels.size()) + " fields"};
    return listing;
  }
  for (std::size_t i = 0; i < r.data.channels.size(); ++i) {
    SourceEntry e;
    e.label = names.empty() ? "column " + std::to_string(i + 1) : names[i];
    e.expression = e.label;
    e.numeric = true;
    e.rows = r.data.samples();
    e.cols = 1;
    e.shape = std::to_string(e.rows) + " rows";
    e.kind = "number";
    listing.entries.push_back(std::move(e));
    listing.columns.push_back(std::move(r.data.channels[i].values));
  }
  listing.ok = true;
  return listing;
}

SeriesRead readSourceSeries(const std::string& path, const SourceListing& listing, const std::string& name,
                            const LogReadOptions& options) {
  if (listing.format == LogFormat::Mat) return io::readMatExpression(path, name, options);
  SeriesRead out;
  for (std::size_t i = 0; i < listing.entries.size() && i < listing.columns.size(); ++i)
    if (listing.entries[i].expression == name) {
      out.ok = true;
      out.values = listing.columns[i];
      return out;
    }
  out.error = ReadError{path, 0, 0, name, "the file has no column " + inQuotes(name)};
  return out;
}

}  // namespace flexarm
