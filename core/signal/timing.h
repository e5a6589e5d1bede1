#pragma once
// Irregular time stamps of a log: the nominal sample interval and grid, and every place where
// the stamps leave it - jitter (a sample off its grid point), gaps (dropped samples),
// duplicates (the same time twice) and reversals (time running backwards) - with the time,
// the sample and the file line.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class TimingEventKind { Jitter, Gap, Duplicate, Reversal };
const char* toString(TimingEventKind k);
std::optional<TimingEventKind> timingEventKindFromString(std::string_view s);

struct TimingEvent {
  TimingEventKind kind = TimingEventKind::Jitter;
  std::size_t index = 0;  // sample in file order (0-based)
  int line = 0;           // line in the file, 0 when not read from a file
  double time = 0.0;      // the sample's time stamp, seconds
  // Jitter: deviation from the grid point as a fraction of the interval. Gap: seconds from
  // the previous sample. Duplicate: 0. Reversal: seconds back from the previous line's time.
  double size = 0.0;
  long missing = 0;  // Gap: samples missing in it
};

struct TimingOptions {
  double jitterTolerance = 0.01;  // deviation from the grid (fraction of the interval) allowed
  double declaredRateHz = 0.0;    // sample_rate_hz of the log's metadata, 0 when none
  std::size_t maxEvents = 100000; // events listed; the counts always cover all
  bool isValid(std::string* why) const;
};

struct TimingReport {
  std::size_t samples = 0;
  // The grid: gridStart + k interval, k = 0 .. gridPoints - 1, fitted to the stamps (the
  // declared rate when the stamps agree with it).
  double interval = 0.0;
  double gridStart = 0.0;
  std::size_t gridPoints = 0;
  std::size_t jitter = 0, gaps = 0, missing = 0, duplicates = 0, reversals = 0;
  double largestJitter = 0.0;  // fraction of the interval
  double longestGap = 0.0;     // seconds between the samples around it
  double longestGapTime = 0.0; // time of the sample after it
  std::vector<TimingEvent> events;  // in time order (reversals where they occur in the file)
  bool truncated = false;           // more events than TimingOptions::maxEvents

  bool regular() const { return jitter + gaps + duplicates + reversals == 0; }
  double rateHz() const { return interval > 0.0 ? 1.0 / interval : 0.0; }
  // One sentence, e.g. "2 gaps (3 samples missing, the longest 1.5 ms at 12.3 s, line
  // 24605), 4 jittered samples (up to 3.0 % of the 0.5 ms interval)".
  std::string summary() const;
};

// Analyses time stamps in file order; lines (optional, same length) are the file lines of
// the samples. Throws std::invalid_argument for invalid options or a non-finite stamp.
TimingReport analyzeTiming(const std::vector<double>& time, const std::vector<int>& lines = {},
                           const TimingOptions& options = {});

// "line 24605" or "sample 24603" for an event.
std::string placeOf(const TimingEvent& e);

// A duration in words for messages: "1.5 ms", "2 s".
std::string durationText(double seconds);
// A number in a message, printf-formatted: formatted("%.6g Hz", rate).
std::string formatted(const char* format, double value);

}  // namespace flexarm
