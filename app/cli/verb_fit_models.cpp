// The physical models that `flexarm fit` and `flexarm bode` know by name. This file is the
// single place where core/models is plugged into the verbs.
#include "app/cli/verb_fit.h"
#include "core/models/physical_models.h"

namespace flexarm::cli {

bool isPhysicalModelName(const std::string& name) {
  for (const auto& s : modelStructureNames())
    if (s == name) return true;
  return false;
}

std::unique_ptr<PhysicalModel> makePhysicalModel(const std::string& name) {
  if (!isPhysicalModelName(name)) return nullptr;
  return makeModel(name);  // nominal values: Table 5.2 (two-mass), Table 5.7 p6 (three-mass)
}

}  // namespace flexarm::cli
