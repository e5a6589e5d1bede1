#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>

#include "app/cli/cli.h"

namespace flexarm::cli {

ArgParser::ArgParser(std::vector<std::string> flags, std::vector<std::string> valued)
    : flags_(std::move(flags)), valued_(std::move(valued)) {}

bool ArgParser::parse(const std::vector<std::string>& args) {
  auto contains = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() < 3 || a.compare(0, 2, "--") != 0) {
      if (a.size() >= 2 && a[0] == '-' && !(a[1] >= '0' && a[1] <= '9') && a[1] != '.') {
        error_ = "unknown option '" + a + "'";
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
    if (contains(flags_, name)) {
      if (hasValue) {
        error_ = "option --" + name + " takes no value";
        return false;
      }
      values_[name].push_back("");
    } else if (contains(valued_, name)) {
      if (!hasValue) {
        if (i + 1 >= args.size()) {
          error_ = "option --" + name + " needs a value";
          return false;
        }
        value = args[++i];
      }
      values_[name].push_back(value);
    } else {
      error_ = "unknown option '--" + name + "'";
      return false;
    }
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

bool ArgParser::number(const std::string& name, double& out) {
  auto v = value(name);
  if (!v) return true;
  const char* b = v->data();
  const char* e = v->data() + v->size();
  if (b != e && *b == '+') ++b;
  double x = 0;
  auto res = std::from_chars(b, e, x);
  if (res.ec != std::errc() || res.ptr != e || !std::isfinite(x)) {
    error_ = "--" + name + " expects a number, got '" + *v + "'";
    return false;
  }
  out = x;
  return true;
}

bool ArgParser::integer(const std::string& name, long& out) {
  auto v = value(name);
  if (!v) return true;
  long x = 0;
  auto res = std::from_chars(v->data(), v->data() + v->size(), x);
  if (res.ec != std::errc() || res.ptr != v->data() + v->size()) {
    error_ = "--" + name + " expects an integer, got '" + *v + "'";
    return false;
  }
  out = x;
  return true;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

bool ArgParser::integer(const std::string& name, int& out, int min, int max) {
  auto v = value(name);
  if (!v) return true;
  long long x = 0;
  const char* b = v->data();
  const char* e = v->data() + v->size();
  if (b != e && *b == '+') ++b;
  const auto res = std::from_chars(b, e, x);
  if (res.ec != std::errc() || res.ptr != e || x < min || x > max) {
    error_ = "--" + name + " expects a whole number from " + std::to_string(min) + " to " +
             std::to_string(max) + ", got '" + *v + "'";
    return false;
  }
  out = static_cast<int>(x);
  return true;
}

}  // namespace flexarm::cli
