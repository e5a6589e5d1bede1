#include "core/session/model_json.h"
#include "core/common/text.h"

#include <cmath>
#include <set>
#include <stdexcept>

namespace flexarm {

using nlohmann::json;

json modelToJson(const std::string& name, const PhysicalModel& model,
                 const std::vector<Effect>& effects) {
  json params = json::array();
  for (const auto& p : model.parameters())
    params.push_back({{"name", p.name}, {"value", p.value}, {"free", p.free}});
  json fx = json::array();
  for (const auto& e : effects) fx.push_back(toString(e));
  return {{"name", name},
          {"structure", model.structureName()},
          {"output", toString(model.options().output)},
          {"arm_acceleration", model.options().armAcceleration},
          {"parameters", params},
          {"effects", fx}};
}

std::optional<ModelSpec> modelFromJson(const json& j, std::string* why) {
  auto fail = [&](const std::string& s) -> std::optional<ModelSpec> {
    if (why) *why = s;
    return std::nullopt;
  };
  if (!j.is_object()) return fail("a model must be an object");
  if (!j.contains("name") || !j["name"].is_string() || j["name"].get<std::string>().empty())
    return fail("a model needs a name");
  const std::string name = j["name"].get<std::string>();
  if (!j.contains("structure") || !j["structure"].is_string())
    return fail("model '" + name + "': 'structure' is missing");
  ModelOptions options;
  if (j.contains("output")) {
    auto o = j["output"].is_string() ? modelOutputFromString(j["output"].get<std::string>())
                                     : std::nullopt;
    if (!o) return fail("model '" + name + "': unknown output " + j["output"].dump());
    options.output = *o;
  }
  if (j.contains("arm_acceleration")) {
    if (!j["arm_acceleration"].is_boolean())
      return fail("model '" + name + "': arm_acceleration must be true or false");
    options.armAcceleration = j["arm_acceleration"].get<bool>();
  }
  ModelSpec spec;
  spec.name = name;
  try {
    spec.model = std::shared_ptr<PhysicalModel>(makeModel(j["structure"].get<std::string>(), options));
  } catch (const std::invalid_argument& e) {
    return fail("model '" + name + "': " + e.what());
  }
  if (j.contains("parameters")) {
    if (!j["parameters"].is_array()) return fail("model '" + name + "': parameters must be a list");
    if (j["parameters"].size() > spec.model->parameters().size())
      return fail("model '" + name + "': " + std::to_string(j["parameters"].size()) +
                  " parameters listed, but the " + j["structure"].get<std::string>() +
                  " model has " + std::to_string(spec.model->parameters().size()));
    std::set<std::string> seen;
    for (const auto& p : j["parameters"]) {
      if (!p.is_object() || !p.contains("name") || !p["name"].is_string() ||
          !p.contains("value") || !p["value"].is_number())
        return fail("model '" + name + "': each parameter needs a name and a numeric value");
      const std::string pn = p["name"].get<std::string>();
      if (!seen.insert(pn).second)
        return fail("model '" + name + "': parameter " + pn + " is listed twice");
      try {
        spec.model->setParameter(pn, p["value"].get<double>());
        if (p.contains("free")) {
          if (!p["free"].is_boolean())
            return fail("model '" + name + "': parameter " + pn + ": free must be true or false");
          spec.model->setFree(pn, p["free"].get<bool>());
        }
      } catch (const std::invalid_argument& e) {
        return fail("model '" + name + "': parameter " + pn + ": " + e.what());
      }
    }
  }
  if (j.contains("effects")) {
    if (!j["effects"].is_array()) return fail("model '" + name + "': effects must be a list");
    if (j["effects"].size() > kMaxEffects)
      return fail("model '" + name + "': more than " + std::to_string(kMaxEffects) + " effects");
    for (const auto& e : j["effects"]) {
      std::string effectWhy;
      auto effect = e.is_string() ? parseEffect(e.get<std::string>(), &effectWhy) : std::nullopt;
      if (!effect)
        return fail("model '" + name + "': effect " + e.dump() + ": " +
                    (effectWhy.empty() ? "must be text like \"backlash:2e-4\"" : effectWhy));
      spec.effects.push_back(*effect);
    }
  }
  return spec;
}

std::optional<ModelSpec> findListModel(const nlohmann::json& models, const std::string& name,
                                       std::string* why) {
  if (models.is_array())
    for (const auto& m : models) {
      auto spec = modelFromJson(m, why);
      if (spec && spec->name == name) return spec;
    }
  if (why) *why = "the model list has no model named " + inQuotes(name);
  return std::nullopt;
}

}  // namespace flexarm
