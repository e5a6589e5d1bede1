#include "core/session/session_models.h"

#include "core/session/fit_request.h"
#include "core/session/model_json.h"

namespace flexarm {

ModelList modelListOf(const Session& session) {
  ModelList list;
  const nlohmann::json& parts = session.parts;
  if (parts.contains("models") && parts["models"].is_array())
    for (const auto& m : parts["models"]) {
      std::string why;
      auto spec = modelFromJson(m, &why);
      if (!spec) continue;
      ModelEntry e;
      e.name = spec->name;
      e.model = spec->model;
      e.effects = spec->effects;
      e.origin = ModelOrigin::Session;
      e.estimatedOn = provenanceIn(m);
      list.insert(list.size(), std::move(e));
    }
  if (!parts.contains("fits") || !parts["fits"].is_object() || !parts["fits"].contains("requests")) return list;
  for (const auto& j : parts["fits"]["requests"]) {
    std::string why;
    auto request = fitRequestFromJson(j, &why);
    if (!request) continue;
    auto shared = std::make_shared<const FitRequest>(*request);
    const int at = list.indexOf(request->name);
    if (at >= 0 && !list[static_cast<std::size_t>(at)].fitRequest) {
      ModelEntry e = list[static_cast<std::size_t>(at)];
      e.fitRequest = shared;
      e.origin = ModelOrigin::Fit;
      list.replace(static_cast<std::size_t>(at), std::move(e));
      continue;
    }
    if (request->physical() || !j.contains("estimate")) continue;
    auto estimate = polynomialEstimateFromJson(j["estimate"], *request, &why);
    if (!estimate) continue;
    ModelEntry e;
    e.name = request->name;
    e.polynomial = std::make_shared<const PolynomialModel>(std::move(*estimate));
    e.fitRequest = shared;
    e.origin = ModelOrigin::Fit;
    list.insert(list.size(), std::move(e));
  }
  return list;
}

}  // namespace flexarm
