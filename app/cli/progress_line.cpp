#include "app/cli/progress_line.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <ostream>

namespace flexarm::cli {

ProgressCallback progressLine(std::ostream& err, const std::string& verb, double everySeconds) {
  struct State {
    std::mutex mutex;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last = start;
    bool printed = false;
  };
  auto state = std::make_shared<State>();
  return [&err, verb, everySeconds, state](double fraction, const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(state->mutex);
    const double sinceStart = std::chrono::duration<double>(now - state->start).count();
    const double sinceLast = std::chrono::duration<double>(now - state->last).count();
    if (sinceStart < 1.0 || (state->printed && sinceLast < everySeconds)) return ProgressAction::Continue;
    state->last = now;
    state->printed = true;
    const double percent = std::isfinite(fraction) ? std::floor(100.0 * std::clamp(fraction, 0.0, 1.0)) : 0.0;
    err << "flexarm " << verb << ": " << percent << " %";
    if (!stage.empty()) err << " (" << stage << ")";
    err << std::endl;
    return ProgressAction::Continue;
  };
}

}  // namespace flexarm::cli
