#include "core/session/model_entry.h"

#include "core/session/fit_request.h"

namespace flexarm {

const char* toString(ModelOrigin o) {
  switch (o) {
    case ModelOrigin::Hand: return "hand";
    case ModelOrigin::Fit: return "fit";
    case ModelOrigin::Discovery: return "discovery";
    case ModelOrigin::Session: return "session";
  }
  return "hand";
}

std::optional<Provenance> ModelEntry::dataProvenance() const {
  if (estimatedOn) return estimatedOn;
  if (fitRequest && fitRequest->provenance) return fitRequest->provenance;
  return std::nullopt;
}

int ModelEntry::decimation() const {
  return fitRequest && model ? std::max(1, fitRequest->options.decimation) : 1;
}

EvaluatedModel ModelEntry::evaluated() const {
  EvaluatedModel m;
  m.name = name;
  m.physical = model;
  m.effects = model ? effects : std::vector<Effect>{};
  m.polynomial = model ? nullptr : polynomial;
  m.decimation = decimation();
  m.smoothingSpeed = smoothingSpeed;
  m.armOutput = fitRequest && fitRequest->options.model.armOutput;
  return m;
}

std::string ModelEntry::provenanceText() const {
  const ModelOrigin from = fitRequest && origin == ModelOrigin::Hand ? ModelOrigin::Fit : origin;
  std::string s = from == ModelOrigin::Hand ? "by hand" : toString(from);
  if (const auto p = dataProvenance()) s += " on " + shortDescription(*p);
  if (decimation() > 1) s += " at decimation " + std::to_string(decimation());
  if (!effects.empty()) {
    s += ", with ";
    for (std::size_t i = 0; i < effects.size(); ++i) s += (i ? ", " : "") + std::string(toString(effects[i].kind));
  }
  return s;
}

}  // namespace flexarm
