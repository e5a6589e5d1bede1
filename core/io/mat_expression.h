#pragma once
// MATLAB expressions that name one signal inside a .mat file, as MATLAB users store logs: a
// variable (`t`), struct fields (`rec.time_cont`), one element of a struct array or cell
// (`runs(2).tau`, `c{3}`) and a row, column or part of a numeric array
// (`rec.act_torque_abs_nm(1,:)`, `data(:,2)`, `x(100:end)`, `q(end-999:end, 3)`).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/mat_check.h"

namespace flexarm {

// One subscript: ':' (all), or first[:last], each a 1-based number or `end` minus a number.
struct MatSubscript {
  bool all = false;
  long long first = 1, last = 1;         // the numbers written (after `end-`: subtracted)
  bool firstFromEnd = false, lastFromEnd = false;
};

struct MatStep {
  enum class Kind { Field, Paren, Brace };
  Kind kind = Kind::Field;
  std::string field;                     // Kind::Field
  std::vector<MatSubscript> subscripts;  // Kind::Paren and Kind::Brace
};

struct MatExpression {
  std::string text;      // as written, blanks trimmed
  std::string variable;  // the top-level variable
  std::vector<MatStep> steps;
};

// Parses text; nullopt with a sentence naming the character where it goes wrong.
std::optional<MatExpression> parseMatExpression(std::string_view text, std::string* why);

// A channel name made of the expression: letters, digits and '_' only, ':' dropped
// ("rec.act_torque_abs_nm(1,:)" -> "rec_act_torque_abs_nm_1"); the text itself when it is a
// plain name.
std::string channelNameFor(std::string_view expression);

// The elements an expression names in a numeric array of the file: `count` elements from
// `start`, `stride` apart (column-major, as MATLAB stores them).
struct MatSelection {
  const MatVariable* array = nullptr;
  std::uint64_t start = 0, stride = 1, count = 0;
};

// Follows e through the variables of a file (the check's tree, or matio's converted to it) to
// a vector of numbers; false with a sentence saying what does not fit ("'rec' has no field
// 'tau'; its fields are ...", "'rec.act_pos_mot_deg' is a 6 x 2501 array: name a row or a
// column, e.g. rec.act_pos_mot_deg(1,:)", "row 7 is beyond the 6 rows").
bool selectMatVector(const std::vector<MatVariable>& variables, const MatExpression& e,
                     MatSelection& out, std::string* why);

// "6 x 2501", and MATLAB's name of an array class ("double", "struct", "cell", "char").
std::string matShapeText(const std::vector<std::uint64_t>& dims);
const char* matClassName(std::uint32_t arrayClass);
// True for the numeric classes (double, single and the integer classes).
bool isNumericMatClass(std::uint32_t arrayClass);

}  // namespace flexarm
