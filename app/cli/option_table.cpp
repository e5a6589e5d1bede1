// The verbs' option tables and the help text written from them.
#include <cstdio>
#include <sstream>

#include "app/cli/cli.h"

namespace flexarm::cli {

namespace {

constexpr std::size_t kWidth = 90;   // of a help line
constexpr std::size_t kIndent = 24;  // where an option's help starts

constexpr double kNoBound = 1e308;

std::string numberText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// Appends text to out, wrapped at kWidth, every line but the first indented by indent; the
// first line continues at column `at`.
void wrap(std::string& out, const std::string& text, std::size_t indent, std::size_t at) {
  std::istringstream words(text);
  std::string word;
  bool first = true;
  while (words >> word) {
    if (!first && at + 1 + word.size() > kWidth) {
      out += "\n" + std::string(indent, ' ');
      at = indent;
    } else if (!first) {
      out += " ";
      ++at;
    }
    out += word;
    at += word.size();
    first = false;
  }
  out += "\n";
}

// What an option's help adds to its line: repeatable, required, its range and its default.
std::string facts(const Option& o) {
  std::string out;
  auto add = [&out](const std::string& s) { out += (out.empty() ? "" : "; ") + s; };
  if (o.repeatable) add("repeatable");
  if (o.required) add("required");
  if (const std::string range = rangeText(o); !range.empty()) add(range.substr(1));
  if (!o.defaultValue.empty()) add("default " + o.defaultValue);
  return out.empty() ? out : " (" + out + ")";
}

}  // namespace

Option flagOption(std::string name, std::string help) {
  Option o;
  o.name = std::move(name);
  o.help = std::move(help);
  return o;
}

Option textOption(std::string name, std::string value, std::string help, bool repeatable) {
  Option o;
  o.name = std::move(name);
  o.kind = OptionKind::Text;
  o.value = std::move(value);
  o.help = std::move(help);
  o.repeatable = repeatable;
  return o;
}

Option integerOption(std::string name, std::string value, long min, long max, std::string defaultValue,
                     std::string help) {
  Option o = textOption(std::move(name), std::move(value), std::move(help));
  o.kind = OptionKind::Integer;
  o.min = static_cast<double>(min);
  o.max = static_cast<double>(max);
  o.defaultValue = std::move(defaultValue);
  return o;
}

Option numberOption(std::string name, std::string value, double min, double max, std::string defaultValue,
                    std::string help) {
  Option o = textOption(std::move(name), std::move(value), std::move(help));
  o.kind = OptionKind::Number;
  o.min = min;
  o.max = max;
  o.defaultValue = std::move(defaultValue);
  return o;
}

Option choiceOption(std::string name, std::vector<std::string> choices, std::string defaultValue, std::string help) {
  std::string value;
  for (const auto& c : choices) value += (value.empty() ? "" : "|") + c;
  Option o = textOption(std::move(name), value, std::move(help));
  o.kind = OptionKind::Choice;
  o.choices = std::move(choices);
  o.defaultValue = std::move(defaultValue);
  return o;
}

Option required(Option o) {
  o.required = true;
  return o;
}

std::string rangeText(const Option& o) {
  if (o.kind != OptionKind::Number && o.kind != OptionKind::Integer) return "";
  const bool low = o.min > -kNoBound, high = o.max < kNoBound;
  const std::string lo = numberText(o.min), hi = numberText(o.max);
  if (low && high) {
    if (!o.minOpen && !o.maxOpen) return " from " + lo + " to " + hi;
    if (o.minOpen && o.maxOpen) return " strictly between " + lo + " and " + hi;
    return std::string(o.minOpen ? " above " : " of at least ") + lo + (o.maxOpen ? " and below " : " and at most ") + hi;
  }
  if (low) return (o.minOpen ? " above " : " of at least ") + lo;
  if (high) return (o.maxOpen ? " below " : " of at most ") + hi;
  return "";
}

OptionTable::OptionTable(std::string usage, std::string description)
    : usage_(std::move(usage)), description_(std::move(description)) {
  groups_.push_back({"", {flagOption("help", "print this help")}});
}

OptionTable& OptionTable::group(std::string heading) {
  groups_.push_back({std::move(heading), {}});
  return *this;
}

OptionTable& OptionTable::add(Option option) {
  groups_.back().options.push_back(std::move(option));
  return *this;
}

OptionTable& OptionTable::add(const std::vector<Option>& options) {
  for (const auto& o : options) add(o);
  return *this;
}

OptionTable& OptionTable::replace(Option option) {
  for (auto& g : groups_)
    for (auto& o : g.options)
      if (o.name == option.name) {
        o = std::move(option);
        return *this;
      }
  return add(std::move(option));
}

OptionTable& OptionTable::note(std::string paragraph) {
  notes_.push_back(std::move(paragraph));
  return *this;
}

OptionTable& OptionTable::block(std::string text) {
  blocks_.push_back(std::move(text));
  return *this;
}

const Option* OptionTable::find(const std::string& name) const {
  for (const auto& g : groups_)
    for (const auto& o : g.options)
      if (o.name == name) return &o;
  return nullptr;
}

std::vector<const Option*> OptionTable::options() const {
  std::vector<const Option*> out;
  for (const auto& g : groups_)
    for (const auto& o : g.options) out.push_back(&o);
  return out;
}

std::string OptionTable::help() const {
  std::string out;
  if (!usage_.empty()) out += "Usage: " + usage_ + "\n\n";
  if (!description_.empty()) {
    wrap(out, description_, 0, 0);
    out += "\n";
  }
  for (const auto& g : groups_) {
    if (g.options.empty()) continue;
    if (!g.heading.empty()) out += g.heading + ":\n";
    for (const auto& o : g.options) {
      if (o.name == "help") continue;  // every verb has it; `flexarm --help` says so
      // The help beside its option, or below it when the option and its value are longer.
      std::string head = "  --" + o.name + (o.value.empty() ? "" : " " + o.value);
      if (head.size() < kIndent - 1) head.resize(kIndent, ' ');
      else head += "\n" + std::string(kIndent, ' ');
      out += head;
      wrap(out, o.help + facts(o), kIndent, kIndent);
    }
  }
  for (const auto& n : notes_) {
    out += "\n";
    wrap(out, n, 0, 0);
  }
  for (const auto& b : blocks_) out += "\n" + b + (b.empty() || b.back() == '\n' ? "" : "\n");
  return out;
}

}  // namespace flexarm::cli
