#include "core/io/ranges.h"

#include <algorithm>
#include <cmath>

namespace flexarm {

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
