#include "core/models/two_mass_lqg_reduction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "core/models/analysis.h"

namespace flexarm {

const char* toString(TwoMassReduction r) {
  switch (r) {
    case TwoMassReduction::MergeMasses:
      return "merge-masses";
    case TwoMassReduction::MatchFirstMode:
      return "match-first-mode";
  }
  return "?";
}

std::optional<TwoMassReduction> twoMassReductionFromString(std::string_view s) {
  for (auto r : {TwoMassReduction::MergeMasses, TwoMassReduction::MatchFirstMode})
    if (s == toString(r)) return r;
  return std::nullopt;
}

bool TwoMassReductionOptions::isValid(std::string* why) const {
  if (!twoMassReductionFromString(toString(method))) {
    if (why) *why = "unknown reduction method";
    return false;
  }
  return true;
}

namespace {

// The two-mass model (3.13) in physical parameters, converting (5.5) when needed.
std::unique_ptr<PhysicalModel> physicalTwoMass(const PhysicalModel& m) {
  auto out = makeModel("two-mass");
  for (const char* name : {"r", "k_T"}) out->setParameter(name, m.value(name));
  if (m.structureName() == "two-mass-theta") {
    double t[5];
    for (int i = 0; i < 5; ++i) t[i] = m.value("theta_" + std::to_string(i + 1));
    const TwoMassPhysical q = twoMassFromTheta(t, m.value("r"));
    out->setParameter("J_m", q.J_m);
    out->setParameter("J_a", q.J_a);
    out->setParameter("f_m", q.f_m);
    out->setParameter("k_a", q.k);
    out->setParameter("d_a", q.d);
  } else {
    for (const char* name : {"J_m", "J_a", "f_m", "k_a", "d_a"})
      out->setParameter(name, m.value(name));
  }
  return out;
}

bool has(const PhysicalModel& m, const std::string& name) { return m.indexOf(name) >= 0; }

}  // namespace

TwoMassReductionResult reduceToTwoMass(const PhysicalModel& model,
                                       const TwoMassReductionOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("reduceToTwoMass: " + why);
  const auto start = std::chrono::steady_clock::now();
  TwoMassReductionResult result;
  auto finish = [&](Termination t, const std::string& message) {
    result.termination = t;
    result.message = message;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  const std::string s = model.structureName();
  if (s == "rigid")
    return finish(Termination::Failed,
                  "the rigid model (3.10) has no spring: the chapter-8 form needs a flexible model");

  const double r = model.value("r");
  const double r2 = r * r;
  const double kT = model.value("k_T");
  TwoMassLqgParameters& p = result.parameters;
  p.fa = 0.0;
  std::ostringstream text;
  text.precision(4);

  if (s == "two-mass" || s == "two-mass-theta") {
    // (3.11)-(3.12) with phi_a = r psi, multiplied by r: motor-side arm angle psi.
    const auto m = physicalTwoMass(model);
    p.Jm = m->value("J_m");
    p.fm = m->value("f_m");
    p.Ja = r2 * m->value("J_a");
    p.k = r2 * m->value("k_a");
    p.d = r2 * m->value("d_a");
    text << "two-mass (3.13) scaled by r^2 = " << r2 << " to the motor side";
  } else {
    std::vector<std::string> masses = {"J_g", "J_a"};
    if (has(model, "J_p")) masses.push_back("J_p");
    double armInertia = 0.0;
    for (const auto& name : masses) armInertia += model.value(name);
    armInertia *= r2;
    const double Jm = model.value("J_m");
    p.fm = model.value("f_m");
    if (options.method == TwoMassReduction::MergeMasses) {
      const double kg = model.value("k_g"), ka = model.value("k_a");
      const double dg = model.value("d_g"), da = model.value("d_a");
      const double k = 1.0 / (1.0 / kg + 1.0 / ka);
      p.Jm = Jm;
      p.Ja = armInertia;
      p.k = r2 * k;
      const double d = r2 * k * k * (dg / (kg * kg) + da / (ka * ka));
      p.d = std::max(0.0, d);
      text << s << " with the masses after the gear merged and k_g, k_a in series, scaled by r^2";
      if (d < 0.0) text << "; the series damping " << d << " is negative and set to 0";
    } else {
      ModelOptions velocity;  // (3.14): torque to motor velocity
      std::unique_ptr<ParametricModel> copy = model.clone();
      auto* phys = static_cast<PhysicalModel*>(copy.get());
      phys->setOptions(velocity);
      const StateSpace sys = phys->stateSpace();
      const auto notches = notchFrequencies(sys);
      const auto peaks = peakFrequencies(sys);
      if (notches.empty() || peaks.empty())
        return finish(Termination::Failed, "the " + s +
                                               " model has no lightly damped first resonance and "
                                               "antiresonance to match");
      const double wz = notches.front().naturalFrequency, wp = peaks.front().naturalFrequency;
      if (!(wp > wz))
        return finish(Termination::Failed,
                      "the first resonance of the " + s +
                          " model is not above its first antiresonance; a two-mass model "
                          "cannot match them");
      const double total = Jm + armInertia;
      p.Jm = total * wz * wz / (wp * wp);
      p.Ja = total - p.Jm;
      p.k = p.Ja * wz * wz;
      const double zeta = notches.front().damping;
      p.d = std::max(0.0, 2.0 * zeta * std::sqrt(p.k * p.Ja));
      text << s << " matched at its first antiresonance " << wz << " rad/s and resonance " << wp
           << " rad/s with the total inertia kept";
      if (zeta < 0.0)
        text << "; the antiresonance has negative damping (" << zeta << "), d set to 0";
    }
  }
  if (kT != 1.0) text << "; u is the motor torque k_T u (k_T = " << kT << ")";
  if (!p.isValid(&why)) return finish(Termination::Failed, "the reduced model is not physical: " + why);
  return finish(Termination::Converged, text.str());
}

}  // namespace flexarm
