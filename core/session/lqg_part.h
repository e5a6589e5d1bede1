#pragma once
// An LQG design as a session stores it: what the LQG panel holds (the two-mass parameters of
// Figure 8.1 with where they came from, the measurement, the weights Q1, Q2 of (8.17) and the
// noise intensities R1, R2 of (8.16), the input saturation limit). Replaying it runs
// analyzeLqg again and writes the report section: the options table, the stability verdicts
// of the regulator and of the closed loop, max |S| and the distance to -1 (8.38), Bode's
// integral (8.37), the encirclements of -1 by F_y G, the Nyquist curve and |S|, |T| (8.36).
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/control/lqg_analysis.h"
#include "core/session/session_part.h"

namespace flexarm {

struct LqgRequest {
  std::string source = "Table 8.1";  // where the parameters came from, in words
  LqgOptions design;
  double saturationLimit = 0.0;  // > 0: the disturbance steps also with |u| <= limit
  double taBandwidth = 0.0;      // rad/s for the Section 8.4 criterion; 0 skips it
  // The analysis options the request implies (the rest at their defaults).
  LqgAnalysisOptions analysisOptions() const;
  bool isValid(std::string* why) const;
};

nlohmann::json lqgRequestToJson(const LqgRequest& request);
// The request in j; nullopt with a sentence for a malformed or invalid one.
std::optional<LqgRequest> lqgRequestFromJson(const nlohmann::json& j, std::string* why);

// The session part "lqg".
std::shared_ptr<const SessionPart> makeLqgPart();

}  // namespace flexarm
