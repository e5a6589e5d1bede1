#include "core/common/progress.h"

namespace flexarm {

const char* toString(Termination t) {
  switch (t) {
    case Termination::Converged: return "converged";
    case Termination::MaxIterations: return "max-iterations";
    case Termination::Diverged: return "diverged";
    case Termination::Cancelled: return "cancelled";
    case Termination::Failed: return "failed";
  }
  return "failed";
}

std::optional<Termination> terminationFromString(std::string_view s) {
  for (Termination t : {Termination::Converged, Termination::MaxIterations, Termination::Diverged,
                        Termination::Cancelled, Termination::Failed})
    if (s == toString(t)) return t;
  return std::nullopt;
}

}  // namespace flexarm
