#include "core/signal/id_data.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace flexarm {

const char* toString(ChannelRole r) {
  switch (r) {
    case ChannelRole::None: return "none";
    case ChannelRole::Input: return "input";
    case ChannelRole::Output: return "output";
    case ChannelRole::Reference: return "reference";
  }
  return "none";
}

std::optional<ChannelRole> channelRoleFromString(std::string_view s) {
  for (ChannelRole r : {ChannelRole::None, ChannelRole::Input, ChannelRole::Output,
                        ChannelRole::Reference})
    if (s == toString(r)) return r;
  return std::nullopt;
}

std::string unitFromColumnName(std::string_view name) {
  struct Suffix {
    const char* suffix;
    const char* unit;
  };
  // Longest suffixes first so "_rad_s2" wins over "_s2" and "_rad_s" over "_s".
  static const Suffix kSuffixes[] = {
      {"_rad_s2", "rad/s^2"}, {"_rad_s", "rad/s"}, {"_m_s2", "m/s^2"}, {"_m_s", "m/s"},
      {"_rad", "rad"},        {"_deg", "deg"},     {"_nm", "N m"},     {"_hz", "Hz"},
      {"_s", "s"},            {"_m", "m"},         {"_a", "A"},        {"_v", "V"},
  };
  for (const auto& s : kSuffixes) {
    std::string_view suf(s.suffix);
    if (name.size() > suf.size() && name.substr(name.size() - suf.size()) == suf) return s.unit;
  }
  return {};
}

int IdData::indexOf(std::string_view name) const {
  for (std::size_t i = 0; i < channels.size(); ++i)
    if (channels[i].name == name) return static_cast<int>(i);
  return -1;
}

const Channel* IdData::channel(std::string_view name) const {
  int i = indexOf(name);
  return i < 0 ? nullptr : &channels[static_cast<std::size_t>(i)];
}

Channel* IdData::channel(std::string_view name) {
  int i = indexOf(name);
  return i < 0 ? nullptr : &channels[static_cast<std::size_t>(i)];
}

const Channel* IdData::withRole(ChannelRole role) const {
  for (const auto& c : channels)
    if (c.role == role) return &c;
  return nullptr;
}

bool IdData::setRole(std::string_view name, ChannelRole role) {
  Channel* target = channel(name);
  if (!target) return false;
  if (role == ChannelRole::Input || role == ChannelRole::Output)
    for (auto& c : channels)
      if (c.role == role) c.role = ChannelRole::None;
  target->role = role;
  return true;
}

void IdData::setChannel(Channel c) {
  if (!channels.empty() && c.values.size() != samples())
    throw std::invalid_argument("IdData::setChannel: channel '" + c.name + "' has " +
                                std::to_string(c.values.size()) + " samples, the data have " +
                                std::to_string(samples()));
  if (c.unit.empty()) c.unit = unitFromColumnName(c.name);
  if (Channel* existing = channel(c.name))
    *existing = std::move(c);
  else
    channels.push_back(std::move(c));
}

std::string IdData::meta(std::string_view key) const {
  for (const auto& kv : metadata)
    if (kv.first == key) return kv.second;
  return {};
}

void IdData::setMeta(const std::string& key, const std::string& value) {
  for (auto& kv : metadata)
    if (kv.first == key) {
      kv.second = value;
      return;
    }
  metadata.emplace_back(key, value);
}

SampleRange IdData::rangeForTimes(double t0, double t1) const {
  if (t1 < t0) std::swap(t0, t1);
  const std::size_t n = samples();
  if (n == 0) return {};
  auto clampIndex = [&](double x) {
    if (!(x > 0.0)) return std::size_t{0};
    if (x >= static_cast<double>(n)) return n;
    return static_cast<std::size_t>(x);
  };
  std::size_t b = clampIndex(std::ceil((t0 - startTime) / sampleTime - 1e-9));
  std::size_t e = clampIndex(std::floor((t1 - startTime) / sampleTime + 1e-9) + 1.0);
  if (e < b) e = b;
  return {b, e};
}

std::size_t IdData::indexNear(double t) const {
  const std::size_t n = samples();
  if (n == 0) return 0;
  if (timeStamps.empty()) {
    const double pos = std::round((t - startTime) / sampleTime);
    return pos <= 0.0 ? 0 : std::min(n - 1, static_cast<std::size_t>(pos));
  }
  const auto it = std::lower_bound(timeStamps.begin(), timeStamps.end(), t);
  std::size_t i = static_cast<std::size_t>(it - timeStamps.begin());
  if (i >= n) return n - 1;
  if (i > 0 && std::abs(timeStamps[i - 1] - t) < std::abs(timeStamps[i] - t)) --i;
  return i;
}

IdData IdData::select(SampleRange r) const {
  r.end = std::min(r.end, samples());
  r.begin = std::min(r.begin, r.end);
  IdData out;
  out.sampleTime = sampleTime;
  out.startTime = timeAt(r.begin);
  out.metadata = metadata;
  for (const auto& c : channels) {
    Channel nc{c.name, c.unit, c.role, {}};
    nc.values.assign(c.values.begin() + static_cast<std::ptrdiff_t>(r.begin),
                     c.values.begin() + static_cast<std::ptrdiff_t>(r.end));
    out.channels.push_back(std::move(nc));
  }
  auto shift = [&](const std::optional<SampleRange>& in) -> std::optional<SampleRange> {
    if (!in) return std::nullopt;
    std::size_t b = std::clamp(in->begin, r.begin, r.end) - r.begin;
    std::size_t e = std::clamp(in->end, r.begin, r.end) - r.begin;
    if (e <= b) return std::nullopt;
    return SampleRange{b, e};
  };
  out.estimationRange = shift(estimationRange);
  out.validationRange = shift(validationRange);
  auto slice = [&](const auto& v, auto& into) {
    if (v.size() == samples())
      into.assign(v.begin() + static_cast<std::ptrdiff_t>(r.begin), v.begin() + static_cast<std::ptrdiff_t>(r.end));
  };
  slice(timeStamps, out.timeStamps);
  slice(sourceLines, out.sourceLines);
  return out;
}

bool IdData::isValid(std::string* why) const {
  auto fail = [&](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  if (!(sampleTime >= kMinSampleTime) || !std::isfinite(sampleTime))
    return fail("the sample time must be finite and at least 1e-06 s (1 MHz)");
  const std::size_t n = samples();
  if (!timeStamps.empty()) {
    if (timeStamps.size() != n)
      return fail("there are " + std::to_string(timeStamps.size()) + " time stamps for " +
                  std::to_string(n) + " samples");
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(timeStamps[i]))
        return fail("the time stamp of sample " + std::to_string(i) + " is not finite");
  }
  if (!sourceLines.empty() && sourceLines.size() != n)
    return fail("there are " + std::to_string(sourceLines.size()) + " source lines for " +
                std::to_string(n) + " samples");
  for (const auto& c : channels) {
    if (c.values.size() != n)
      return fail("channel '" + c.name + "' has " + std::to_string(c.values.size()) +
                  " samples, expected " + std::to_string(n));
    // A quick pass for long logs: a value is not finite when its exponent bits are all set,
    // and then (and only then) adding 1 to the exponent field carries into the top bit.
    // Integer adds and ors, which the compiler vectorises.
    constexpr std::uint64_t kExponent = 0x7ff0000000000000ull, kExponentOne = 1ull << 52;
    std::uint64_t carries = 0;
    for (double v : c.values) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      carries |= (bits & kExponent) + kExponentOne;
    }
    if (!(carries >> 63)) continue;
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(c.values[i]) && !(std::isnan(c.values[i]) && !timeStamps.empty()))
        return fail("channel '" + c.name + "' has a non-finite value at sample " +
                    std::to_string(i));
  }
  for (const auto* r : {&estimationRange, &validationRange})
    if (*r && (*r)->end > n) return fail("a selected range lies beyond the data");
  return true;
}

}  // namespace flexarm
