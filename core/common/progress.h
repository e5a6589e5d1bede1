#pragma once
// Progress reporting, cancellation and the way long computations end (the shape of Ceres'
// Solver::Summary): every estimator returns a Termination and a message naming the cause.
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace flexarm {

enum class ProgressAction { Continue, Abort };

// Called from the worker with the fraction done (0..1) and a short stage name. Returning
// Abort asks the computation to stop at the next safe point and report Termination::Cancelled.
using ProgressCallback = std::function<ProgressAction(double fraction, const std::string& stage)>;

enum class Termination { Converged, MaxIterations, Diverged, Cancelled, Failed };

const char* toString(Termination t);
std::optional<Termination> terminationFromString(std::string_view s);

// Calls cb if it is set; true when the caller should stop.
inline bool reportProgress(const ProgressCallback& cb, double fraction, const std::string& stage) {
  return cb && cb(fraction, stage) == ProgressAction::Abort;
}

}  // namespace flexarm
