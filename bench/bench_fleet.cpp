// The plant (`flexarm fleet`): how many daily 12 s logs a minute the local engine analyses and
// stores on this machine's two cores, at 1x, 4x and 16x the fleet (1, 4 and 16 robots of six
// axes, twelve days each, made by `flexarm simulate --fleet` at 2 kHz), and whether it grows
// linearly; what a rerun of the 16x store costs when nothing is new; where a log's time goes (hashing, reading, the chapter 6-7 diagnosis, the store);
// and, on a one-node Slurm when one answers (SLURM_CONF), the Slurm engine's time and a job
// array task's overhead, the numbers behind docs/plant.md's cluster size for 10 000 robots x 6
// axes a night. The peer at 1x is what a user would run without the fleet: `flexarm diagnose`
// for every log against its axis' reference (fitted anew each time), in a shell loop of two
// at once; the logs' verdicts are compared.
#include <sys/resource.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <set>

#include "bench_common.h"
#include "core/diagnosis/diagnosis.h"
#include "core/fleet/log_analysis.h"
#include "core/fleet/manifest.h"
#include "core/fleet/store.h"
#include "core/io/log_io.h"
#include "core/session/sha256.h"

using namespace flexarm;
using namespace flexarm::bench;

namespace {

double wallNow() { return now(false); }

// The manifest's entries of robots R01..Rk, with absolute paths.
std::string subset(const FleetManifest& m, int robots, const std::string& path) {
  std::vector<FleetEntry> entries;
  for (const auto& e : m.entries)
    if (std::stoi(e.robot.substr(1)) <= robots) {
      entries.push_back(e);
      entries.back().log = e.path;
    }
  std::ofstream(path) << fleetManifestText(entries);
  return path;
}

// How many axes the run named as the truth file says (status and parameter).
std::pair<int, int> namedAsTruth(const Json& run, const Json& truth, int robots) {
  std::map<std::string, const Json*> found;
  for (const auto& a : run.at("axes"))
    found[a.at("robot").get<std::string>() + "/" + std::to_string(a.at("axis").get<int>())] = &a;
  int right = 0, total = 0;
  for (const auto& t : truth.at("axes")) {
    if (std::stoi(t.at("robot").get<std::string>().substr(1)) > robots) continue;
    ++total;
    const auto it = found.find(t.at("robot").get<std::string>() + "/" + std::to_string(t.at("axis").get<int>()));
    if (it == found.end()) continue;
    const std::string scenario = t.at("scenario");
    const std::string want = scenario == "healthy" ? "healthy" : scenario == "wear" ? "drift" : "fault";
    right += it->second->at("status") == want &&
             (scenario == "healthy" || it->second->at("parameter") == t.at("parameter"));
  }
  return {right, total};
}

}  // namespace

int main() {
  const std::string exe = FLEXARM_EXECUTABLE;
  TempDir dir("flexarm-bench-fleet");
  const int days = 12, axes = 6;
  const std::string plant = dir.file("plant");
  bool ok = true;
  std::cerr << "bench_fleet: simulating 16 robots x 6 axes x 12 days at 2 kHz...\n";
  capture(exe + " simulate --fleet " + plant + " --robots 16 --axes 6 --days 12 --rate 2000 --seed 3 --wear 8 "
                "--loads 8 --faults 8 --json",
          &ok);
  ManifestError merr;
  const auto manifest = readFleetManifest(plant + "/manifest.csv", &merr);
  if (!ok || !manifest) {
    std::cerr << "bench_fleet: the plant could not be simulated: " << merr.toString() << "\n";
    return 1;
  }
  const Json truth = Json::parse(std::ifstream(plant + "/truth.json"));

  double perLogAt1 = 0.0, wall16 = 0.0;
  for (int scale : {1, 4, 16}) {
    const std::string m = subset(*manifest, scale, dir.file("manifest-" + std::to_string(scale) + ".csv"));
    const std::string db = dir.file("fleet-" + std::to_string(scale) + ".sqlite");
    const double cpu0 = childCpuSeconds(), t0 = wallNow();
    const std::string out = capture(exe + " fleet " + m + " --db " + db + " --json", &ok);
    const double wall = wallNow() - t0, cpu = childCpuSeconds() - cpu0;
    const Json run = ok ? Json::parse(out) : Json();
    const int logs = scale * axes * days;
    Row row;
    row.group = "fleet (the plant)";
    row.task = "flexarm fleet, local engine: new daily logs diagnosed (chapters 6-7) and stored";
    row.size = std::to_string(logs) + " logs of 12 s at 2 kHz (" + std::to_string(scale) + " robot" +
               (scale > 1 ? "s" : "") + " x 6 axes x 12 days)";
    row.flexarmSeconds = wall;
    row.scale = scale;
    row.extra["logs_per_minute"] = logs / wall * 60.0;
    row.extra["cpu_s_per_log"] = cpu / logs;
    row.extra["logs_per_minute_cpu_bound_2_cores"] = 2.0 * 60.0 * logs / cpu;
    const auto [right, total] = ok ? namedAsTruth(run, truth, scale) : std::pair<int, int>{0, scale * axes};
    row.agree = ok && run.at("analysed") == logs && right == total;
    char text[300];
    std::snprintf(text, sizeof text,
                  "%d of %d axes named as the truth; %.0f logs a minute (wall), %.0f ms of CPU a log, "
                  "%.0f a minute if the two cores were ours",
                  right, total, logs / wall * 60.0, 1e3 * cpu / logs, 2.0 * 60.0 * logs / cpu);
    row.agreement = text;
    if (scale == 1) {
      perLogAt1 = wall / logs;
      // The peer: flexarm diagnose for each log against its axis' reference, two at a time.
      std::map<std::string, std::string> reference;
      for (const auto& a : manifest->axes) reference[a.key()] = manifest->entries[a.referenceEntry].path;
      const std::string script = dir.file("peer.sh");
      {
        std::ofstream s(script);
        for (const auto& e : manifest->entries) {
          if (std::stoi(e.robot.substr(1)) > 1) continue;
          s << exe << " diagnose " << e.path << " --reference-log " << reference[e.robot + "/" + std::to_string(e.axis)]
            << " --model three-mass --json > " << e.path << ".diagnosis.json\n";
        }
      }
      const double p0 = wallNow();
      capture("xargs -P 2 -d '\\n' -I CMD sh -c CMD < " + script, &ok);
      row.peer = "flexarm diagnose per log (reference fitted each time), 2 at once";
      row.peerSeconds = wallNow() - p0;
      // Same verdicts, log by log.
      std::string why;
      auto store = FleetStore::open(db, false, &why);
      int same = 0, compared = 0;
      for (const auto& l : store ? store->logs() : std::vector<StoredLog>{}) {
        std::ifstream f(l.path + ".diagnosis.json");
        if (!f) continue;
        try {
          const Json d = Json::parse(f);
          ++compared;
          same += d.at("verdict").get<std::string>() == l.result.verdict;
        } catch (const std::exception&) {
        }
      }
      row.agree = *row.agree && compared == logs && same == compared;
      row.agreement += "; per-log verdicts " + std::to_string(same) + " of " + std::to_string(compared) +
                       " as flexarm diagnose's";
    } else {
      row.peer = "none at this size (the peer runs at 1x)";
      row.extra["per_log_over_1x"] = (wall / logs) / perLogAt1;
    }
    emit(row);
    if (scale == 16) wall16 = wall;
  }

  // A rerun of the 16x store with nothing new: every log known by its checksum, kept with its
  // file's size, modification time and inode, so no log is read again.
  {
    const std::string m = dir.file("manifest-16.csv"), db = dir.file("fleet-16.sqlite");
    const double cpu0 = childCpuSeconds(), t0 = wallNow();
    const std::string out = capture(exe + " fleet " + m + " --db " + db + " --json", &ok);
    const double wall = wallNow() - t0, cpu = childCpuSeconds() - cpu0;
    const Json run = ok ? Json::parse(out) : Json();
    const int logs = 16 * axes * days;
    Row row;
    row.group = "fleet (the plant)";
    row.task = "flexarm fleet rerun, nothing new: every log skipped by its stored checksum";
    row.size = std::to_string(logs) + " logs of 12 s at 2 kHz (16 robots x 6 axes x 12 days, 2 GB)";
    row.flexarmSeconds = wall;
    row.peer = "the first run of the same store";
    row.peerSeconds = wall16;
    row.agree = ok && run.at("analysed") == 0 && run.at("skipped") == logs && run.at("failed") == 0;
    char text[200];
    std::snprintf(text, sizeof text, "%d analysed, %d skipped; %.2f s of CPU", ok ? run.at("analysed").get<int>() : -1,
                  ok ? run.at("skipped").get<int>() : -1, cpu);
    row.agreement = text;
    row.extra["cpu_s"] = cpu;
    emit(row);
  }

  // Where a log's time goes, in this process, one log at a time (R01 axis 1's logs).
  {
    FleetAnalysisOptions options;
    const FleetAxis& a = manifest->axes.front();
    const DiagnosisReference ref = fleetReference(manifest->entries[a.referenceEntry].path, options);
    double sha = 0, read = 0, whole = 0;
    std::vector<StoredLog> results;
    for (std::size_t i : a.entries) {
      const std::string& path = manifest->entries[i].path;
      double t = now(true);
      (void)sha256OfFile(path, nullptr);
      sha += now(true) - t;
      t = now(true);
      (void)readLog(path);
      read += now(true) - t;
      t = now(true);
      StoredLog l;
      l.result = analyseFleetLog(path, ref, options);
      l.result.referenceSha256 = std::string(64, '0');  // one reference for the timing store
      whole += now(true) - t;
      l.robot = "R01";
      l.axis = static_cast<int>(results.size());
      results.push_back(l);
    }
    std::string why;
    auto store = FleetStore::open(dir.file("timing.sqlite"), true, &why);
    double t = now(true);
    if (!store || !store->putLogs(results, 1, &why)) std::fprintf(stderr, "bench_fleet: %s\n", why.c_str());
    const double write = now(true) - t;
    const double n = static_cast<double>(a.entries.size());
    Row row;
    row.group = "fleet (the plant)";
    row.task = "one log's CPU time: SHA-256, read, diagnosis (chapters 6-7), store";
    row.size = "12 s at 2 kHz, 1.75 MB";
    row.flexarmSeconds = whole / n + write / n;
    row.peer = "none (the parts of the row above)";
    char text[300];
    std::snprintf(text, sizeof text,
                  "SHA-256 %.1f ms, read %.1f ms, diagnosis %.1f ms (the recursive estimators and tests at 200 Hz), "
                  "store %.2f ms; target 300 ms (400 logs a minute on 2 cores)",
                  1e3 * sha / n, 1e3 * read / n, 1e3 * (whole - sha - read) / n, 1e3 * write / n);
    row.agreement = text;
    row.agree = (whole + write) / n < 0.3;
    row.extra["sha_ms"] = 1e3 * sha / n;
    row.extra["read_ms"] = 1e3 * read / n;
    row.extra["diagnosis_ms"] = 1e3 * (whole - sha - read) / n;
    row.extra["store_ms"] = 1e3 * write / n;
    row.extra["clock"] = "cpu";
    emit(row);
  }

  // Slurm, when one answers: the engine on the 1x fleet, and the overhead of an array task.
  bool slurm = false;
  capture("sinfo -h > /dev/null 2>&1", &slurm);
  if (slurm) {
    const std::string m = dir.file("manifest-1.csv");
    const std::string db = dir.file("fleet-slurm.sqlite");
    const double t0 = wallNow();
    const std::string out = capture(exe + " fleet " + m + " --db " + db + " --engine slurm --logs-per-task 64 --json", &ok);
    const double wall = wallNow() - t0;
    // An array of 16 tasks that do nothing: what each task costs Slurm on this node.
    const std::string job = dir.file("empty.sh");
    std::ofstream(job) << "#!/bin/sh\n#SBATCH --output=/dev/null\ntrue\n";
    const double e0 = wallNow();
    bool submitted = false;
    capture("sbatch --wait --array=0-15 " + job + " > /dev/null 2>&1", &submitted);
    const double empty = wallNow() - e0;
    Row row;
    row.group = "fleet (the plant)";
    row.task = "flexarm fleet, Slurm engine (one node, 2 cores), chunks of 64 logs";
    row.size = "72 logs of 12 s at 2 kHz (1 robot x 6 axes x 12 days)";
    row.flexarmSeconds = wall;
    row.peer = "the local engine, same logs";
    row.peerSeconds = perLogAt1 * 72;
    row.agree = ok && Json::parse(out).at("analysed") == 72;
    char text[200];
    std::snprintf(text, sizeof text, "every log analysed; an empty array task costs %.2f s on this node (16 in %.1f s)",
                  submitted ? empty / 16 : -1.0, empty);
    row.agreement = text;
    row.extra["slurm_task_overhead_s"] = submitted ? empty / 16 : -1.0;
    emit(row);
  } else {
    std::cerr << "bench_fleet: no Slurm answers (sinfo); the Slurm row is left out\n";
  }
  return 0;
}
