// The physical models that `flexarm fit` and `flexarm bode` know by name. This file is the
// single place where core/models is plugged into the verbs.
#include "app/cli/verb_fit.h"

namespace flexarm::cli {

bool isPhysicalModelName(const std::string& name) {
  return name == "two-mass" || name == "three-mass" || name == "four-mass" || name == "rigid";
}

std::unique_ptr<ParametricModel> makePhysicalModel(const std::string& /*name*/) {
  // core/models provides no physical model in this build yet; when it does, construct the
  // model for `name` here with its nominal values (the seed's Table 5.2 and Section 5.3.2).
  return nullptr;
}

}  // namespace flexarm::cli
