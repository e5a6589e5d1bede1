// Step 5 for physical fits: the sentences that say a parameter is physically absurd
// (FitResult::plausibility), beside the numbers in the text, the JSON and the Fit panel.
#include <cmath>
#include <cstdio>

#include "core/common/text.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit_internal.h"

namespace flexarm::fit_detail {
namespace {

std::string g(double v) { return shortNumber(v); }

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// The range of robot axes FlexArm knows, referred to the arm side (gear ratio r), from a small
// arm (the seed's IRB 1400: J_a 12 kg m^2, k 1.5e5 N m/rad) to a heavy one (a KR300's axis
// one: inertias of thousands of kg m^2, stiffnesses of 1e7 N m/rad); a value more than a
// hundred times outside it is absurd for any robot axis.
struct Range {
  const char* what;
  double lo, hi;
};
constexpr Range kMotorInertia{"a robot motor's inertia", 1e-5, 1e-1};
constexpr Range kArmInertia{"the inertia of a robot axis behind its gear", 1e-1, 1e5};
constexpr Range kStiffness{"a robot gear's or arm's stiffness", 1e4, 1e8};
constexpr double kMargin = 100.0;

}  // namespace

bool sitsOnBound(const FitResult& r, const std::string& name) {  // said by the bound's own warning
  for (const auto& w : r.warnings)
    if (w.rfind(name + " sits on its", 0) == 0) return true;
  return false;
}

void plausibilityChecks(const FitOptions& o, FitResult& r) {
  if (o.model.kind != FitModelKind::Physical || r.parameters.empty()) return;
  const double z = twoSidedNormalQuantile(o.level);
  auto onBound = [&r](const std::string& name) { return sitsOnBound(r, name); };
  for (const auto& p : r.parameters) {
    if (!p.free || !std::isfinite(p.value) || onBound(p.name)) continue;
    if (std::isfinite(p.std) && z * p.std > std::abs(p.value))
      r.plausibility.push_back(p.name + " = " + g(p.value) + " +- " + g(p.std) + ": its " + g(100.0 * o.level) +
                               " % interval [" + g(p.lower) + ", " + g(p.upper) +
                               "] is wider than the value, so the data do not determine it");
  }
  if (!r.physical) return;
  const PhysicalModel& m = *r.physical;
  const double ratio = m.value("r");
  // Inverse dynamics reports its own rows; the rigid model behind them only carries them.
  const bool inverse = o.method != FitMethod::PredictionError;
  // Motor-side parameters (r = 1) put the arm's inertia and stiffness times r_true^2: the
  // absolute ranges hold only for arm-side ones.
  const bool armSide = ratio < 0.5;
  for (const auto& p : m.parameters()) {
    if (!p.free || inverse) continue;
    const Range* range = nullptr;
    if (p.name == "J_m" && armSide) range = &kMotorInertia;  // with r = 1 J_m may be the whole axis
    else if (startsWith(p.name, "J_") && armSide) range = &kArmInertia;
    else if (startsWith(p.name, "k_") && p.name != "k_T" && armSide) range = &kStiffness;
    if (!range) continue;
    if (p.value < range->lo / kMargin || p.value > range->hi * kMargin)
      r.plausibility.push_back(p.name + " = " + g(p.value) + " " + p.unit + " lies " +
                               (p.value < range->lo ? "far below " : "far above ") + range->what + " (" +
                               g(range->lo) + " to " + g(range->hi) + " " + p.unit + ", r = " + g(ratio) + ")");
  }
  // Every resonance must lie where the data can see it.
  auto velocity = std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(m.clone().release()));
  velocity->setOptions(ModelOptions{});
  const double nyquist = M_PI / r.data.sampleTime;
  for (const auto& mode : peakFrequencies(velocity->stateSpace()))
    if (mode.frequency > nyquist && !inverse)
      r.plausibility.push_back("the estimate resonates at " + g(mode.frequency) + " rad/s, above the data's Nyquist "
                               "frequency " + g(nyquist) + " rad/s: the data cannot see that mode, so its spring "
                               "and damper are not determined");
  const IdData& log = *o.estimation.front().data;
  bool rGiven = false;
  for (const auto& v : o.startValues) rGiven = rGiven || v.name == "r";
  if (log.meta("gear_ratio").empty() && !rGiven && m.structureName() != "two-mass-theta" && !inverse)
    r.plausibility.push_back("the log states no gear ratio (metadata gear_ratio), so r = " + g(ratio) +
                             " is the model's default, not this axis's: the arm-side inertias and stiffnesses "
                             "are referred through a ratio nobody set (give --start r=VALUE, or the log's "
                             "gear ratio when it is read)");
}

}  // namespace flexarm::fit_detail
