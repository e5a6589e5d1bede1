#include "core/session/replay.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "core/common/text.h"
#include "core/session/session_part.h"
#include "core/session/sha256.h"
#include "core/signal/preprocess.h"

namespace flexarm {

bool ReplayOptions::isValid(std::string* why) const {
  for (const auto& [name, path] : substitutes)
    if (name.empty() || path.empty()) {
      if (why) *why = "a substituted log needs NAME=PATH";
      return false;
    }
  return true;
}

PreparedSession prepareSession(const Session& session, const std::string& sessionPath,
                               const std::map<std::string, std::string>& substitutes) {
  PreparedSession out;
  for (const auto& [name, path] : substitutes) {
    bool known = false;
    for (const auto& l : session.logs) known = known || l.name == name;
    if (!known) {
      out.message = "the session has no log named " + inQuotes(name);
      return out;
    }
  }
  for (const auto& ref : session.logs) {
    PreparedLog log;
    log.name = ref.name;
    auto sub = substitutes.find(ref.name);
    log.path = sub != substitutes.end() ? sub->second : resolveLogPath(sessionPath, ref.path);
    std::string why;
    auto sum = sha256OfFile(log.path, &why);
    if (!sum) {
      out.message = "log '" + ref.name + "': " + why;
      return out;
    }
    log.sha256 = *sum;
    if (sub != substitutes.end()) {
      log.note = "substituted";
    } else if (log.sha256 != ref.sha256) {
      log.note = "changed since the session was saved";
      out.warnings.push_back("log '" + ref.name + "' (" + log.path +
                             ") changed since the session was saved: its SHA-256 is " +
                             log.sha256 + ", the session recorded " + ref.sha256);
    }
    LogReadResult read = readLog(log.path, ref.read);
    if (!read.ok) {
      out.message = "log '" + ref.name + "': " + read.error.toString();
      return out;
    }
    log.raw = std::move(read.data);
    try {
      if (session.preprocessed && session.preprocess.range && !session.preprocess.resample &&
          session.preprocess.range->end > log.raw.samples())
        throw std::invalid_argument("the preprocessing keeps samples up to " +
                                    std::to_string(session.preprocess.range->end) +
                                    " but the log has " + std::to_string(log.raw.samples()));
      log.data = session.preprocessed ? preprocess(log.raw, session.preprocess) : log.raw;
    } catch (const std::invalid_argument& e) {
      out.message = "log '" + ref.name + "': preprocessing failed: " + e.what();
      return out;
    }
    // The ranges belong to the analysed (first) log; parts name their own ranges on the others.
    const bool analysed = out.logs.empty();
    auto apply = [&](const std::optional<SecondsRange>& r, std::optional<SampleRange>& target,
                     const char* what) {
      target.reset();
      if (!r) return;
      SampleRange s = log.data.rangeForTimes(r->start, r->end);
      if (s.empty() && !analysed) return;
      if (s.empty())
        out.warnings.push_back(std::string("the ") + what + " range " + formatSignificant(r->start) +
                               "-" + formatSignificant(r->end) + " s lies outside log '" +
                               ref.name + "'");
      else
        target = s;
    };
    apply(session.estimation, log.data.estimationRange, "estimation");
    apply(session.validation, log.data.validationRange, "validation");
    out.logs.push_back(std::move(log));
  }
  out.ok = true;
  return out;
}

namespace {

// The "Data" section: what was read and how it was prepared.
ReportSection dataSection(const Session& session, const PreparedSession& prepared) {
  ReportSection s;
  s.title = "Data";
  ReportTable logs{"Logs", {"Log", "File", "Samples", "Rate (Hz)", "SHA-256"}, {}};
  nlohmann::json logsJson = nlohmann::json::array();
  for (const auto& l : prepared.logs) {
    logs.rows.push_back({l.name + (l.note.empty() ? "" : " (" + l.note + ")"),
                         std::filesystem::path(l.path).filename().string(),
                         std::to_string(l.raw.samples()), formatSignificant(l.raw.sampleRateHz(), 6),
                         l.sha256});
    logsJson.push_back({{"name", l.name}, {"samples", l.raw.samples()},
                        {"rate_hz", l.raw.sampleRateHz()}, {"sha256", l.sha256}});
  }
  s.tables.push_back(logs);
  // How each log was read when it is not a FlexArm log read as it is, and what was assumed.
  for (std::size_t i = 0; i < session.logs.size() && i < prepared.logs.size(); ++i) {
    const std::vector<std::string> reading = describeMapping(session.logs[i].read.mapping);
    std::string text;
    for (const auto& r : reading) text += (text.empty() ? "" : "; ") + r;
    if (!text.empty()) s.paragraphs.push_back("Log '" + prepared.logs[i].name + "' read with " + text + ".");
    if (const std::string assumed = prepared.logs[i].raw.meta("assumed"); !assumed.empty())
      s.paragraphs.push_back("Log '" + prepared.logs[i].name + "', not said and so assumed: " + assumed + ".");
    if (i == 0 && !reading.empty()) s.values["reading"] = reading;
  }
  const IdData& d = prepared.logs.front().data;
  ReportTable channels{"Channels of '" + prepared.logs.front().name + "' as analysed",
                       {"Channel", "Unit", "Role"}, {}};
  for (const auto& c : d.channels) channels.rows.push_back({c.name, c.unit, toString(c.role)});
  s.tables.push_back(channels);
  const auto steps = describePreprocessing(session.preprocess);
  if (!session.preprocessed || steps.empty()) {
    s.paragraphs.push_back("No preprocessing: the log is analysed as read.");
  } else {
    std::string text = "Preprocessing (Section 5.2 order): ";
    for (std::size_t i = 0; i < steps.size(); ++i)
      text += (i ? "; " : "") + std::to_string(i + 1) + ". " + steps[i];
    s.paragraphs.push_back(text + ". Result: " + std::to_string(d.samples()) + " samples at " +
                           formatSignificant(d.sampleRateHz(), 6) + " Hz.");
  }
  ReportTable ranges{"Ranges", {"Range", "From (s)", "To (s)", "Samples"}, {}};
  nlohmann::json rangesJson = nlohmann::json::object();
  auto addRange = [&](const char* name, const std::optional<SecondsRange>& r,
                      const std::optional<SampleRange>& samples) {
    if (!r) return;
    const std::size_t n = samples ? samples->size() : 0;
    ranges.rows.push_back({name, formatSignificant(r->start, 6), formatSignificant(r->end, 6),
                           std::to_string(n)});
    rangesJson[name] = {{"start_s", r->start}, {"end_s", r->end}, {"samples", n}};
  };
  addRange("estimation", session.estimation, d.estimationRange);
  addRange("validation", session.validation, d.validationRange);
  if (ranges.rows.empty()) s.paragraphs.push_back("No estimation or validation range is set.");
  else s.tables.push_back(ranges);
  for (const Channel* c : {d.input(), d.output()}) {
    if (!c) continue;
    ReportSeries series{c->name, {}, {}, false};
    const std::size_t step = std::max<std::size_t>(1, d.samples() / 3000);
    for (std::size_t i = 0; i < d.samples(); i += step) {
      series.x.push_back(d.timeAt(i));
      series.y.push_back(c->values[i]);
    }
    s.plots.push_back(ReportPlot{std::string(c == d.input() ? "Input " : "Output ") + c->name,
                                 "time (s)", c->name + " (" + c->unit + ")", false, false, {series}});
  }
  s.values = {{"logs", logsJson},
              {"samples", d.samples()},
              {"rate_hz", d.sampleRateHz()},
              {"preprocessing", session.preprocessed ? steps : std::vector<std::string>{}},
              {"ranges", rangesJson}};
  return s;
}

}  // namespace

ReplayResult replaySession(const Session& session, const std::string& sessionPath,
                           const ReplayOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument(why);
  const auto t0 = std::chrono::steady_clock::now();
  ReplayResult r;
  r.report.flexarmVersion = FLEXARM_VERSION;
  r.report.session = sessionPath;
  auto finish = [&](Termination t, std::string message) {
    r.termination = t;
    r.message = std::move(message);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  };
  if (reportProgress(options.progress, 0.0, "reading logs")) return finish(Termination::Cancelled, "cancelled");
  PreparedSession prepared = prepareSession(session, sessionPath, options.substitutes);
  if (!prepared.ok) {
    r.badInput = true;
    return finish(Termination::Failed, prepared.message);
  }
  for (const auto& l : prepared.logs) r.report.logs.push_back({l.name, l.path, l.sha256, l.note});
  r.report.warnings = prepared.warnings;
  r.report.sections.push_back(dataSection(session, prepared));
  std::vector<std::pair<std::string, const IdData*>> logs;
  std::vector<std::pair<std::string, const IdData*>> rawLogs;
  for (const auto& l : prepared.logs) {
    logs.emplace_back(l.name, &l.data);
    rawLogs.emplace_back(l.name, &l.raw);
  }
  const Provenance open =
      sessionDataProvenance(session, prepared.logs.front().path, prepared.logs.front().sha256);
  ReplayContext context{session, prepared.logs.front().data, logs, options.progress, &rawLogs, &open};
  const auto& parts = sessionParts();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string key = parts[i]->key();
    if (!session.parts.contains(key)) continue;
    const double lo = 0.1 + 0.9 * static_cast<double>(i) / parts.size();
    const double hi = 0.1 + 0.9 * static_cast<double>(i + 1) / parts.size();
    if (reportProgress(options.progress, lo, key)) return finish(Termination::Cancelled, "cancelled");
    // The part reports 0..1 of its own work; the caller sees it within the part's share.
    ReplayContext partContext = context;
    partContext.progress = [&options, lo, hi](double f, const std::string& stage) {
      return options.progress ? options.progress(lo + (hi - lo) * std::clamp(f, 0.0, 1.0), stage)
                              : ProgressAction::Continue;
    };
    // A part that records the data of its result (section "provenance") is not recomputed on
    // other data: it shows what it stored and says on which data that was.
    const nlohmann::json& section = session.parts[key];
    if (const std::string other = mismatchWithOpen(provenanceIn(section), context); !other.empty()) {
      parts[i]->replayStored(section, other, r.report);
      continue;
    }
    parts[i]->replay(section, partContext, r.report);
  }
  return finish(Termination::Converged, "replayed " + std::to_string(r.report.sections.size()) +
                                            " report sections");
}

}  // namespace flexarm
