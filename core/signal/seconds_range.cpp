#include "core/signal/seconds_range.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/common/text.h"

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

std::optional<SecondsRange> secondsRangeFromText(const std::string& text, std::string* why) {
  SecondsRange r;
  if (parseSecondsRange(text, r.start, r.end)) return r;
  if (why) *why = "a range is written A:B in seconds with A < B, e.g. 2.5:10, not " + inQuotes(text);
  return std::nullopt;
}

std::string formatSecondsRange(const IdData& data, const SampleRange& r) {
  char buf[96];
  const std::size_t last = r.end > 0 ? r.end - 1 : 0;
  std::snprintf(buf, sizeof buf, "%.9g:%.9g", data.timeAt(r.begin), data.timeAt(last));
  return buf;
}

SampleRange samplesIn(const IdData& data, const SecondsRange& r) {
  return data.rangeForTimes(r.start, r.end);
}

SecondsRange secondsOf(const IdData& data, const SampleRange& r) {
  const std::size_t last = r.end > r.begin ? r.end - 1 : r.begin;
  return {data.timeAt(r.begin), data.timeAt(last)};
}

bool sameSamples(const IdData& a, const std::optional<SecondsRange>& rangeA, const IdData& b,
                 const std::optional<SecondsRange>& rangeB) {
  const SampleRange sa = rangeA ? samplesIn(a, *rangeA) : SampleRange{0, a.samples()};
  const SampleRange sb = rangeB ? samplesIn(b, *rangeB) : SampleRange{0, b.samples()};
  if (sa.empty() || sa.size() != sb.size() || a.channels.size() != b.channels.size() ||
      a.sampleTime != b.sampleTime)
    return false;
  for (const Channel& ca : a.channels) {
    const Channel* cb = b.channel(ca.name);
    if (!cb || cb->unit != ca.unit) return false;
    if (!std::equal(ca.values.begin() + static_cast<std::ptrdiff_t>(sa.begin),
                    ca.values.begin() + static_cast<std::ptrdiff_t>(sa.end),
                    cb->values.begin() + static_cast<std::ptrdiff_t>(sb.begin)))
      return false;
  }
  return true;
}

}  // namespace flexarm
