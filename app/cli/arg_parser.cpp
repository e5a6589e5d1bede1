#include "app/cli/cli.h"

#include <charconv>
#include <cstdio>
#include <cmath>
#include <ostream>
#include <sstream>
#include <string>

#include "core/common/text.h"

namespace flexarm::cli {

namespace {

// "123", "+123", "-4": a whole number, nothing else (no fraction, no exponent, no overflow).
std::optional<long long> wholeNumber(const std::string& text) {
  const char* b = text.data();
  const char* e = text.data() + text.size();
  if (b != e && *b == '+') ++b;
  long long x = 0;
  const auto res = std::from_chars(b, e, x);
  if (b == e || res.ec != std::errc() || res.ptr != e) return std::nullopt;
  return x;
}

std::optional<double> finiteNumber(const std::string& text) {
  const char* b = text.data();
  const char* e = text.data() + text.size();
  if (b != e && *b == '+') ++b;
  double x = 0;
  const auto res = std::from_chars(b, e, x);
  if (b == e || res.ec != std::errc() || res.ptr != e || !std::isfinite(x)) return std::nullopt;
  return x;
}

}  // namespace

ArgParser::ArgParser(OptionTable table) : table_(std::move(table)) {}

ArgParser::ArgParser(std::vector<std::string> flags, std::vector<std::string> valued) : table_("", "") {
  for (auto& n : flags) table_.add(flagOption(std::move(n), ""));
  for (auto& n : valued) table_.add(textOption(std::move(n), "VALUE", "", true));
}

bool ArgParser::parse(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() < 3 || a.compare(0, 2, "--") != 0) {
      if (a.size() >= 2 && a[0] == '-' && !(a[1] >= '0' && a[1] <= '9') && a[1] != '.') {
        error_ = "unknown option " + inQuotes(a);
        return false;
      }
      positional_.push_back(a);
      continue;
    }
    std::string name = a.substr(2), value;
    bool hasValue = false;
    if (auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      hasValue = true;
    }
    const Option* o = table_.find(name);
    if (!o) {
      error_ = "unknown option '--" + name + "'";
      return false;
    }
    if (o->kind == OptionKind::Flag) {
      if (hasValue) {
        error_ = "option --" + name + " takes no value";
        return false;
      }
      values_[name].push_back("");
      sequence_.emplace_back(name, "");
      continue;
    }
    if (!hasValue) {
      if (i + 1 >= args.size()) {
        error_ = "option --" + name + " needs a value";
        return false;
      }
      value = args[++i];
    }
    switch (o->kind) {
      case OptionKind::Number: {
        const auto x = finiteNumber(value);
        const bool inside = x && (o->minOpen ? *x > o->min : *x >= o->min) && (o->maxOpen ? *x < o->max : *x <= o->max);
        if (!inside) {
          error_ = "--" + name + " expects a number" + rangeText(*o) + ", got " + inQuotes(value);
          return false;
        }
        break;
      }
      case OptionKind::Integer: {
        const auto x = wholeNumber(value);
        if (!x || static_cast<double>(*x) < o->min || static_cast<double>(*x) > o->max) {
          error_ = "--" + name + " expects a whole number" + rangeText(*o) + ", got " + inQuotes(value);
          return false;
        }
        break;
      }
      case OptionKind::Choice: {
        bool known = false;
        for (const auto& c : o->choices) known = known || c == value;
        if (!known) {
          std::string list;
          for (std::size_t k = 0; k < o->choices.size(); ++k)
            list += (k == 0 ? "" : k + 1 == o->choices.size() ? " or " : ", ") + o->choices[k];
          error_ = "--" + name + " expects " + list + ", not " + inQuotes(value);
          return false;
        }
        break;
      }
      case OptionKind::Flag:
      case OptionKind::Text: break;
    }
    values_[name].push_back(value);
    sequence_.emplace_back(name, value);
  }
  if (!flag("help"))
    for (const auto* o : table_.options())
      if (o->required && !values_.count(o->name)) {
        error_ = "--" + o->name + " is required";
        return false;
      }
  return true;
}

bool ArgParser::flag(const std::string& name) const { return values_.count(name) > 0; }

std::optional<std::string> ArgParser::value(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::vector<std::string> ArgParser::values(const std::string& name) const {
  auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

std::string ArgParser::text(const std::string& name) const {
  if (auto v = value(name)) return *v;
  const Option* o = table_.find(name);
  return o ? o->defaultValue : std::string();
}

double ArgParser::number(const std::string& name) const { return finiteNumber(text(name)).value_or(0.0); }

long ArgParser::integer(const std::string& name) const {
  return static_cast<long>(wholeNumber(text(name)).value_or(0));
}

bool ArgParser::number(const std::string& name, double& out, double min, double max) {
  auto v = value(name);
  if (!v) return true;
  const auto x = finiteNumber(*v);
  if (!x || *x < min || *x > max) {
    error_ = "--" + name + " expects a number from " + shortNumber(min, 6) + " to " + shortNumber(max, 6) + ", got " +
             inQuotes(*v);
    return false;
  }
  out = *x;
  return true;
}

bool ArgParser::number(const std::string& name, double& out) {
  auto v = value(name);
  if (!v) return true;
  const auto x = finiteNumber(*v);
  if (!x) {
    error_ = "--" + name + " expects a number, got " + inQuotes(*v);
    return false;
  }
  out = *x;
  return true;
}

bool ArgParser::integer(const std::string& name, long& out) {
  auto v = value(name);
  if (!v) return true;
  long x = 0;
  auto res = std::from_chars(v->data(), v->data() + v->size(), x);
  if (res.ec != std::errc() || res.ptr != v->data() + v->size()) {
    error_ = "--" + name + " expects an integer, got " + inQuotes(*v);
    return false;
  }
  out = x;
  return true;
}

bool ArgParser::integer(const std::string& name, int& out, int min, int max) {
  auto v = value(name);
  if (!v) return true;
  const auto x = wholeNumber(*v);
  if (!x || *x < min || *x > max) {
    error_ = "--" + name + " expects a whole number from " + std::to_string(min) + " to " +
             std::to_string(max) + ", got " + inQuotes(*v);
    return false;
  }
  out = static_cast<int>(*x);
  return true;
}

std::optional<int> parseArguments(ArgParser& args, const std::vector<std::string>& argv, const std::string& verb,
                                  std::ostream& out, std::ostream& err) {
  if (!args.parse(argv)) {
    err << "flexarm " << verb << ": " << args.error() << "\n(flexarm " << verb << " --help explains the options)\n";
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << args.table().help();
    return kExitOk;
  }
  return std::nullopt;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace flexarm::cli
