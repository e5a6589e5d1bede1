// torque_ripple: a torque periodic in the motor angle (cogging of the motor's magnets, the
// mesh of the gear's teeth): the harmonics of a base order n per motor revolution, each with
// its own amplitude and phase against the encoder's zero,
//   tau = sum_k A_k sin(k n phi_m + psi_k) = sum_k a_k sin(k n phi_m) + b_k cos(k n phi_m),
// k = 1..K, on the motor. The values are a_1, n, b_1, a_2, b_2, ..., a_K, b_K: a sine and a
// cosine coefficient per harmonic (linear in the torque, either sign), so that
// `torque_ripple:A,n` is A sin(n phi_m). A_k = hypot(a_k, b_k), psi_k = atan2(b_k, a_k).
#include <cmath>

#include "core/models/effect_registry.h"

namespace flexarm {
namespace {

constexpr std::size_t kMaxHarmonics = 8;

std::size_t harmonics(std::size_t count) { return (count - 1) / 2; }
double sineOf(const std::vector<double>& v, std::size_t k) { return v[k == 0 ? 0 : 2 * k + 1]; }
double cosineOf(const std::vector<double>& v, std::size_t k) { return v[2 * k + 2]; }

class RippleTorque : public TorqueTerm {
 public:
  explicit RippleTorque(const std::vector<double>& v) : order_(v[1]) {
    for (std::size_t k = 0; k < harmonics(v.size()); ++k) {
      a_.push_back(sineOf(v, k));
      b_.push_back(cosineOf(v, k));
    }
  }
  double torque(const JointSignals& s) const override {
    // sin and cos of k x by the angle-addition recurrence from those of x.
    const double x = order_ * s.motorAngle;
    const double s1 = std::sin(x), c1 = std::cos(x);
    double sk = s1, ck = c1, tau = 0.0;
    for (std::size_t k = 0; k < a_.size(); ++k) {
      tau += a_[k] * sk + b_[k] * ck;
      const double sn = sk * c1 + ck * s1;
      ck = ck * c1 - sk * s1;
      sk = sn;
    }
    return tau;
  }

 private:
  double order_;
  std::vector<double> a_, b_;
};

class TorqueRipple : public EffectDefinition {
 public:
  std::vector<EffectParameterInfo> parameters() const override { return parameters(3); }
  std::vector<EffectParameterInfo> parameters(std::size_t count) const override {
    std::vector<EffectParameterInfo> p;
    for (std::size_t k = 0; k < harmonics(count); ++k) {
      const std::string i = std::to_string(k + 1);
      const std::string mult = k == 0 ? "" : i + " ";
      EffectParameterInfo a{"a_" + i, "N m", k == 0 ? 0.05 : 0.0,
                            "sine coefficient of harmonic " + i + ": a_" + i + " sin(" + mult + "n phi_m)",
                            ValueDomain::Signed, -1e300, 1e300, true};
      EffectParameterInfo b{"b_" + i, "N m", 0.0,
                            "cosine coefficient of harmonic " + i + ": b_" + i + " cos(" + mult + "n phi_m)",
                            ValueDomain::Signed, -1e300, 1e300, true};
      p.push_back(a);
      if (k == 0)
        p.push_back({"n", "1/rev", 6.0, "ripple periods per motor revolution (the base order)", ValueDomain::Positive,
                     0.0, 1000.0, false});
      p.push_back(b);
    }
    return p;
  }
  bool takesCount(std::size_t count) const override {
    return count >= 3 && count % 2 == 1 && harmonics(count) <= kMaxHarmonics;
  }
  std::optional<Effect> withOneMoreTerm(const Effect& e) const override {
    if (harmonics(e.values.size()) >= kMaxHarmonics) return std::nullopt;
    Effect out = e;
    out.values.push_back(0.0);
    out.values.push_back(0.0);
    return out;
  }
  std::string summary() const override {
    return "sum_k a_k sin(k n phi_m) + b_k cos(k n phi_m) on the motor, harmonics k = 1..K of the order n "
           "(a_2,b_2,... after b_1 add harmonics)";
  }
  void addToPlant(const Effect& e, PlantTerms& t) const override {
    bool any = false;
    for (std::size_t i = 0; i < e.values.size(); ++i) any = any || (i != 1 && e.values[i] != 0.0);
    if (any) t.torques.push_back({TorqueSite::Motor, std::make_shared<RippleTorque>(e.values)});
  }
  // Every coefficient searched (linear in the torque), the order n on the grid 1..12.
  std::vector<EffectSearchCoordinate> searchCoordinates(const Effect& e, const EffectSearchBounds&) const override {
    std::vector<EffectSearchCoordinate> out;
    for (std::size_t i = 0; i < e.values.size(); ++i) {
      if (i == 1) continue;
      EffectSearchCoordinate c;
      c.index = static_cast<int>(i);
      c.map = EffectSearchCoordinate::Map::Signed;
      c.scale = 0.05;
      out.push_back(c);
    }
    return out;
  }
  int gridValues(const Effect&) const override { return 1; }
  EffectSearchPlan searchPlan(const Effect& e0, const EffectSearchBounds&) const override {
    EffectSearchPlan plan;
    plan.screenOwnOnly = true;
    for (int n = 1; n <= 12; ++n) {
      Effect e = e0;
      e.values.assign({0.01, static_cast<double>(n), 0.01});
      plan.starts.push_back(e);
    }
    return plan;
  }
  std::string magnitudeName() const override { return "A_1"; }
  double magnitude(const Effect& e) const override { return std::hypot(e.value(0), e.value(2)); }
  Effect withMagnitude(const Effect& e, double m) const override {
    Effect out = e;
    const double now = magnitude(e);
    if (!(now > 0.0)) {
      out.values[0] = m;
      return out;
    }
    for (std::size_t i = 0; i < out.values.size(); ++i)
      if (i != 1) out.values[i] *= m / now;
    return out;
  }
  std::vector<DerivedQuantity> derivedQuantities(const Effect& e) const override {
    std::vector<DerivedQuantity> out;
    for (std::size_t k = 0; k < harmonics(e.values.size()); ++k) {
      const std::string i = std::to_string(k + 1);
      out.push_back({"A_" + i, "N m", [k](const std::vector<double>& v) { return std::hypot(sineOf(v, k), cosineOf(v, k)); }});
      out.push_back({"psi_" + i, "rad", [k](const std::vector<double>& v) { return std::atan2(cosineOf(v, k), sineOf(v, k)); }});
    }
    return out;
  }
  std::string displayUnit() const override { return "N m"; }
  std::string signature() const override {
    return "the residual against the ripple's harmonics of the motor angle (the response to sum_k A_k sin(k n phi_m + "
           "psi_k))";
  }
  std::string describe(const std::vector<EffectParameterEstimate>& p) const override {
    const EffectParameterEstimate* n = nullptr;
    for (const auto& q : p)
      if (q.name == "n") n = &q;
    std::string s = "torque ripple of order " + effect_text::number(n ? n->value : 0.0) + " per motor revolution:";
    int k = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p[i].name.rfind("A_", 0) != 0 || i + 1 >= p.size()) continue;
      const auto& A = p[i];
      const auto& psi = p[i + 1];
      s += std::string(k++ ? "," : "") + " " + A.name + " = " + effect_text::plusMinus(A) + " N m at " + psi.name +
           " = " + effect_text::plusMinus(psi) + " rad";
    }
    return s;
  }
};

}  // namespace

std::unique_ptr<EffectDefinition> torqueRippleEffect() { return std::make_unique<TorqueRipple>(); }

}  // namespace flexarm
