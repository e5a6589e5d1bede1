#pragma once
// A model of the shared model list as session JSON: its name, structure (makeModel name),
// output options, every parameter's value and free flag, and the effects switched on.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/models/effects.h"
#include "core/models/physical_models.h"

namespace flexarm {

struct ModelSpec {
  std::string name;
  std::shared_ptr<PhysicalModel> model;
  std::vector<Effect> effects;
};

nlohmann::json modelToJson(const std::string& name, const PhysicalModel& model,
                           const std::vector<Effect>& effects);

// Effects one model may carry (there are six kinds).
inline constexpr std::size_t kMaxEffects = 16;

// The model described by j; nullopt with a sentence for an unknown structure or parameter, a
// value outside its bounds, a parameter listed twice or more often than the structure has
// parameters, or a malformed effect.
std::optional<ModelSpec> modelFromJson(const nlohmann::json& j, std::string* why);

// The model named `name` in a session's "models" part (a list of modelToJson objects);
// nullopt with a sentence when there is none by that name.
std::optional<ModelSpec> findListModel(const nlohmann::json& models, const std::string& name,
                                       std::string* why);

}  // namespace flexarm
