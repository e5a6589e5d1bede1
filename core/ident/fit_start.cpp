// The start model and the bounds of a physical fit (fit.h): start values by name, the gear
// ratio's rescaling of the parameters behind the gear, and the default bounds.
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "core/ident/fit.h"

namespace flexarm {
namespace {

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// Parameters whose value, referred to the motor side, scales with r^2 (3.13), (3.21), (3.22):
// every inertia, stiffness and damping behind the gear (all but J_m, f_m, r and k_T).
bool behindGear(const std::string& name) {
  if (name == "J_m" || name == "k_T") return false;
  return startsWith(name, "J_") || startsWith(name, "k_") || startsWith(name, "d_");
}

std::string numberText(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string namesOf(const PhysicalModel& m) {
  std::string out;
  for (const auto& p : m.parameters()) out += (out.empty() ? "" : ", ") + p.name;
  return out;
}

// A whole string as a number (inf and -inf included); nullopt otherwise.
std::optional<double> numberOf(const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && !std::isnan(v)) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

}  // namespace

std::optional<double> logGearRatio(const IdData& data, std::string* why) {
  const std::string text = trimmed(data.meta("gear_ratio"));
  if (text.empty()) return std::nullopt;
  auto fail = [&](const std::string& reason) -> std::optional<double> {
    if (why) *why = "the log's gear_ratio '" + text + "' " + reason;
    return std::nullopt;
  };
  const auto slash = text.find('/');
  const auto a = numberOf(trimmed(text.substr(0, slash)));
  const auto b = slash == std::string::npos ? std::optional<double>(1.0) : numberOf(trimmed(text.substr(slash + 1)));
  if (!a || !b || !std::isfinite(*a) || !std::isfinite(*b) || *b == 0.0) return fail("is not a number or a ratio A/B");
  const double r = *a / *b;
  if (!(r > 0.0)) return fail("is not positive");
  if (r > 1.0)
    return fail("is above 1: it is arm turns per motor turn (arm/motor); a gear of " + numberText(r) +
                " motor turns per arm turn is 1/" + numberText(r));
  if (why) why->clear();
  return r;
}

std::optional<ParameterValue> parameterValueFromText(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return std::nullopt;
  const auto v = numberOf(trimmed(text.substr(eq + 1)));
  if (!v || !std::isfinite(*v)) return std::nullopt;
  return ParameterValue{trimmed(text.substr(0, eq)), *v};
}

std::optional<ParameterBound> parameterBoundFromText(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return std::nullopt;
  // The colon after the first character of LO (LO may be "-inf").
  const auto colon = text.find(':', eq + 2);
  if (colon == std::string::npos) return std::nullopt;
  const auto lo = numberOf(trimmed(text.substr(eq + 1, colon - eq - 1))), hi = numberOf(trimmed(text.substr(colon + 1)));
  if (!lo || !hi || !(*lo <= *hi)) return std::nullopt;
  return ParameterBound{trimmed(text.substr(0, eq)), *lo, *hi};
}

bool startsAndBoundsFromText(const std::string& text, std::vector<ParameterValue>& starts,
                             std::vector<ParameterBound>& bounds, std::string* why) {
  starts.clear();
  bounds.clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = trimmed(item);
    if (item.empty()) continue;
    if (item.find(':') != std::string::npos) {
      if (auto b = parameterBoundFromText(item)) {
        bounds.push_back(*b);
        continue;
      }
    } else if (auto v = parameterValueFromText(item)) {
      starts.push_back(*v);
      continue;
    }
    if (why)
      *why = "'" + item + "' is neither a start value P=V nor bounds P=LO:HI with LO <= HI";
    return false;
  }
  return true;
}

std::string startsAndBoundsText(const std::vector<ParameterValue>& starts, const std::vector<ParameterBound>& bounds) {
  std::string out;
  for (const auto& v : starts) out += (out.empty() ? "" : ", ") + v.name + "=" + numberText(v.value);
  for (const auto& b : bounds)
    out += (out.empty() ? "" : ", ") + b.name + "=" + numberText(b.lower) + ":" + numberText(b.upper);
  return out;
}

std::vector<ParameterBound> fitBounds(const FitOptions& o) {
  if (o.model.kind != FitModelKind::Physical || !o.model.start)
    throw std::invalid_argument("fitBounds: the fit is not of a physical model");
  const PhysicalModel& m = *o.model.start;
  std::vector<ParameterBound> b;
  for (const auto& p : m.parameters()) {
    ParameterBound q{p.name, p.lower, p.upper};
    // Dampings dissipate: a negative one makes energy, which no gear does; inertias and
    // stiffnesses are positive already (their model bounds start above zero). A start model
    // whose own damping is negative (the seed's identified d_g = -62 of Table 5.7, the
    // three-mass default) keeps the model's bounds for it, so that the search starts inside
    // them and can reach the value the model came from; a start value given for it is held
    // to d >= 0 (--bound opens it).
    const bool given = std::any_of(o.startValues.begin(), o.startValues.end(),
                                   [&p](const ParameterValue& v) { return v.name == p.name; });
    if (startsWith(p.name, "d_") && (given || p.value >= 0.0)) q.lower = std::max(q.lower, 0.0);
    b.push_back(q);
  }
  for (const auto& given : o.bounds) {
    const int i = m.indexOf(given.name);
    if (i < 0)
      throw std::invalid_argument("the " + m.structureName() + " model has no parameter '" + given.name +
                                  "' to bound (its parameters: " + namesOf(m) + ")");
    if (std::isnan(given.lower) || std::isnan(given.upper) || !(given.lower <= given.upper))
      throw std::invalid_argument("the bounds of " + given.name + " must be LO <= HI, not " +
                                  numberText(given.lower) + ":" + numberText(given.upper));
    b[static_cast<std::size_t>(i)].lower = given.lower;
    b[static_cast<std::size_t>(i)].upper = given.upper;
  }
  return b;
}

std::shared_ptr<PhysicalModel> fitStartModel(const FitOptions& o, std::vector<std::string>* notes) {
  const std::vector<ParameterBound> bounds = fitBounds(o);
  auto m = std::shared_ptr<PhysicalModel>(static_cast<PhysicalModel*>(o.model.start->clone().release()));
  const auto& params = m->parameters();
  // Bounds first, wide enough for any value, so the start values below can be set.
  for (const auto& p : params) m->setBounds(p.name, -1e300, 1e300);
  auto given = [&o](const std::string& name) {
    return std::any_of(o.startValues.begin(), o.startValues.end(),
                       [&name](const ParameterValue& v) { return v.name == name; });
  };
  // A fixed parameter is not searched: it keeps the model's own bounds, a free one takes the
  // fit's.
  const PhysicalModel& own = *o.model.start;
  auto boundsOf = [&](int i) {
    const auto& p = own.parameters()[static_cast<std::size_t>(i)];
    return p.free ? bounds[static_cast<std::size_t>(i)] : ParameterBound{p.name, p.lower, p.upper};
  };
  for (const auto& v : o.startValues) {
    const int i = m->indexOf(v.name);
    if (i < 0)
      throw std::invalid_argument("the " + m->structureName() + " model has no parameter '" + v.name +
                                  "' (its parameters: " + namesOf(*m) + ")");
    const ParameterBound b = boundsOf(i);
    if (!std::isfinite(v.value) || v.value < b.lower || v.value > b.upper)
      throw std::invalid_argument(v.name + " = " + numberText(v.value) + " is outside its bounds [" +
                                  numberText(b.lower) + ", " + numberText(b.upper) + "]" +
                                  (params[static_cast<std::size_t>(i)].free ? " (as a start value)" : ""));
    if (v.name == "r" && v.value != m->value("r")) {
      const double scale = std::pow(m->value("r") / v.value, 2);
      for (const auto& p : params)
        if (behindGear(p.name) && !given(p.name)) m->setParameter(p.name, p.value * scale);
    }
    m->setParameter(v.name, v.value);
  }
  // The log's gear ratio is the one source of r when it states one and no start value names r.
  const IdData* log = o.estimation.empty() ? nullptr : o.estimation.front().data.get();
  if (log && m->indexOf("r") >= 0 && !given("r")) {
    std::string why;
    const auto ratio = logGearRatio(*log, &why);
    if (!ratio && !why.empty()) throw std::invalid_argument(why);
    // A ratio written with 12 digits (as flexarm simulate writes 1/118) is the same ratio.
    if (ratio && std::abs(*ratio - m->value("r")) > 1e-9 * m->value("r")) {
      const ParameterBound b = boundsOf(m->indexOf("r"));
      if (*ratio < b.lower || *ratio > b.upper)
        throw std::invalid_argument("the log's gear ratio " + numberText(*ratio) + " is outside the bounds of r [" +
                                    numberText(b.lower) + ", " + numberText(b.upper) + "]");
      m->setParameter("r", *ratio);
    }
  }
  for (std::size_t i = 0; i < params.size(); ++i) {
    const ParameterBound b = boundsOf(static_cast<int>(i));
    const std::string name = params[i].name;
    const double v = params[i].value;
    if (v < b.lower || v > b.upper) {
      const double to = std::clamp(v, b.lower, b.upper);
      m->setParameter(name, to);
      if (notes)
        notes->push_back("the start value " + name + " = " + numberText(v) + " lay " +
                         (v < b.lower ? "below its lower" : "above its upper") + " bound " +
                         numberText(to) + ", so the fit started from the bound");
    }
    m->setBounds(name, b.lower, b.upper);
  }
  return m;
}

}  // namespace flexarm
