#include "core/fleet/work.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>
#include <variant>

#include "core/session/json_fields.h"
#include "core/io/log_io.h"

namespace flexarm::fleet {

using nlohmann::json;

ReferenceOutcome fitReference(const ReferenceJob& job, const FleetAnalysisOptions& options) {
  ReferenceOutcome out;
  out.id = job.id;
  const DiagnosisReference ref = fleetReference(job.log, options);
  if (!ref.ok()) {
    out.message = job.log + ": " + ref.message;
    return out;
  }
  out.ok = true;
  out.message = ref.source;
  out.json = referenceToJson(ref).dump();
  return out;
}

FleetLogResult analyseLog(const LogJob& job, const WorkChunk& chunk) {
  FleetLogResult r;
  const auto it = chunk.references.find(job.referenceSha256);
  std::string why;
  std::optional<DiagnosisReference> ref;
  if (it != chunk.references.end()) {
    try {
      ref = referenceFromJson(json::parse(it->second), &why);
    } catch (const json::exception& e) {
      why = jsonErrorText(e);
    }
  } else {
    why = "the chunk lacks the reference " + job.referenceSha256;
  }
  if (!ref) {
    r.message = job.log + ": no usable reference: " + why;
  } else {
    r = analyseFleetLog(job.log, *ref, chunk.options);
  }
  r.referenceSha256 = job.referenceSha256;
  return r;
}

json chunkJson(const WorkChunk& c) {
  json fits = json::array(), logs = json::array(), refs = json::object();
  for (const auto& f : c.fits) fits.push_back({{"id", f.id}, {"log", f.log}, {"sha256", f.sha256}});
  for (const auto& l : c.logs) logs.push_back({{"id", l.id}, {"log", l.log}, {"reference_sha256", l.referenceSha256}});
  for (const auto& [sha, text] : c.references) refs[sha] = json::parse(text);
  return {{"format", "flexarm-fleet-chunk"},
          {"version", 1},
          {"model", c.options.model},
          {"settled_fraction", c.options.settledFraction},
          {"fits", fits},
          {"logs", logs},
          {"references", refs}};
}

bool chunkFromJson(const json& j, WorkChunk& c, std::string* why) {
  try {
    if (j.at("format").get<std::string>() != "flexarm-fleet-chunk" || j.at("version").get<int>() != 1) {
      if (why) *why = "not a FlexArm fleet chunk of version 1";
      return false;
    }
    c = {};
    c.options.model = j.at("model").get<std::string>();
    c.options.settledFraction = j.at("settled_fraction").get<double>();
    for (const auto& f : j.at("fits"))
      c.fits.push_back({f.at("id").get<std::size_t>(), f.at("log").get<std::string>(), f.at("sha256").get<std::string>()});
    for (const auto& l : j.at("logs"))
      c.logs.push_back({l.at("id").get<std::size_t>(), l.at("log").get<std::string>(),
                        l.at("reference_sha256").get<std::string>()});
    for (const auto& [sha, ref] : j.at("references").items()) c.references[sha] = ref.dump();
  } catch (const json::exception& e) {
    if (why) *why = std::string("malformed chunk: ") + jsonErrorText(e);
    return false;
  }
  return c.options.isValid(why);
}

json referenceOutcomeJson(const ReferenceOutcome& r) {
  return {{"id", r.id}, {"ok", r.ok}, {"message", r.message}, {"reference", r.ok ? json::parse(r.json) : json(nullptr)}};
}

bool runLocally(const WorkChunk& work, int jobs, const Sinks& sinks, std::string* why) {
  (void)why;
  using Outcome = std::variant<ReferenceOutcome, std::pair<std::size_t, FleetLogResult>>;
  const std::size_t total = work.size();
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex m;
  std::condition_variable ready;
  std::deque<Outcome> done;
  std::size_t finishedWorkers = 0;
  const unsigned threads = static_cast<unsigned>(std::clamp<std::size_t>(
      jobs > 0 ? static_cast<std::size_t>(jobs) : std::max(1u, std::thread::hardware_concurrency()), 1,
      std::max<std::size_t>(1, total)));
  auto worker = [&] {
    for (std::size_t i; !stop && (i = next++) < total;) {
      Outcome o = i < work.fits.size()
                      ? Outcome(fitReference(work.fits[i], work.options))
                      : Outcome(std::make_pair(work.logs[i - work.fits.size()].id,
                                               analyseLog(work.logs[i - work.fits.size()], work)));
      std::lock_guard<std::mutex> lock(m);
      done.push_back(std::move(o));
      ready.notify_one();
    }
    std::lock_guard<std::mutex> lock(m);
    ++finishedWorkers;
    ready.notify_one();
  };
  std::vector<std::thread> pool;
  for (unsigned k = 0; k < threads; ++k) pool.emplace_back(worker);
  // This thread is the one writer: it hands every result to the sinks as it arrives.
  while (true) {
    std::unique_lock<std::mutex> lock(m);
    ready.wait(lock, [&] { return !done.empty() || finishedWorkers == threads; });
    if (done.empty()) break;
    Outcome o = std::move(done.front());
    done.pop_front();
    lock.unlock();
    bool more = true;
    if (auto* r = std::get_if<ReferenceOutcome>(&o)) more = sinks.reference(*r);
    else {
      auto& [id, result] = std::get<1>(o);
      more = sinks.log(id, std::move(result));
    }
    if (!more) stop = true;
  }
  for (auto& t : pool) t.join();
  return true;
}

}  // namespace flexarm::fleet

namespace flexarm {

bool runFleetTask(const std::string& chunkPath, const std::string& resultPath, std::string* why) {
  std::string text;
  {
    std::FILE* f = std::fopen(chunkPath.c_str(), "rb");
    if (!f) {
      if (why) *why = chunkPath + ": cannot be opened";
      return false;
    }
    char buf[65536];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
    std::fclose(f);
  }
  fleet::WorkChunk chunk;
  std::string err;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    if (why) *why = chunkPath + ": " + jsonErrorText(e);
    return false;
  }
  if (!fleet::chunkFromJson(j, chunk, &err)) {
    if (why) *why = chunkPath + ": " + err;
    return false;
  }
  nlohmann::json fits = nlohmann::json::array(), logs = nlohmann::json::array();
  for (const auto& f : chunk.fits) fits.push_back(fleet::referenceOutcomeJson(fleet::fitReference(f, chunk.options)));
  for (const auto& l : chunk.logs) {
    auto r = fleetLogResultJson(fleet::analyseLog(l, chunk));
    r["id"] = l.id;
    logs.push_back(std::move(r));
  }
  const nlohmann::json result = {{"format", "flexarm-fleet-result"}, {"version", 1}, {"fits", fits}, {"logs", logs}};
  if (!writeFileAtomically(resultPath, result.dump() + "\n", &err)) {
    if (why) *why = err;
    return false;
  }
  return true;
}

}  // namespace flexarm
