#include "core/session/json_fields.h"

#include <cmath>
#include <limits>

namespace flexarm {

using nlohmann::json;

namespace {

// Looks key up: Absent (an error only when required), Bad (missing though required, or of
// another kind than `kind` names) or Present; an error leaves a sentence in why.
enum class Field { Absent, Present, Bad };
template <class IsKind>
Field field(const json& j, const char* key, bool required, IsKind isKind, const char* kind,
            std::string* why, const std::string& where) {
  if (!j.contains(key)) {
    if (!required) return Field::Absent;
    if (why) *why = where + key + " is missing";
    return Field::Bad;
  }
  if (!isKind(j[key])) {
    if (why) *why = where + key + " must be " + kind;
    return Field::Bad;
  }
  return Field::Present;
}

}  // namespace

json jsonNumber(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

bool readNumber(const json& j, const char* key, double& out, bool required, std::string* why,
                const std::string& where) {
  const Field f = field(j, key, required, [](const json& v) { return v.is_number() || v.is_null(); },
                        "a number", why, where);
  if (f == Field::Present)
    out = j[key].is_null() ? std::numeric_limits<double>::quiet_NaN() : j[key].get<double>();
  return f != Field::Bad;
}

bool readText(const json& j, const char* key, std::string& out, bool required, std::string* why,
              const std::string& where) {
  const Field f = field(j, key, required, [](const json& v) { return v.is_string(); }, "text", why, where);
  if (f == Field::Present) out = j[key].get<std::string>();
  return f != Field::Bad;
}

bool readFlag(const json& j, const char* key, bool& out, std::string* why, const std::string& where) {
  const Field f = field(j, key, false, [](const json& v) { return v.is_boolean(); }, "true or false",
                        why, where);
  if (f == Field::Present) out = j[key].get<bool>();
  return f != Field::Bad;
}

bool readWhole(const json& j, const char* key, int& out, std::string* why, const std::string& where) {
  const Field f = field(j, key, false, [](const json& v) { return v.is_number_integer(); },
                        "a whole number", why, where);
  if (f == Field::Present) out = j[key].get<int>();
  return f != Field::Bad;
}

std::string jsonErrorText(const nlohmann::json::exception& e) {
  std::string s = e.what();
  if (s.rfind("[json.exception.", 0) == 0)
    if (const auto close = s.find("] "); close != std::string::npos) s.erase(0, close + 2);
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  if (s.size() > 160) s = s.substr(0, 160) + "...";
  return s;
}

}  // namespace flexarm
