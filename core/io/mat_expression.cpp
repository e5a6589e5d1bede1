#include "core/io/mat_expression.h"
#include "core/common/text.h"

#include <algorithm>
#include <cctype>
#include <limits>

namespace flexarm {
namespace {

constexpr std::size_t kMaxText = 1000;
constexpr std::size_t kMaxSteps = 64;

bool isNameStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool isNameChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

class Parser {
 public:
  explicit Parser(std::string_view text) : s_(text) {}
  std::string problem;

  bool parse(MatExpression& e) {
    blanks();
    if (!name(e.variable, "a variable name")) return false;
    while (true) {
      blanks();
      if (at_ == s_.size()) return true;
      if (e.steps.size() >= kMaxSteps) return fail("more than 64 fields and subscripts");
      MatStep step;
      const char c = s_[at_];
      if (c == '.') {
        ++at_;
        blanks();
        step.kind = MatStep::Kind::Field;
        if (!name(step.field, "a field name after '.'")) return false;
      } else if (c == '(' || c == '{') {
        ++at_;
        step.kind = c == '(' ? MatStep::Kind::Paren : MatStep::Kind::Brace;
        if (!subscripts(step.subscripts, c == '(' ? ')' : '}')) return false;
      } else {
        return fail(std::string("'") + c + "' does not belong here (expected '.', '(' or '{')");
      }
      e.steps.push_back(std::move(step));
    }
  }

 private:
  bool fail(const std::string& what) {
    problem = what + " at character " + std::to_string(at_ + 1);
    return false;
  }
  void blanks() {
    while (at_ < s_.size() && (s_[at_] == ' ' || s_[at_] == '\t')) ++at_;
  }
  bool name(std::string& out, const char* what) {
    if (at_ >= s_.size() || !isNameStart(s_[at_])) return fail(std::string("expected ") + what);
    const std::size_t b = at_;
    while (at_ < s_.size() && isNameChar(s_[at_])) ++at_;
    out.assign(s_.substr(b, at_ - b));
    return true;
  }
  // A number or `end` with an optional "-N"/"+N".
  bool bound(long long& value, bool& fromEnd) {
    blanks();
    fromEnd = false;
    value = 0;
    if (s_.substr(at_, 3) == "end" && (at_ + 3 == s_.size() || !isNameChar(s_[at_ + 3]))) {
      at_ += 3;
      fromEnd = true;
      blanks();
      if (at_ < s_.size() && (s_[at_] == '-' || s_[at_] == '+')) {
        const bool minus = s_[at_] == '-';
        ++at_;
        blanks();
        if (!number(value)) return false;
        value = minus ? value : -value;
      }
      return true;
    }
    return number(value);
  }
  bool number(long long& value) {
    if (at_ >= s_.size() || !std::isdigit(static_cast<unsigned char>(s_[at_])))
      return fail("expected a whole number, 'end' or ':'");
    value = 0;
    while (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) {
      if (value > (std::numeric_limits<long long>::max() - 9) / 10) return fail("the number is too large");
      value = value * 10 + (s_[at_++] - '0');
    }
    if (at_ < s_.size() && (s_[at_] == '.' || s_[at_] == 'e' || s_[at_] == 'E'))
      return fail("subscripts are whole numbers");
    return true;
  }
  bool subscripts(std::vector<MatSubscript>& out, char close) {
    while (true) {
      blanks();
      if (out.size() >= 32) return fail("more than 32 subscripts");
      MatSubscript sub;
      if (at_ < s_.size() && s_[at_] == ':') {
        ++at_;
        sub.all = true;
      } else {
        if (!bound(sub.first, sub.firstFromEnd)) return false;
        sub.last = sub.first;
        sub.lastFromEnd = sub.firstFromEnd;
        blanks();
        if (at_ < s_.size() && s_[at_] == ':') {
          ++at_;
          if (!bound(sub.last, sub.lastFromEnd)) return false;
          blanks();
          if (at_ < s_.size() && s_[at_] == ':') return fail("steps other than 1 (a:step:b) are not read");
        }
      }
      out.push_back(sub);
      blanks();
      if (at_ >= s_.size()) return fail(std::string("expected '") + close + "'");
      if (s_[at_] == ',') {
        ++at_;
        continue;
      }
      if (s_[at_] == close) {
        ++at_;
        return true;
      }
      return fail(std::string("expected ',' or '") + close + "'");
    }
  }

  std::string_view s_;
  std::size_t at_ = 0;
};

std::string list(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + i;
  return out;
}

std::uint64_t product(const std::vector<std::uint64_t>& dims) {
  std::uint64_t n = 1;
  for (auto d : dims) n = d == 0 ? 0 : n * d;
  return n;
}

// The range [first, last] (0-based) a subscript selects in a dimension of `size`.
bool resolve(const MatSubscript& s, std::uint64_t size, std::uint64_t& first, std::uint64_t& last,
             const std::string& what, std::string* why) {
  if (s.all) {
    if (size == 0) {
      if (why) *why = what + " is empty";
      return false;
    }
    first = 0;
    last = size - 1;
    return true;
  }
  const auto at = [&](long long v, bool fromEnd) {
    return fromEnd ? static_cast<long long>(size) - v : v;  // `end - v`, else v
  };
  const long long a = at(s.first, s.firstFromEnd), b = at(s.last, s.lastFromEnd);
  for (long long v : {a, b})
    if (v < 1 || v > static_cast<long long>(size)) {
      if (why) *why = what + " " + std::to_string(v) + " is outside 1.." + std::to_string(size);
      return false;
    }
  if (b < a) {
    if (why) *why = what + " " + std::to_string(a) + ":" + std::to_string(b) + " selects nothing";
    return false;
  }
  first = static_cast<std::uint64_t>(a - 1);
  last = static_cast<std::uint64_t>(b - 1);
  return true;
}

std::string describe(const MatVariable& v) {
  if (!v.unreadable.empty()) return v.unreadable;
  return "a " + matShapeText(v.dims) + " " + matClassName(v.arrayClass) + " array";
}

// The one element (0-based, column-major) that subscripts name in an array of `dims`.
bool oneElement(const std::vector<MatSubscript>& subs, const std::vector<std::uint64_t>& dims,
                const std::string& where, std::uint64_t& index, std::string* why) {
  const auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (subs.size() != 1 && subs.size() != dims.size())
    return fail(where + " has " + std::to_string(dims.size()) + " dimensions: give 1 or " +
                std::to_string(dims.size()) + " subscripts");
  std::uint64_t stride = 1;
  index = 0;
  for (std::size_t i = 0; i < subs.size(); ++i) {
    const std::uint64_t size = subs.size() == 1 ? product(dims) : dims[i];
    std::uint64_t a = 0, b = 0;
    if (!resolve(subs[i], size, a, b, where + " subscript " + std::to_string(i + 1), why)) return false;
    if (a != b) return fail(where + ": name one element, not a range");
    index += a * stride;
    stride *= size;
  }
  return true;
}

}  // namespace

std::optional<MatExpression> parseMatExpression(std::string_view text, std::string* why) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  if (text.empty()) {
    if (why) *why = "the expression is empty";
    return std::nullopt;
  }
  if (text.size() > kMaxText) {
    if (why) *why = "the expression is longer than 1000 characters";
    return std::nullopt;
  }
  MatExpression e;
  e.text = std::string(text);
  Parser p(text);
  if (!p.parse(e)) {
    if (why) *why = p.problem;
    return std::nullopt;
  }
  return e;
}

std::string channelNameFor(std::string_view expression) {
  std::string out;
  for (char c : expression) {
    if (isNameChar(c)) out += c;
    else if (c != ':' && c != ' ' && !out.empty() && out.back() != '_') out += '_';
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out.empty() ? std::string("signal") : out;
}

std::string matShapeText(const std::vector<std::uint64_t>& dims) {
  std::string s;
  for (auto d : dims) s += (s.empty() ? "" : " x ") + std::to_string(d);
  return s.empty() ? "0 x 0" : s;
}

const char* matClassName(std::uint32_t c) {
  switch (c) {
    case 1: return "cell";
    case 2: return "struct";
    case 3: return "object";
    case 4: return "char";
    case 5: return "sparse";
    case 6: return "double";
    case 7: return "single";
    case 8: return "int8";
    case 9: return "uint8";
    case 10: return "int16";
    case 11: return "uint16";
    case 12: return "int32";
    case 13: return "uint32";
    case 14: return "int64";
    case 15: return "uint64";
    case 16: return "function handle";
    case 17: return "object";
    default: return "unknown";
  }
}

bool isNumericMatClass(std::uint32_t c) { return c >= 6 && c <= 15; }

bool selectMatVector(const std::vector<MatVariable>& variables, const MatExpression& e,
                     MatSelection& out, std::string* why) {
  const auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  const MatVariable* node = nullptr;
  std::vector<std::string> names;
  for (const MatVariable& v : variables) {
    if (v.name.empty()) continue;
    if (v.name == e.variable) node = &v;
    names.push_back(v.name);
  }
  if (!node)
    return fail("the variable '" + e.variable + "' is missing; the file holds " + list(names));
  std::string where = e.variable;
  bool selected = false;
  bool chosen = false;        // an element of a struct array was named last
  std::uint64_t element = 0;  // which
  for (std::size_t k = 0; k < e.steps.size(); ++k) {
    const MatStep& step = e.steps[k];
    if (!node->unreadable.empty())
      return fail("'" + where + "' is " + node->unreadable + ", which FlexArm does not read");
    if (selected) return fail("'" + where + "' is already a part of a numeric array: nothing can follow it");
    if (chosen && step.kind != MatStep::Kind::Field)
      return fail("'" + where + "' is one element of a struct array: name one of its fields");
    switch (step.kind) {
      case MatStep::Kind::Field: {
        if (node->arrayClass != 2) return fail("'" + where + "' is " + describe(*node) + ", not a struct");
        if (node->elements != 1 && !chosen)
          return fail("'" + where + "' is a " + matShapeText(node->dims) +
                      " struct array: name one element, e.g. " + where + "(1)." + step.field);
        const auto f = std::find(node->fields.begin(), node->fields.end(), step.field);
        if (f == node->fields.end())
          return fail("'" + where + "' has no field '" + step.field + "'; its fields are " + list(node->fields));
        const auto i = static_cast<std::size_t>(f - node->fields.begin()) +
                       static_cast<std::size_t>(chosen ? element : 0) * node->fields.size();
        chosen = false;
        if (i >= node->children.size()) return fail("'" + where + "' holds more than FlexArm lists");
        node = &node->children[i];
        where += "." + step.field;
        break;
      }
      case MatStep::Kind::Brace:
      case MatStep::Kind::Paren: {
        const bool brace = step.kind == MatStep::Kind::Brace;
        if (node->arrayClass == 1 && !brace)
          return fail("'" + where + "' is a cell array: name a cell with braces, e.g. " + where + "{1}");
        if (brace && node->arrayClass != 1) return fail("'" + where + "' is " + describe(*node) + ", not a cell array");
        if (node->arrayClass == 1 || node->arrayClass == 2) {
          std::uint64_t index = 0;
          if (!oneElement(step.subscripts, node->dims, "" + inQuotes(where), index, why)) return false;
          const std::uint64_t perElement = node->arrayClass == 2 ? std::max<std::size_t>(node->fields.size(), 1) : 1;
          const std::uint64_t child = node->arrayClass == 1 ? index : index * perElement;
          if (node->arrayClass == 2 && node->fields.empty())
            return fail("'" + where + "' is a struct without fields");
          if (child >= node->children.size()) return fail("'" + where + "' holds more than FlexArm lists");
          // A struct element is kept as the struct with one element: the fields follow.
          std::string sub;
          for (const auto& s : step.subscripts)
            sub += (sub.empty() ? "" : ",") + (s.all ? std::string(":") : std::to_string(s.first));
          where += (brace ? "{" : "(") + sub + (brace ? "}" : ")");
          if (node->arrayClass == 1) node = &node->children[child];
          else chosen = true, element = index;  // the struct stays; its next field is this element's
          break;
        }
        if (!isNumericMatClass(node->arrayClass))
          return fail("'" + where + "' is " + describe(*node) + ", not numbers");
        // Numbers: at most one subscript names more than one element.
        const auto& subs = step.subscripts;
        const std::vector<std::uint64_t>& dims = node->dims;
        if (subs.size() != 1 && subs.size() != dims.size())
          return fail("'" + where + "' has " + std::to_string(dims.size()) + " dimensions: give 1 or " +
                      std::to_string(dims.size()) + " subscripts");
        std::uint64_t start = 0, stride = 1, count = 1, scale = 1;
        bool ranged = false;
        for (std::size_t i = 0; i < subs.size(); ++i) {
          const std::uint64_t size = subs.size() == 1 ? product(dims) : dims[i];
          static const char* const kinds[] = {"row", "column"};
          const std::string what = subs.size() == 2 ? std::string(kinds[i]) : "subscript " + std::to_string(i + 1);
          std::uint64_t a = 0, b = 0;
          if (!resolve(subs[i], size, a, b, "'" + where + "' " + what, why)) return false;
          if (b > a) {
            if (ranged)
              return fail("'" + e.text + "' names a block of " + where +
                          ", not one signal: let one subscript be a number, e.g. " + where + "(1,:)");
            ranged = true;
            stride = scale;
            count = b - a + 1;
          }
          start += a * scale;
          scale *= size;
        }
        out = MatSelection{node, start, stride, count};
        selected = true;
        where = e.text;
        break;
      }
    }
  }
  if (selected) return true;
  if (chosen) return fail("'" + where + "' is a struct: name one of its fields (" + list(node->fields) + ")");
  if (!node->unreadable.empty()) return fail("'" + where + "' is " + node->unreadable + ", which FlexArm does not read");
  if (node->arrayClass == 2 && node->elements == 1)
    return fail("'" + where + "' is a struct: name one of its fields (" + list(node->fields) + ")");
  if (!isNumericMatClass(node->arrayClass)) return fail("'" + where + "' is " + describe(*node) + ", not numbers");
  if (node->complex) return fail("'" + where + "' holds complex numbers; FlexArm reads real signals");
  int long_ = 0;
  for (auto d : node->dims) long_ += d > 1;
  if (long_ > 1)
    return fail("'" + where + "' is a " + matShapeText(node->dims) +
                " array: name a row or a column, e.g. " + where + "(1,:) or " + where + "(:,1)");
  out = MatSelection{node, 0, 1, node->elements};
  return true;
}

}  // namespace flexarm
