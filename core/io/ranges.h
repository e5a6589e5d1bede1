#pragma once
// Estimation and validation ranges stored in a log's metadata as seconds, e.g.
// "# estimation_range_s: 0.5:12" and "# validation_range_s: 12:20".
#include <string>

#include "core/signal/id_data.h"

namespace flexarm {

inline constexpr const char* kEstimationRangeKey = "estimation_range_s";
inline constexpr const char* kValidationRangeKey = "validation_range_s";

// Parses "A:B" (seconds, A < B); false when malformed.
bool parseSecondsRange(const std::string& text, double& t0, double& t1);
// "A:B" for a sample range of data, in seconds.
std::string formatSecondsRange(const IdData& data, const SampleRange& r);

// Sets data's ranges from its metadata; false with a message when a stored range is malformed.
bool applyStoredRanges(IdData& data, std::string* why);
// Writes data's ranges into its metadata (removing keys of absent ranges).
void storeRanges(IdData& data);

}  // namespace flexarm
