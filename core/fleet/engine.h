#pragma once
// A fleet run: every new log of the manifest (by SHA-256 of its bytes and of its axis'
// reference) analysed against its axis' reference, the results committed to the store in
// batches by this process alone, then each axis' trend. Where the analysis runs is the
// engine's business:
//  - local: a pool of threads on this machine;
//  - slurm: a Slurm job array (sbatch), each task a chunk of many logs run by
//    `flexarm fleet --task CHUNK.json --out RESULT.json` on a node, its results written as a
//    file into a shared folder and merged into the store here as they arrive (the store is
//    never opened over a network file system).
// Both call the same functions on the same reference JSON, so they give the same store.
// First the missing references are fitted (one per axis), then the logs are analysed.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/progress.h"
#include "core/fleet/manifest.h"
#include "core/fleet/store.h"
#include "core/fleet/trend.h"

namespace flexarm {

enum class FleetEngine { Local, Slurm };
const char* toString(FleetEngine e);  // "local", "slurm"
std::optional<FleetEngine> fleetEngineFromString(const std::string& s);

struct SlurmOptions {
  std::string executable;       // the flexarm the tasks run (on the nodes' path)
  std::string workDir;          // shared folder for chunks and results; default STORE.slurm
  std::string sbatch = "sbatch", squeue = "squeue", scancel = "scancel";
  std::vector<std::string> sbatchArguments;  // e.g. --partition=night, --account=...
  int logsPerTask = 64;         // logs of one array task (references: a quarter of it)
  int maxTasksAtOnce = 0;       // the array's %N (0: Slurm's limit)
  double timeoutS = 6 * 3600.0; // for each array; then it is cancelled and the rest reported
  double pollS = 0.5;
  bool isValid(std::string* why) const;
};

struct FleetOptions {
  FleetEngine engine = FleetEngine::Local;
  int jobs = 0;                 // local threads (0: one per core)
  int batch = 16;               // results per transaction
  FleetAnalysisOptions analysis;
  TrendOptions trend;
  SlurmOptions slurm;
  // Stop after this many new logs (0: all of them): a partial run, as a run cut short would be.
  int limit = 0;
  bool isValid(std::string* why) const;
};

struct FleetAxisReport {
  std::string robot;
  int axis = 0;
  std::string referenceLog, referenceSha256;
  int logs = 0, failed = 0;
  AxisTrend trend;
  struct LogPoint {              // the analysed logs behind the trend, in time order
    std::string time, path, sha256, verdict;
    double day = 0.0;
    std::optional<double> temperatureC;
  };
  std::vector<LogPoint> points;
};

struct FleetFailure {
  std::string robot;
  int axis = 0;
  std::string time, log, message;
};

struct FleetRunResult {
  Termination termination = Termination::Failed;
  std::string message;
  FleetEngine engine = FleetEngine::Local;
  long runId = 0;
  int analysed = 0, skipped = 0, failed = 0, referencesFitted = 0;
  double seconds = 0.0;
  double analysisSeconds = 0.0;  // the analyses' own time, summed
  std::vector<FleetFailure> failures;
  std::vector<FleetAxisReport> axes;
};

// Runs the fleet. A log that cannot be read or analysed is a failure in the result (stored
// when its bytes could be hashed, so a rerun does not try it again) and the rest goes on.
// Invalid options throw std::invalid_argument; Abort from progress stops after the batch in
// hand (Cancelled, everything analysed so far committed).
FleetRunResult runFleet(const FleetManifest& manifest, FleetStore& store, const FleetOptions& options,
                        const ProgressCallback& progress = {});

// Each stored axis' trend from the store alone (its current reference's logs).
std::vector<FleetAxisReport> fleetTrends(const FleetStore& store, const TrendOptions& options);

// The work of one Slurm array task: fits the references and analyses the logs the chunk
// lists, and writes their results to resultPath (atomically). False with a sentence when the
// chunk cannot be read or the result not written.
bool runFleetTask(const std::string& chunkPath, const std::string& resultPath, std::string* why);

// The failures a run's JSON lists (the rest are counted in failures_not_listed).
inline constexpr std::size_t kListedFailures = 1000;

// JSON of a run: axes [{robot, axis, status, parameter, since, trend, days_to_threshold,
// evidence, suggestion}], maintenance, analysed, skipped, failed, failures, seconds.
nlohmann::json fleetRunJson(const FleetRunResult& r);
nlohmann::json fleetAxisJson(const FleetAxisReport& a);

}  // namespace flexarm
