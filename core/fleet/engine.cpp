#include "core/fleet/engine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <sys/stat.h>

#include "core/common/text.h"
#include "core/fleet/work.h"
#include "core/session/sha256.h"

namespace flexarm {

namespace {

using nlohmann::json;

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

json optionalJson(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::string dateOrNull(const std::optional<double>& day) { return day ? isoFromDay(*day) : std::string(); }

// The trend of one stored axis from its logs against the given reference.
FleetAxisReport axisReport(const FleetStore& store, const StoredAxis& a, const TrendOptions& options) {
  FleetAxisReport r;
  r.robot = a.robot;
  r.axis = a.axis;
  r.referenceLog = a.referenceLog;
  r.referenceSha256 = a.referenceSha256;
  std::vector<TrendPoint> points;
  for (const auto& l : store.logs(a.robot, a.axis, a.referenceSha256)) {
    if (!l.result.ok) {
      ++r.failed;
      continue;
    }
    ++r.logs;
    points.push_back({l.day, l.temperatureC, l.result.verdict, l.result.estimates});
    r.points.push_back({l.time, l.path, l.result.sha256, l.result.verdict, l.day, l.temperatureC});
  }
  r.trend = analyseAxisTrend(points, a.referenceTemperatureC, options);
  return r;
}

}  // namespace

const char* toString(FleetEngine e) { return e == FleetEngine::Slurm ? "slurm" : "local"; }

std::optional<FleetEngine> fleetEngineFromString(const std::string& s) {
  if (s == "local") return FleetEngine::Local;
  if (s == "slurm") return FleetEngine::Slurm;
  return std::nullopt;
}

bool SlurmOptions::isValid(std::string* why) const {
  auto fail = [&](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (executable.empty()) return fail("the Slurm engine needs the flexarm executable the tasks run");
  if (logsPerTask < 1 || logsPerTask > 1000000) return fail("logs per Slurm task must lie between 1 and 1000000");
  if (maxTasksAtOnce < 0) return fail("the tasks at once must be 0 (no limit) or more");
  if (!(timeoutS > 0.0 && timeoutS <= 30 * 86400.0))
    return fail("the Slurm timeout (--slurm-timeout) must lie between 0 and 2592000 s (30 days)");
  if (!(pollS > 0.0 && pollS <= 3600.0)) return fail("the Slurm poll interval must lie between 0 and 3600 s");
  auto plain = [](const std::string& s) { return !hasControlCharacter(s); };
  if (!plain(workDir)) return fail("--slurm-dir holds a line break or another control character; give a plain path");
  if (!plain(executable)) return fail("--flexarm holds a line break or another control character; give a plain path");
  for (const auto& a : sbatchArguments)
    if (!plain(a)) return fail("an --sbatch-arg holds a line break or another control character");
  return true;
}

bool FleetOptions::isValid(std::string* why) const {
  if (jobs < 0 || jobs > 1024) {
    if (why) *why = "--jobs must lie between 0 (one per core) and 1024";
    return false;
  }
  if (batch < 1) {
    if (why) *why = "a batch holds at least one result";
    return false;
  }
  if (limit < 0) {
    if (why) *why = "the limit must be 0 (none) or more";
    return false;
  }
  if (!analysis.isValid(why) || !trend.isValid(why)) return false;
  return engine == FleetEngine::Local || slurm.isValid(why);
}

FleetRunResult runFleet(const FleetManifest& manifest, FleetStore& store, const FleetOptions& options,
                        const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("fleet: " + why);
  const auto begin = std::chrono::steady_clock::now();
  FleetRunResult run;
  run.engine = options.engine;
  // One store, one model: its analyses are not comparable with another model's.
  if (const auto model = store.meta("model"); model && *model != options.analysis.model) {
    run.message = store.path() + " holds " + *model + " analyses; the " + options.analysis.model +
                  " model needs a store of its own";
    return run;
  }
  run.runId = store.beginRun(toString(options.engine), manifest.path, &why);
  if (run.runId == 0) {
    run.message = why;
    return run;
  }
  // What the panel needs to show the store as this run saw it.
  store.setMeta("model", options.analysis.model, nullptr);
  store.setMeta("threshold", std::to_string(options.trend.threshold), nullptr);
  auto failEntry = [&](const FleetEntry& e, const std::string& message) {
    run.failures.push_back({e.robot, e.axis, e.time, e.path, message});
    ++run.failed;
  };

  // What is new: every log whose (bytes, reference) pair the store lacks. A file whose size,
  // modification time and inode are as when it was last hashed keeps its checksum.
  const auto stored = store.storedKeys();
  if (const auto bad = store.readError()) {  // what it skips must be what it holds
    run.message = *bad;
    store.finishRun({run.runId, "", "", toString(options.engine), manifest.path, 0, 0, 0, secondsSince(begin)}, nullptr);
    return run;
  }
  std::vector<std::pair<std::string, std::pair<FleetStore::FileStamp, std::string>>> hashed;
  std::map<std::string, std::string> hashedNow;  // path -> SHA-256, this run
  auto hashOf = [&](const std::string& path, std::string* error) -> std::optional<std::string> {
    if (auto it = hashedNow.find(path); it != hashedNow.end()) return it->second;
    auto remember = [&](std::optional<std::string> sha) {
      if (sha) hashedNow[path] = *sha;
      return sha;
    };
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
      const FleetStore::FileStamp stamp{static_cast<long long>(st.st_size),
                                        static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec,
                                        static_cast<long long>(st.st_ino)};
      if (auto known = store.knownSha256(path, stamp)) return remember(known);
      auto sha = sha256OfFile(path, error);
      if (sha) hashed.push_back({path, {stamp, *sha}});
      return remember(sha);
    }
    return remember(sha256OfFile(path, error));
  };
  fleet::WorkChunk fits, logs;
  fits.options = logs.options = options.analysis;
  std::vector<const FleetEntry*> logEntry;             // LogJob id -> entry
  std::vector<const FleetAxis*> fitAxis;               // ReferenceJob id -> axis
  std::map<std::string, std::vector<std::size_t>> waiting;  // reference SHA -> its log jobs
  std::map<std::string, std::string> referenceSha;     // axis key -> reference SHA
  int newLogs = 0;
  // Rows whose logs have the same bytes (the same file twice, or a copy) against the same
  // reference are one recording: the first row is analysed and stored, each other one is
  // reported with the row it repeats, every run alike.
  std::map<std::pair<std::string, std::string>, const FleetEntry*> firstRow;
  for (const auto& axis : manifest.axes) {
    const FleetEntry& ref = manifest.entries[axis.referenceEntry];
    const auto refSha = hashOf(ref.path, &why);
    if (!refSha) {
      for (std::size_t i : axis.entries)
        failEntry(manifest.entries[i], "the axis' reference log " + ref.path + " cannot be read: " + why);
      continue;
    }
    referenceSha[axis.key()] = *refSha;
    const auto known = store.axis(axis.robot, axis.axis);
    const bool haveReference = known && known->referenceSha256 == *refSha;
    if (haveReference) logs.references[*refSha] = known->referenceJson;
    bool needFit = !haveReference;
    for (std::size_t i : axis.entries) {
      const FleetEntry& e = manifest.entries[i];
      const auto sha = hashOf(e.path, &why);
      if (!sha) {
        failEntry(e, e.path + ": " + why);
        continue;
      }
      const auto [first, isNew] = firstRow.emplace(std::make_pair(*sha, *refSha), &e);
      if (!isNew) {
        failEntry(e, "line " + std::to_string(e.line) + " names a log of the same bytes as line " +
                         std::to_string(first->second->line) + " (" + first->second->log +
                         "): one recording is analysed and stored once; remove one of the rows");
        continue;
      }
      if (stored.count({*sha, *refSha})) {
        ++run.skipped;
        continue;
      }
      if (options.limit > 0 && newLogs >= options.limit) continue;
      ++newLogs;
      const std::size_t id = logEntry.size();
      logEntry.push_back(&e);
      logs.logs.push_back({id, e.path, *refSha});
      if (!haveReference) waiting[*refSha].push_back(id);
    }
    if (needFit && waiting.count(*refSha)) {
      fits.fits.push_back({fitAxis.size(), ref.path, *refSha});
      fitAxis.push_back(&axis);
    }
  }
  store.putSha256(hashed, nullptr);  // only saves time on the next run
  const std::size_t total = fits.size() + logs.size();
  std::size_t done = 0;
  bool cancelled = false;
  auto step = [&](const std::string& stage) {
    ++done;
    if (reportProgress(progress, total ? static_cast<double>(done) / static_cast<double>(total) : 1.0, stage))
      cancelled = true;
    return !cancelled;
  };

  // Phase 1: the references the store lacks, each committed as it arrives.
  std::map<std::string, std::string> refused;  // reference SHA -> why it could not be fitted
  fleet::Sinks sinks;
  sinks.reference = [&](const fleet::ReferenceOutcome& r) {
    const FleetAxis& axis = *fitAxis[r.id];
    const FleetEntry& ref = manifest.entries[axis.referenceEntry];
    const std::string sha = fits.fits[r.id].sha256;
    if (r.ok) {
      StoredAxis a{axis.robot, axis.axis, sha, ref.path, ref.temperatureC, r.json};
      std::string e;
      if (store.putAxis(a, &e)) {
        logs.references[sha] = r.json;
        ++run.referencesFitted;
      } else {
        refused[sha] = e;
      }
    } else {
      refused[sha] = r.message;
    }
    return step("references");
  };
  sinks.lost = [&](std::size_t id, bool isReference, const std::string& reason) {
    if (isReference) refused[fits.fits[id].sha256] = reason;
    else {
      failEntry(*logEntry[id], reason);
      step("logs");
    }
  };
  const std::string runDir = options.slurm.workDir.empty() ? store.path() + ".slurm/run-" + std::to_string(run.runId)
                                                           : options.slurm.workDir + "/run-" + std::to_string(run.runId);
  auto execute = [&](const fleet::WorkChunk& work, const std::string& part) {
    return options.engine == FleetEngine::Slurm ? fleet::runOnSlurm(work, options.slurm, runDir + "/" + part, sinks, &why)
                                                : fleet::runLocally(work, options.jobs, sinks, &why);
  };
  bool engineOk = execute(fits, "references");

  // Phase 2: the logs of every axis with a reference, committed in batches by this thread.
  fleet::WorkChunk ready;
  ready.options = logs.options;
  ready.references = logs.references;
  for (const auto& job : logs.logs) {
    if (!engineOk || cancelled) break;
    if (auto r = refused.find(job.referenceSha256); r != refused.end()) {
      failEntry(*logEntry[job.id], "the axis' reference could not be fitted: " + r->second);
      continue;
    }
    if (!ready.references.count(job.referenceSha256)) {
      failEntry(*logEntry[job.id], "the axis has no reference");
      continue;
    }
    ready.logs.push_back(job);
  }
  std::vector<StoredLog> pending;
  std::string storeError;
  auto flush = [&] {
    if (pending.empty()) return true;
    std::string e;
    if (!store.putLogs(pending, run.runId, &e)) {
      storeError = e;
      return false;
    }
    pending.clear();
    return true;
  };
  sinks.log = [&](std::size_t id, FleetLogResult result) {
    const FleetEntry& e = *logEntry[id];
    run.analysisSeconds += result.seconds;
    if (result.ok) ++run.analysed;
    else failEntry(e, result.message);
    if (!result.sha256.empty()) {
      pending.push_back({e.robot, e.axis, e.time, e.day, e.path, e.temperatureC, e.reference ? "reference" : "",
                         std::move(result)});
    }
    if (pending.size() >= static_cast<std::size_t>(options.batch) && !flush()) return false;
    return step("logs");
  };
  if (engineOk && !cancelled) engineOk = execute(ready, "logs");
  flush();
  if (!engineOk) {
    run.message = "the " + std::string(toString(options.engine)) + " engine could not run: " + why;
  } else if (!storeError.empty()) {
    run.message = storeError;
  } else {
    run.termination = cancelled ? Termination::Cancelled : Termination::Converged;
    run.message = cancelled ? "cancelled; every result so far is stored"
                            : std::to_string(run.analysed) + " logs analysed, " + std::to_string(run.skipped) +
                                  " already stored, " + std::to_string(run.failed) + " failed";
  }
  run.seconds = secondsSince(begin);
  store.finishRun({run.runId, "", "", toString(options.engine), manifest.path, run.analysed, run.skipped, run.failed,
                   run.seconds},
                  nullptr);

  // The trends of the manifest's axes.
  for (const auto& axis : manifest.axes) {
    const auto a = store.axis(axis.robot, axis.axis);
    if (!a || referenceSha[axis.key()] != a->referenceSha256) continue;
    run.axes.push_back(axisReport(store, *a, options.trend));
  }
  if (const auto bad = store.readError()) {  // a trend of part of the logs is not reported as whole
    run.termination = Termination::Failed;
    run.message = *bad;
  }
  return run;
}

std::vector<FleetAxisReport> fleetTrends(const FleetStore& store, const TrendOptions& options) {
  std::vector<FleetAxisReport> out;
  for (const auto& a : store.axes()) out.push_back(axisReport(store, a, options));
  return out;
}

json fleetAxisJson(const FleetAxisReport& a) {
  const AxisTrend& t = a.trend;
  json series = json::object();
  for (const auto& s : t.series) {
    json x = {{"kind", s.kind}, {"scatter", s.scatter}, {"reference", s.reference}, {"level", s.level}};
    if (s.kind == "step") x["step"] = s.size;
    if (s.kind == "drift") x["slope_per_day"] = s.slope;
    if (s.since) x["since"] = isoFromDay(*s.since);
    series[s.name] = x;
  }
  json trend = {{"slope_per_day", optionalJson(t.slopePerDay)},
                {"slope_99", t.slopePerDay ? json{*t.slopeLow, *t.slopeHigh} : json(nullptr)},
                {"step", optionalJson(t.stepSize)},
                {"threshold", t.threshold},
                {"days_to_threshold_99", t.daysToThreshold ? json{optionalJson(t.daysLow), optionalJson(t.daysHigh)}
                                                           : json(nullptr)},
                {"crossing", t.crossingDay ? json(isoFromDay(*t.crossingDay)) : json(nullptr)},
                {"temperature",
                 {{"alpha_per_degc", t.temperature.termination == Termination::Converged
                                         ? json(t.temperature.model.alpha) : json(nullptr)},
                  {"alpha_std", t.temperature.termination == Termination::Converged
                                    ? json(t.temperature.model.alphaStd) : json(nullptr)},
                  {"reference_c", optionalJson(t.referenceTemperatureC)},
                  {"note", t.temperature.message}}},
                {"parameters", series}};
  return {{"robot", a.robot},
          {"axis", a.axis},
          {"status", t.status},
          {"parameter", t.parameter.empty() ? json(nullptr) : json(t.parameter)},
          {"since", t.since ? json(dateOrNull(t.since)) : json(nullptr)},
          {"trend", trend},
          {"days_to_threshold", optionalJson(t.daysToThreshold)},
          {"evidence", t.evidence},
          {"caveat", t.caveat.empty() ? json(nullptr) : json(t.caveat)},
          {"suggestion", t.suggestion},
          {"service_at_next_stop", t.serviceAtNextStop},
          {"logs", a.logs},
          {"failed", a.failed},
          {"reference_log", a.referenceLog}};
}

json fleetRunJson(const FleetRunResult& r) {
  json axes = json::array(), maintenance = json::array(), failures = json::array();
  std::vector<const FleetAxisReport*> due;
  for (const auto& a : r.axes) {
    axes.push_back(fleetAxisJson(a));
    if (a.trend.serviceAtNextStop) due.push_back(&a);
  }
  std::stable_sort(due.begin(), due.end(), [](const FleetAxisReport* x, const FleetAxisReport* y) {
    return x->trend.daysToThreshold.value_or(1e9) < y->trend.daysToThreshold.value_or(1e9);
  });
  for (const auto* a : due)
    maintenance.push_back({{"robot", a->robot}, {"axis", a->axis}, {"parameter", a->trend.parameter},
                           {"status", a->trend.status}, {"days_to_threshold", optionalJson(a->trend.daysToThreshold)},
                           {"suggestion", a->trend.suggestion}});
  // At most kListedFailures are listed (a manifest of missing files would print them all).
  for (std::size_t i = 0; i < std::min(r.failures.size(), kListedFailures); ++i) {
    const auto& f = r.failures[i];
    failures.push_back({{"robot", f.robot}, {"axis", f.axis}, {"time", f.time}, {"log", f.log}, {"message", f.message}});
  }
  return {{"engine", toString(r.engine)},
          {"run", r.runId},
          {"termination", toString(r.termination)},
          {"message", r.message},
          {"analysed", r.analysed},
          {"skipped", r.skipped},
          {"failed", r.failed},
          {"references_fitted", r.referencesFitted},
          {"failures", failures},
          {"failures_not_listed", r.failures.size() - std::min(r.failures.size(), kListedFailures)},
          {"axes", axes},
          {"maintenance", maintenance},
          {"seconds", r.seconds},
          {"analysis_seconds", r.analysisSeconds}};
}

}  // namespace flexarm
