#pragma once
// The fleet manifest: which daily logs belong to which robot's axis, when each was recorded,
// at what temperature, and which one is the axis' fault-free reference.
//
//     # flexarm-fleet: 1
//     robot,axis,time,log,temperature_c,role
//     R01,1,2026-03-01T06:00:00Z,R01/ax1/2026-03-01.csv,24.5,reference
//     R01,1,2026-03-02T06:00:00Z,R01/ax1/2026-03-02.csv,31.0,
//
// Paths are relative to the manifest (absolute ones are kept; a log must lie inside the
// manifest's folder unless ManifestReadOptions::allowLogsOutside), times are UTC in ISO 8601
// (seconds optional, "Z" or no zone), the temperature (degC) may be empty, and role
// "reference" marks an axis' healthy reference; without one, the axis' earliest log is. The
// columns may come in any order; temperature_c and role may be left out.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

struct FleetEntry {
  std::string robot;
  int axis = 0;
  std::string time;              // as written
  double day = 0.0;              // days since 1970-01-01T00:00:00Z
  std::string log;               // as written
  std::string path;              // resolved against the manifest's folder
  std::optional<double> temperatureC;
  bool reference = false;        // role "reference"
  int line = 0;                  // in the manifest, 1-based
};

struct FleetAxis {
  std::string robot;
  int axis = 0;
  std::string key() const;                // "R01/1"
  std::size_t referenceEntry = 0;         // index into FleetManifest::entries
  std::vector<std::size_t> entries;       // every log of the axis in time order (reference too)
};

struct FleetManifest {
  std::string path;                       // the manifest file
  std::vector<FleetEntry> entries;        // in file order
  std::vector<FleetAxis> axes;            // sorted by robot, then axis
  const FleetAxis* axis(const std::string& robot, int axis) const;
};

struct ManifestError {
  std::string file;
  int line = 0;
  std::string column;   // the column's name, when the problem is one field
  std::string problem;
  // "fleet.csv:7: column time: '2026-13-01' is not an ISO 8601 UTC time"
  std::string toString() const;
};

struct ManifestReadOptions {
  // A log must lie inside the manifest's folder (after links are resolved): a row naming
  // /etc/passwd or ../../x is refused before anything is read. True lets logs lie anywhere.
  bool allowLogsOutside = false;
  // The most rows a manifest may have (a plant of 100 robots x 6 axes x a year is 219 000).
  std::size_t maxRows = 500000;
};

// Reads a manifest file (at most 1 GiB); nullopt with the error naming file, line, column and
// problem for a missing version line, unknown or missing columns, a malformed field, the same
// robot, axis and time twice, two references for one axis, a log outside the manifest's
// folder, more rows than the budget, or text that is not UTF-8 (a UTF-8 byte-order mark is
// accepted; UTF-16 is named).
std::optional<FleetManifest> readFleetManifest(const std::string& path, ManifestError* error,
                                               const ManifestReadOptions& options = {});
// The same on text in memory; `path` names it in messages and relative logs resolve against
// its folder.
std::optional<FleetManifest> parseFleetManifest(std::string_view text, const std::string& path,
                                                ManifestError* error, const ManifestReadOptions& options = {});

// "2026-03-01T06:00:00Z" -> days since the epoch; nullopt when malformed.
std::optional<double> parseIsoDay(std::string_view text);
// Days since the epoch -> "2026-03-01T06:00:00Z" (to the second).
std::string isoFromDay(double day);

// The manifest's text for entries (header and rows; paths as `log` holds them).
std::string fleetManifestText(const std::vector<FleetEntry>& entries);

}  // namespace flexarm
