#pragma once
// The model list a session holds, without a window: the "models" part's physical models with
// their effects and provenance, each with the fit request of the "fits" part that produced it
// (its rate, ranges and data), and the black-box estimates stored with their requests. The
// window's session restore and the command line's evaluations (`flexarm compare --session`)
// read the list the same way.
#include "core/session/model_list.h"
#include "core/session/session.h"

namespace flexarm {

// The list of a validated session (parseSession has checked its parts; malformed items are
// skipped). Fit requests whose estimate is neither in the models part nor stored are left out.
ModelList modelListOf(const Session& session);

}  // namespace flexarm
