// Effect names, parameters, parsing and help lines, all read from the registry
// (core/models/effect_registry.h); and the defaults every definition shares.
#include "core/models/effects.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/models/effect_registry.h"

namespace flexarm {

namespace {

struct Registry {
  std::vector<std::unique_ptr<EffectDefinition>> definitions;
  std::vector<EffectKind> kinds;
  std::vector<std::vector<EffectParameterInfo>> parameters;  // at the default size
};

}  // namespace

const EffectDefinition& effectDefinition(EffectKind k) {
  static const Registry* registry = [] {
    auto* r = new Registry;
#define FLEXARM_EFFECT(kind, name, factory)               \
  r->definitions.push_back(factory());                    \
  r->definitions.back()->kind_ = EffectKind::kind;        \
  r->definitions.back()->name_ = name;                    \
  r->kinds.push_back(EffectKind::kind);
#include "core/models/effects/effect_list.h"
#undef FLEXARM_EFFECT
    for (const auto& d : r->definitions) r->parameters.push_back(d->parameters());
    return r;
  }();
  return *registry->definitions[static_cast<std::size_t>(k)];
}

namespace {

bool parseNumber(std::string_view s, double& out) {
  const auto res = std::from_chars(s.data(), s.data() + s.size(), out);
  return res.ec == std::errc() && res.ptr == s.data() + s.size() && std::isfinite(out);
}

}  // namespace

const char* toString(EffectKind k) { return effectDefinition(k).name(); }

std::optional<EffectKind> effectKindFromString(std::string_view s) {
  for (EffectKind k : allEffectKinds())
    if (s == toString(k)) return k;
  return std::nullopt;
}

const std::vector<EffectKind>& allEffectKinds() {
  static const std::vector<EffectKind> kAll = {
#define FLEXARM_EFFECT(kind, name, factory) EffectKind::kind,
#include "core/models/effects/effect_list.h"
#undef FLEXARM_EFFECT
  };
  return kAll;
}

const std::vector<EffectKind>& seedEffectKinds() {
  static const std::vector<EffectKind> kSeed(allEffectKinds().begin(), allEffectKinds().begin() + 6);
  return kSeed;
}

std::string effectNames() {
  std::string s;
  for (EffectKind k : allEffectKinds()) s += (s.empty() ? "" : ", ") + std::string(toString(k));
  return s;
}

const std::vector<EffectParameterInfo>& effectParameters(EffectKind k) {
  static const std::vector<std::vector<EffectParameterInfo>> kAll = [] {
    std::vector<std::vector<EffectParameterInfo>> v;
    for (EffectKind kind : allEffectKinds()) v.push_back(effectDefinition(kind).parameters());
    return v;
  }();
  return kAll[static_cast<std::size_t>(k)];
}

std::vector<EffectParameterInfo> effectParameters(const Effect& e) {
  return effectDefinition(e.kind).parameters(e.values.size());
}

Effect Effect::withDefaults(EffectKind k) {
  Effect e;
  e.kind = k;
  for (const auto& p : effectParameters(k)) e.values.push_back(p.defaultValue);
  return e;
}

bool Effect::isValid(std::string* why) const {
  auto fail = [why](std::string s) {
    if (why) *why = std::move(s);
    return false;
  };
  const EffectDefinition& d = effectDefinition(kind);
  const std::string name = toString(kind);
  if (!d.takesCount(values.size()))
    return fail(name + ": " + std::to_string(values.size()) + " values is not a size this effect takes");
  const auto params = d.parameters(values.size());
  for (std::size_t i = 0; i < params.size(); ++i) {
    const auto& p = params[i];
    const double v = values[i];
    if (!std::isfinite(v)) return fail(name + ": " + p.name + " is not finite");
    switch (p.domain) {
      case ValueDomain::NonNegative:
        if (v < 0.0) return fail(name + ": " + p.name + " must be >= 0");
        break;
      case ValueDomain::Positive:
        if (!(v > 0.0)) return fail(name + ": " + p.name + " must be > 0");
        break;
      case ValueDomain::Fraction:
        if (!(v > 0.0 && v < 1.0)) return fail(name + ": " + p.name + " must be in (0, 1)");
        break;
      case ValueDomain::Signed: break;
    }
    if (v < p.lower || v > p.upper) {
      char buf[96];
      std::snprintf(buf, sizeof buf, " must be in [%g, %g]", p.lower, p.upper);
      return fail(name + ": " + p.name + buf + (p.unit.empty() || p.unit == "1" ? "" : " " + p.unit));
    }
  }
  const std::string problem = d.check(*this);
  if (!problem.empty()) return fail(name + ": " + problem);
  if (why) why->clear();
  return true;
}

std::optional<Effect> parseEffect(std::string_view spec, std::string* why) {
  const auto colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const auto kind = effectKindFromString(name);
  if (!kind) {
    if (why) *why = "unknown effect '" + std::string(name) + "' (expected one of " + effectNames() + ")";
    return std::nullopt;
  }
  Effect e = Effect::withDefaults(*kind);
  const EffectDefinition& d = effectDefinition(*kind);
  if (colon != std::string_view::npos) {
    std::vector<double> given;
    std::string_view rest = spec.substr(colon + 1);
    for (;;) {
      const auto comma = rest.find(',');
      const std::string_view field = rest.substr(0, comma);
      double v = 0.0;
      if (!parseNumber(field, v)) {
        if (why) *why = std::string(name) + ": '" + std::string(field.substr(0, 60)) + "' is not a number";
        return std::nullopt;
      }
      // A value given by hand is one a robot axis can have: beyond 1e15 in SI units (a cubic
      // spring's N m/rad^3 reach 1e7) is a slip of the keyboard, and a start of 1e308 makes
      // every fit overflow.
      if (!(std::fabs(v) <= 1e15)) {
        char buf[48];
        std::snprintf(buf, sizeof buf, "%g", v);
        if (why) *why = std::string(name) + ": " + buf + " is beyond the +-1e15 a robot axis' effect can have";
        return std::nullopt;
      }
      given.push_back(v);
      if (comma == std::string_view::npos) break;
      rest = rest.substr(comma + 1);
    }
    // Fewer values than the default size: the rest keep their defaults; more: the effect's
    // own sizes (the ripple's harmonics).
    if (given.size() > e.values.size()) {
      if (!d.takesCount(given.size())) {
        if (why) {
          *why = std::string(name) + " takes " + std::to_string(e.values.size()) + " values";
          if (d.withOneMoreTerm(e)) *why += " or more in its own steps (see the help)";
        }
        return std::nullopt;
      }
      e.values = given;
    } else {
      for (std::size_t i = 0; i < given.size(); ++i) e.values[i] = given[i];
    }
  }
  if (!e.isValid(why)) return std::nullopt;
  return e;
}

std::string toString(const Effect& e) {
  std::string s = toString(e.kind);
  char buf[40];
  for (std::size_t i = 0; i < e.values.size(); ++i) {
    // Shortest text that reads back to the same double.
    const auto res = std::to_chars(buf, buf + sizeof buf, e.values[i]);
    s += (i == 0 ? ":" : ",");
    s.append(buf, res.ptr);
  }
  return s;
}

std::string effectHelpLines(int nameColumn, int width) {
  std::string out;
  for (EffectKind k : allEffectKinds()) {
    const EffectDefinition& d = effectDefinition(k);
    std::string head = "  " + std::string(d.name());
    std::string defaults;
    const auto params = d.parameters();
    for (std::size_t i = 0; i < params.size(); ++i) {
      head += (i ? "," : ":") + params[i].name;
      char buf[48];
      std::snprintf(buf, sizeof buf, "%g", params[i].defaultValue);
      defaults += (i ? ", " : "") + std::string(buf) +
                  (params[i].unit.empty() || params[i].unit == "1" ? "" : " " + params[i].unit);
    }
    std::string text = d.summary() + " (" + defaults + ")";
    // Wrap the text at `width` after the name column.
    std::string line = head;
    if (static_cast<int>(line.size()) + 1 > nameColumn) {
      out += line + "\n";
      line.clear();
    }
    line.resize(static_cast<std::size_t>(nameColumn), ' ');
    std::size_t at = 0;
    bool first = true;
    while (at < text.size()) {
      const std::size_t room = static_cast<std::size_t>(std::max(20, width - nameColumn));
      std::size_t end = std::min(text.size(), at + room);
      if (end < text.size()) {
        const std::size_t space = text.rfind(' ', end);
        if (space != std::string::npos && space > at) end = space;
      }
      if (!first) line.assign(static_cast<std::size_t>(nameColumn), ' ');
      line += text.substr(at, end - at);
      out += line + "\n";
      at = end;
      while (at < text.size() && text[at] == ' ') ++at;
      first = false;
    }
  }
  return out;
}

// Defaults of the definitions.

std::vector<EffectParameterInfo> EffectDefinition::parameters(std::size_t) const { return parameters(); }

bool EffectDefinition::takesCount(std::size_t count) const { return count == parameters().size(); }

std::unique_ptr<PhysicalModel> EffectDefinition::structure(const PhysicalModel&, const Effect&, std::string*) const {
  return nullptr;
}

std::vector<EffectSearchCoordinate> EffectDefinition::searchCoordinates(const Effect& e,
                                                                        const EffectSearchBounds&) const {
  EffectSearchCoordinate c;
  c.index = mainParameter();
  const auto params = parameters(e.values.size());
  const auto& p = params[static_cast<std::size_t>(c.index)];
  c.map = p.domain == ValueDomain::Signed ? EffectSearchCoordinate::Map::Signed
                                          : EffectSearchCoordinate::Map::NonNegative;
  c.scale = std::abs(p.defaultValue) > 0.0 ? std::abs(p.defaultValue) : 1.0;
  return {c};
}

EffectSearchPlan EffectDefinition::searchPlan(const Effect& e0, const EffectSearchBounds&) const {
  EffectSearchPlan plan;
  Effect e = e0;
  const auto m = static_cast<std::size_t>(mainParameter());
  e.values[m] = 0.5 * effectParameters(kind())[m].defaultValue;
  plan.starts.push_back(e);
  return plan;
}

double EffectDefinition::addedTorque(const Effect& e, const JointSignals& s) const {
  if (structural()) return NAN;
  PlantTerms terms;
  addToPlant(e, terms);
  double t = 0.0;
  for (const auto& term : terms.torques)
    t += term.term->torque(s) * (term.site == TorqueSite::Motor ? 1.0 : s.ratio);
  return t;
}

std::string EffectDefinition::magnitudeName() const {
  return effectParameters(kind())[static_cast<std::size_t>(mainParameter())].name;
}

Effect EffectDefinition::withMagnitude(const Effect& e, double m) const {
  Effect out = e;
  out.values[static_cast<std::size_t>(mainParameter())] = m;
  return out;
}

std::string EffectDefinition::displayUnit() const {
  return effectParameters(kind())[static_cast<std::size_t>(mainParameter())].unit;
}

EffectSearchPlan startsOverADecade(const Effect& e0, int index, std::initializer_list<double> factors) {
  EffectSearchPlan plan;
  const auto i = static_cast<std::size_t>(index);
  for (double x : factors) {
    Effect e = e0;
    e.values[i] = x * effectParameters(e0.kind)[i].defaultValue;
    plan.starts.push_back(e);
  }
  return plan;
}

namespace effect_text {

std::string number(double v, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string plusMinus(const EffectParameterEstimate& p, double factor) {
  return number(p.value * factor) + " +- " + number(p.std * factor, 2);
}

}  // namespace effect_text

}  // namespace flexarm
