#pragma once
// Provenance of a result: the data an estimate, a discovery, a design or a recursive or
// diagnosis run was computed on (log file name, its SHA-256, the preprocessing steps, the
// ranges) and when. Every result of the workspace carries one, so that a report or a session
// shows what WAS computed on which data and never silently recomputes on another log.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/session/session.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

struct Provenance {
  std::string log;     // the log's file name, e.g. "chirp.csv"
  std::string sha256;  // of the log file's contents
  // How the log was read when it is not a FlexArm log read as it is: which variables or
  // columns, their units, sides, gear ratio and input scale (describeMapping).
  std::vector<std::string> reading;
  // The preprocessing steps in words (describePreprocessing), empty: the log as read.
  std::vector<std::string> preprocessing;
  std::optional<SecondsRange> estimation, validation;
  std::string when;  // UTC, ISO 8601 ("2026-11-24T04:45:00Z")

  bool operator==(const Provenance& o) const;
};

// The current UTC time as ISO 8601 with seconds.
std::string utcNow();

// The provenance of the data a session analyses now: its first log (file name of path, the
// checksum sum), its preprocessing and ranges; `when` is now.
Provenance sessionDataProvenance(const Session& session, const std::string& path, const std::string& sum);

// True when a and b are the same signal: the same log contents read and preprocessed the same
// way.
// Ranges are not compared: every result names the ranges it used and replays them itself.
bool sameData(const Provenance& a, const Provenance& b);

// The data in a few words for names and lists: "chirp.csv 0.5-12 s" (the estimation range;
// "whole log" without one).
std::string shortDescription(const Provenance& p);
// The data in a sentence's clause: "chirp.csv (SHA-256 3f2a..., preprocessed: ...; estimation
// 0.5-12 s, validation 12-18 s)".
std::string longDescription(const Provenance& p);
// Empty when result and open are the same data; otherwise "computed on X; the open log is Y"
// in full (file names, checksums, preprocessing).
std::string dataMismatch(const Provenance& result, const Provenance& open);

// {"log", "sha256", "reading": [..] (when mapped), "preprocessing": [..], "estimation_s",
// "validation_s", "when"}.
nlohmann::json provenanceToJson(const Provenance& p);
// The provenance in j; nullopt with a sentence naming the problem.
std::optional<Provenance> provenanceFromJson(const nlohmann::json& j, std::string* why);
// j["provenance"] when j is an object holding one that parses; nullopt otherwise (sessions
// written before provenance have none).
std::optional<Provenance> provenanceIn(const nlohmann::json& j);

// A model name no entry of `taken` has: "BASE (chirp.csv 0.5-12 s)", then "BASE 2 (...)",
// "BASE 3 (...)" for later results of the same base, whatever data they were computed on.
std::string uniqueResultName(const std::string& base, const Provenance& p,
                             const std::vector<std::string>& taken);

}  // namespace flexarm
