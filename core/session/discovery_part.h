#pragma once
// Discovery as a session stores it: what the Discovery panel was asked (the base model by its
// name in the model list or a nominal structure, which log and range are estimation data and
// which validation data, the options) and the summary of what it found (the verdict, the
// effect's parameters with their standard deviations, the evidence, every candidate's
// scores). Replaying the request runs discoverMissingEffect again on the session's data and
// writes the report section: verdict and evidence, the candidate table, the base and augmented
// fit % (5.2) and residual RMS, and the before/after plots of the motor velocity and residual.
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/discovery/discovery.h"
#include "core/session/session.h"
#include "core/session/session_part.h"

namespace flexarm {

// One data set of a discovery request: a log of the session and a range on it.
struct DiscoveryDataRef {
  std::string log;  // the session's log name; empty: the first log (the one analysed)
  std::optional<SecondsRange> range;  // unset: the whole log
};

struct DiscoveryRequest {
  std::string baseModel;      // an entry of the session's model list; empty: baseStructure
  std::string baseStructure;  // a nominal structure with a gear spring (two-, three-, four-mass)
  // Whether the logs are used as read (true) or preprocessed as the session says (false, as
  // the window's workspace holds them).
  bool rawData = false;
  DiscoveryDataRef estimation;
  std::optional<DiscoveryDataRef> validation;  // none: no validation data
  DiscoveryOptions options;
  bool isValid(std::string* why) const;
};

nlohmann::json discoveryRequestToJson(const DiscoveryRequest& request);
// The request in j; nullopt with a sentence for a malformed one.
std::optional<DiscoveryRequest> discoveryRequestFromJson(const nlohmann::json& j, std::string* why);

// The summary of a result a session keeps: verdict, tie, evidence, the disagreement summary,
// base and augmented scores, and every candidate's effect, parameters (value, std, interval),
// loss, validation RMS, AIC, F and its threshold, significance and reason. No traces, models
// or maps.
nlohmann::json discoveryResultToJson(const DiscoveryResult& result);
// A result holding the summary fields only (traces, models and the map stay empty); nullopt
// with a sentence for a malformed summary.
std::optional<DiscoveryResult> discoveryResultFromJson(const nlohmann::json& j, std::string* why);

// The session part "discovery": {"request": ..., "result": ...} (the result may be absent).
std::shared_ptr<const SessionPart> makeDiscoveryPart();

}  // namespace flexarm
