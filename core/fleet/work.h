#pragma once
// The work a fleet run hands to an engine (core/fleet/engine.h): references to fit and logs to
// analyse, each with an id the coordinator maps back to its manifest entry, and the results as
// they come back. The chunk's JSON is what a Slurm task reads; its result's JSON what it writes.
#include <atomic>
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/fleet/engine.h"

namespace flexarm::fleet {

struct ReferenceJob {
  std::size_t id = 0;
  std::string log, sha256;
};

struct LogJob {
  std::size_t id = 0;
  std::string log;
  std::string referenceSha256;  // a key of WorkChunk::references
};

struct WorkChunk {
  FleetAnalysisOptions options;
  std::vector<ReferenceJob> fits;
  std::vector<LogJob> logs;
  std::map<std::string, std::string> references;  // reference SHA-256 -> referenceToJson text
  std::size_t size() const { return fits.size() + logs.size(); }
};

struct ReferenceOutcome {
  std::size_t id = 0;
  bool ok = false;
  std::string message;
  std::string json;  // referenceToJson text when ok
};

// Where results go, on the coordinator's thread; returning false asks the engine to stop
// taking new work.
struct Sinks {
  std::function<bool(const ReferenceOutcome&)> reference;
  std::function<bool(std::size_t id, FleetLogResult)> log;
  // An item the engine could not run at all (a task that died): the sentence says why.
  std::function<void(std::size_t id, bool isReference, const std::string& why)> lost;
};

// One item, as every engine runs it.
ReferenceOutcome fitReference(const ReferenceJob& job, const FleetAnalysisOptions& options);
FleetLogResult analyseLog(const LogJob& job, const WorkChunk& chunk);

nlohmann::json chunkJson(const WorkChunk& chunk);
bool chunkFromJson(const nlohmann::json& j, WorkChunk& chunk, std::string* why);
nlohmann::json referenceOutcomeJson(const ReferenceOutcome& r);

// The engines. Both return false with a sentence when they cannot run at all (then nothing
// was lost: the coordinator reports every item not delivered).
bool runLocally(const WorkChunk& work, int jobs, const Sinks& sinks, std::string* why);
bool runOnSlurm(const WorkChunk& work, const SlurmOptions& options, const std::string& runDir,
                const Sinks& sinks, std::string* why);

}  // namespace flexarm::fleet
