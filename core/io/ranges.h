#pragma once
// Estimation and validation ranges stored in a log's metadata as seconds, e.g.
// "# estimation_range_s: 0.5:12" and "# validation_range_s: 12:20".
#include <string>

#include "core/signal/id_data.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

inline constexpr const char* kEstimationRangeKey = "estimation_range_s";
inline constexpr const char* kValidationRangeKey = "validation_range_s";

// Sets data's ranges from its metadata; false with a message when a stored range is malformed.
bool applyStoredRanges(IdData& data, std::string* why);
// Writes data's ranges into its metadata (removing keys of absent ranges).
void storeRanges(IdData& data);

}  // namespace flexarm
