#pragma once
// Recursive identification (chapter 6) as a session stores it: what the Recursive panel ran -
// the nominal model (an entry of the model list, or a structure's defaults), the log and its
// range, the decimation, and the estimator's design variables - one entry per run (the panel
// overlays runs), with the summary of each result. Replaying a run prepares the log as read
// and runs the estimator again (recursiveIdentification of recursive_log.h, the call the
// command line and the panel make), and writes a report section: the design, the final values
// in the model's names with sigma, the trajectories relative to nominal with their +-3 sigma
// bands (Figures 6.5, 6.7), P's diagonal (Figures 6.6, 6.8) and the prediction errors.
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/models/physical_models.h"
#include "core/recursive/recursive_log.h"
#include "core/session/session_part.h"

namespace flexarm {

struct RecursiveRequest {
  std::string label;                     // the run's name in the panel and the report
  std::string model;                     // an entry of the session's model list; empty: structure
  std::string structure = "three-mass";  // its nominal defaults when model is empty
  std::string log;                       // the session's log name; empty: the first
  RecursiveDataOptions data;
  RecursiveOptions options;
  bool isValid(std::string* why) const;
};

nlohmann::json recursiveRequestToJson(const RecursiveRequest& request);
// The request in j; nullopt with a sentence for a malformed or invalid one.
std::optional<RecursiveRequest> recursiveRequestFromJson(const nlohmann::json& j, std::string* why);

// What a session keeps of a result: termination, message and the final values with sigma in
// the model's names ({"final": {"k_T": ..}, "std": {..}}).
nlohmann::json recursiveResultToJson(const RecursiveResult& result);

// The nominal model of a request in a session (the model list's entry, or the structure's
// defaults); nullptr with a sentence.
std::unique_ptr<PhysicalModel> recursiveNominalModel(const RecursiveRequest& request,
                                                     const Session& session, std::string* why);

// The session part "recursive": {"runs": [{"request": ..., "result": ...}, ...]}.
std::shared_ptr<const SessionPart> makeRecursivePart();

}  // namespace flexarm
