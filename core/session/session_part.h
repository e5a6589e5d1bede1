#pragma once
// The extension point of sessions and reports. Each capability (the model list, view state,
// and later identification, discovery, LQG, ...) owns one section of the session file under
// "parts"/KEY and contributes its own report sections. A capability adds itself by deriving
// from SessionPart and adding one line to sessionParts() in session_parts.cpp; the window
// side adds the matching capture/restore in app/session_parts.cpp.
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/progress.h"
#include "core/session/provenance.h"
#include "core/session/report.h"
#include "core/session/session.h"
#include "core/signal/id_data.h"

namespace flexarm {

// Items (models, fits, ...) one list of a part may hold: replaying each costs seconds, so a
// file listing thousands would make opening it take hours. Parts refuse longer lists.
inline constexpr std::size_t kMaxPartItems = 100;

// What a part sees when it is replayed: the session, the data the analysis uses
// (preprocessed, ranges set) and every log the session names, read and preprocessed alike.
struct ReplayContext {
  const Session& session;
  const IdData& data;
  const std::vector<std::pair<std::string, const IdData*>>& logs;  // by LogReference::name
  ProgressCallback progress;  // 0..1 of the part's own work; Abort cancels the replay
  // Every log as read, before preprocessing and without ranges (by name); null when the
  // caller has none.
  const std::vector<std::pair<std::string, const IdData*>>* rawLogs = nullptr;
  // The data the session analyses now (its first log as read, preprocessing, ranges); null
  // when the caller has none. A result computed on other data is not recomputed on these.
  const Provenance* open = nullptr;
};

// The sentence saying a result's data differ from the open data (dataMismatch), or empty when
// they are the same, the result has no provenance or the context has no open data.
std::string mismatchWithOpen(const std::optional<Provenance>& result, const ReplayContext& context);

// The log a part names (empty: the session's first) among the context's logs as read (raw) or
// as preprocessed; nullptr with a sentence when there is none.
const IdData* findLog(const ReplayContext& context, const std::string& name, bool raw, std::string* why);

class SessionPart {
 public:
  virtual ~SessionPart() = default;
  // The section's key under "parts", e.g. "models".
  virtual std::string key() const = 0;
  // Checks a section read from a file before anything is opened; false with a sentence
  // naming the problem.
  virtual bool validate(const nlohmann::json& section, std::string* why) const = 0;
  // Recomputes the part's results from the section and appends its report sections. Data
  // failures go into the report as sentences; nothing throws for bad data.
  virtual void replay(const nlohmann::json& section, const ReplayContext& context,
                      Report& report) const = 0;
  // A section whose "provenance" names other data than the open ones: the part shows what
  // was stored, with the mismatch sentence, and recomputes nothing. The default says only
  // that the part was computed on other data.
  virtual void replayStored(const nlohmann::json& section, const std::string& mismatch,
                            Report& report) const;
};

// Every known part, in report order.
const std::vector<std::shared_ptr<const SessionPart>>& sessionParts();
// The part with this key, or nullptr.
const SessionPart* findSessionPart(const std::string& key);

}  // namespace flexarm
