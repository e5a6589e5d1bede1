#pragma once
// Progress of long work on the command line: a line on standard error now and then
// ("flexarm fit: 12 % (start 3 of 1000: iteration 4)"), none for work that ends within a
// second, so that quick runs print only their result.
#include <iosfwd>
#include <string>

#include "core/common/progress.h"

namespace flexarm::cli {

// A callback for core's long calls that writes such lines to err; it never cancels.
ProgressCallback progressLine(std::ostream& err, const std::string& verb, double everySeconds = 2.0);

}  // namespace flexarm::cli
