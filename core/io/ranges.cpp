#include "core/io/ranges.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace flexarm {

bool parseSecondsRange(const std::string& text, double& t0, double& t1) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) return false;
  auto parse = [](const std::string& s, double& v) {
    const char* b = s.data();
    const char* e = s.data() + s.size();
    while (b < e && *b == ' ') ++b;
    while (e > b && e[-1] == ' ') --e;
    if (b < e && *b == '+') ++b;
    auto r = std::from_chars(b, e, v);
    return r.ec == std::errc() && r.ptr == e && std::isfinite(v);
  };
  return parse(text.substr(0, colon), t0) && parse(text.substr(colon + 1), t1) && t1 > t0;
}

std::string formatSecondsRange(const IdData& data, const SampleRange& r) {
  char buf[96];
  const std::size_t last = r.end > 0 ? r.end - 1 : 0;
  std::snprintf(buf, sizeof buf, "%.9g:%.9g", data.timeAt(r.begin), data.timeAt(last));
  return buf;
}

bool applyStoredRanges(IdData& data, std::string* why) {
  struct Slot {
    const char* key;
    std::optional<SampleRange>* range;
  } slots[] = {{kEstimationRangeKey, &data.estimationRange},
               {kValidationRangeKey, &data.validationRange}};
  for (auto& s : slots) {
    const std::string text = data.meta(s.key);
    if (text.empty()) continue;
    double t0 = 0, t1 = 0;
    if (!parseSecondsRange(text, t0, t1)) {
      if (why) *why = std::string("metadata '") + s.key + ": " + text + "' is not a range A:B in seconds";
      return false;
    }
    SampleRange r = data.rangeForTimes(t0, t1);
    if (r.empty()) {
      if (why) *why = std::string("metadata '") + s.key + ": " + text + "' holds no samples";
      return false;
    }
    *s.range = r;
  }
  return true;
}

void storeRanges(IdData& data) {
  auto put = [&](const char* key, const std::optional<SampleRange>& r) {
    auto it = std::find_if(data.metadata.begin(), data.metadata.end(),
                           [&](const auto& kv) { return kv.first == key; });
    if (r && !r->empty())
      data.setMeta(key, formatSecondsRange(data, *r));
    else if (it != data.metadata.end())
      data.metadata.erase(it);
  };
  put(kEstimationRangeKey, data.estimationRange);
  put(kValidationRangeKey, data.validationRange);
}

}  // namespace flexarm
