#pragma once
// Ranges of a log given in seconds, as users, sessions and log metadata name them
// ("2.5:10"), and their conversion to the sample ranges of a data set (IdData), which differ
// with the data's rate (after decimation) while the seconds stay.
#include <optional>
#include <string>

#include "core/signal/id_data.h"

namespace flexarm {

// A time range in seconds, start < end.
struct SecondsRange {
  double start = 0.0;
  double end = 0.0;
  bool operator==(const SecondsRange& o) const { return start == o.start && end == o.end; }
  bool operator!=(const SecondsRange& o) const { return !(*this == o); }
};

// Parses "A:B" (seconds, A < B); false when malformed.
bool parseSecondsRange(const std::string& text, double& t0, double& t1);
// The same as a range; nullopt with a sentence quoting the text when malformed.
std::optional<SecondsRange> secondsRangeFromText(const std::string& text, std::string* why);

// "A:B" for a sample range of data, in seconds (first and last sample's times).
std::string formatSecondsRange(const IdData& data, const SampleRange& r);

// The samples of data whose time lies in r (IdData::rangeForTimes); empty when none does.
SampleRange samplesIn(const IdData& data, const SecondsRange& r);
// The seconds of a sample range of data: from its first to its last sample's time.
SecondsRange secondsOf(const IdData& data, const SampleRange& r);

// Whether two experiments (a log, or a range of it: unset, the whole log) hold the same
// samples: the same sample time, the same channels by name and unit, and the same values. A
// repeated experiment is the same evidence whatever file or range it was read from, and an
// estimator that counted it twice would narrow its intervals by sqrt(2).
bool sameSamples(const IdData& a, const std::optional<SecondsRange>& rangeA, const IdData& b,
                 const std::optional<SecondsRange>& rangeB);

}  // namespace flexarm
