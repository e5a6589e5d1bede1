#include "core/ident/fit_spec.h"

#include "core/common/text.h"
#include "core/ident/subspace.h"

#include <algorithm>
#include <cctype>
#include <charconv>

namespace flexarm {

namespace {

// "4,4,1" (or, with sep ' ', "4 4 1"): whole numbers, at least one; false otherwise.
bool wholeNumbers(const std::string& text, char sep, std::vector<int>& out) {
  out.clear();
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t end = std::min(text.find(sep, at), text.size());
    const char* b = text.data() + at;
    const char* e = text.data() + end;
    while (b != e && *b == ' ') ++b;  // "2, 2, 1" as well
    while (e != b && e[-1] == ' ') --e;
    if (b != e && *b == '+') ++b;
    int v = 0;
    const auto res = std::from_chars(b, e, v);
    if (b == e || res.ec != std::errc() || res.ptr != e) return false;
    out.push_back(v);
    at = end + 1;
  }
  return !out.empty();
}

std::string upper(const char* s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// "na,nb,nk" or "NA,NB,NK": the orders a structure's spec lists.
std::string orderList(PolyStructure s, bool capitals) {
  std::string out;
  for (PolyOrder o : polyOrdersOf(s)) out += (out.empty() ? "" : ",") + (capitals ? upper(toString(o)) : toString(o));
  return out;
}

std::shared_ptr<PhysicalModel> editableCopy(const PhysicalModel& m) {
  std::unique_ptr<ParametricModel> c = m.clone();
  return std::shared_ptr<PhysicalModel>(static_cast<PhysicalModel*>(c.release()));
}

}  // namespace

bool isPhysicalModelName(const std::string& name) {
  const auto& names = modelStructureNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::optional<FitModelSpec> fitModelSpecFromText(const std::string& text, bool allowNonparametric,
                                                 std::string* why) {
  auto fail = [why](const std::string& w) -> std::optional<FitModelSpec> {
    if (why) *why = w;
    return std::nullopt;
  };
  FitModelSpec spec;
  const std::string head = text.substr(0, text.find_first_of(":["));
  if (allowNonparametric && (head == "spa" || head == "etfe")) {
    spec.kind = head == "spa" ? FitModelKind::Spa : FitModelKind::Etfe;
    std::vector<int> v;
    if (text.size() > head.size() &&
        (text[head.size()] != ':' || !wholeNumbers(text.substr(head.size() + 1), ',', v) || v.size() != 1 ||
         v[0] < 0))
      return fail(head + ":W takes one non-negative window width, not " + inQuotes(text));
    spec.windowWidth = v.empty() ? 0 : v[0];
    return spec;
  }
  if (isPhysicalModelName(text)) {
    spec.kind = FitModelKind::Physical;
    spec.start = makeModel(text);  // nominal values: Table 5.2 (two-mass), Table 5.7 p6 (three-mass)
    return spec;
  }
  const auto s = polyStructureFromString(head);
  if (s == PolyStructure::Ss && text == head) {  // "ss": the order chosen by the data
    spec.kind = FitModelKind::BlackBox;
    spec.structure = PolyStructure::Ss;
    spec.orders = PolyOrders::stateSpace(0);
    return spec;
  }
  // "oe:2,2,1" as typed, or "oe[2 2 1]" as names print.
  const bool named = s && text.size() > head.size() + 1 && text[head.size()] == '[' && text.back() == ']';
  const bool typed = s && text.size() > head.size() && text[head.size()] == ':';
  if (!named && !typed)
    return fail("a model is " + fitModelSpecGrammar(allowNonparametric) + ", not " + inQuotes(text));
  const std::string numbers =
      named ? text.substr(head.size() + 1, text.size() - head.size() - 2) : text.substr(head.size() + 1);
  std::vector<int> v;
  const auto& orders = polyOrdersOf(*s);
  if (!wholeNumbers(numbers, named ? ' ' : ',', v) || v.size() != orders.size())
    return fail(head + " needs " + std::to_string(orders.size()) + (named ? " " : " comma-separated ") +
                "integers (" + orderList(*s, false) + "), not " + inQuotes(numbers));
  spec.kind = FitModelKind::BlackBox;
  spec.structure = *s;
  spec.orders = PolyOrders{0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < orders.size(); ++i) spec.orders[orders[i]] = v[i];
  if (*s == PolyStructure::Ss) {
    if (v[0] < 1 || v[0] > SubspaceOptions::kMaxOrder)
      return fail("ss:N takes a state-space order N from 1 to " + std::to_string(SubspaceOptions::kMaxOrder) +
                  " (\"ss\" alone lets the data choose it), not " + inQuotes(numbers));
    spec.orders = PolyOrders::stateSpace(v[0]);
  }
  std::string reason;
  if (!spec.orders.isValid(&reason)) return fail(text + ": " + reason);
  return spec;
}

std::string fitModelSpecText(const FitModelSpec& spec) {
  switch (spec.kind) {
    case FitModelKind::Physical: return spec.start ? spec.start->structureName() : "physical";
    case FitModelKind::BlackBox: {
      if (spec.structure == PolyStructure::Ss && spec.orders.na == 0) return "ss";
      std::string out = std::string(toString(spec.structure)) + ":";
      const char* sep = "";
      for (PolyOrder o : polyOrdersOf(spec.structure)) {
        out += sep + std::to_string(spec.orders[o]);
        sep = ",";
      }
      return out;
    }
    case FitModelKind::Spa:
    case FitModelKind::Etfe:
      return std::string(toString(spec.kind)) + (spec.windowWidth > 0 ? ":" + std::to_string(spec.windowWidth) : "");
  }
  return "";
}

std::string fitModelSpecGrammar(bool allowNonparametric) {
  std::string out;
  for (auto s : {PolyStructure::Arx, PolyStructure::Armax, PolyStructure::Oe, PolyStructure::Bj})
    out += std::string(toString(s)) + ":" + orderList(s, true) + " | ";
  out += "ss[:N] | ";
  if (allowNonparametric) out += "spa[:M] | etfe[:W] | ";
  std::string physical;
  for (const auto& n : modelStructureNames()) physical += (physical.empty() ? "" : "|") + n;
  return out + physical;
}

std::string fitParameterLabel(const std::string& name, const std::string& effect) {
  return effect.empty() ? name : name + " (" + effect + ")";
}

std::string fitParameterLabel(const FitParameter& p) { return fitParameterLabel(p.name, p.effect); }

std::vector<std::string> fitParameterLabels(const FitModelSpec& spec) {
  std::vector<std::string> out;
  if (spec.start)
    for (const auto& p : spec.start->parameters()) out.push_back(p.name);
  for (const auto& f : spec.effects)
    for (const auto& info : effectParameters(f.effect))
      out.push_back(fitParameterLabel(info.name, toString(f.effect.kind)));
  return out;
}

std::vector<std::string> freeParameterLabels(const FitModelSpec& spec) {
  std::vector<std::string> out;
  if (spec.start)
    for (const auto& p : spec.start->parameters())
      if (p.free) out.push_back(p.name);
  for (const auto& f : spec.effects) {
    const auto info = effectParameters(f.effect);
    for (std::size_t k = 0; k < info.size(); ++k)
      if (f.isFree(k)) out.push_back(fitParameterLabel(info[k].name, toString(f.effect.kind)));
  }
  return out;
}

std::string fitParameterNames(const FitModelSpec& spec) {
  std::string out;
  if (spec.start)
    for (const auto& p : spec.start->parameters()) out += (out.empty() ? "" : ", ") + p.name;
  for (const auto& f : spec.effects)
    for (const auto& info : effectParameters(f.effect)) out += (out.empty() ? "" : ", ") + info.name;
  return out;
}

FitParameterRef findFitParameter(const FitModelSpec& spec, const std::string& text) {
  FitParameterRef ref;
  for (std::size_t e = 0; e < spec.effects.size(); ++e) {
    const EffectKind kind = spec.effects[e].effect.kind;
    const auto info = effectParameters(spec.effects[e].effect);
    for (std::size_t k = 0; k < info.size(); ++k)
      if (text == info[k].name || text == fitParameterLabel(info[k].name, toString(kind))) {
        ref.effect = static_cast<int>(e);
        ref.value = static_cast<int>(k);
        return ref;
      }
  }
  if (spec.start) ref.model = spec.start->indexOf(text);
  return ref;
}

std::string unknownFitParameter(const FitModelSpec& spec, const std::string& name) {
  const std::string structure = spec.start ? spec.start->structureName() : std::string(toString(spec.kind));
  return "the " + structure + " model" + (spec.effects.empty() ? " has" : " and its effects have") +
         " no parameter '" + name + "' (its parameters: " + fitParameterNames(spec) + ")";
}

bool setFreeParameters(FitModelSpec& spec, const std::vector<std::string>& names, std::string* why) {
  if (!spec.start) {
    if (why) *why = "free parameters apply to physical models only";
    return false;
  }
  auto model = editableCopy(*spec.start);
  for (const auto& p : model->parameters()) model->setFree(p.name, false);
  std::vector<FitEffect> effects = spec.effects;
  for (auto& f : effects) f.free.assign(f.effect.values.size(), false);
  for (const auto& n : names) {
    const FitParameterRef ref = findFitParameter(spec, n);
    if (!ref.found()) {
      if (why) *why = unknownFitParameter(spec, n);
      return false;
    }
    if (ref.effect >= 0)
      effects[static_cast<std::size_t>(ref.effect)].free[static_cast<std::size_t>(ref.value)] = true;
    else
      model->setFree(n, true);
  }
  spec.start = model;
  spec.effects = effects;
  return true;
}

bool applyParameterOption(FitOptions& options, ParameterOption kind, const std::string& text, std::string* why) {
  auto fail = [why](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  FitModelSpec& spec = options.model;
  if (spec.kind != FitModelKind::Physical || !spec.start)
    return fail("free, fixed and start values and bounds apply to physical models only");
  if (kind == ParameterOption::Free) {
    std::vector<std::string> names;
    std::size_t at = 0;
    while (at <= text.size()) {  // the non-empty items of "P1,P2"
      const std::size_t end = std::min(text.find(',', at), text.size());
      if (end > at) names.push_back(text.substr(at, end - at));
      at = end + 1;
    }
    return setFreeParameters(spec, names, why);
  }
  if (kind == ParameterOption::Bound) {
    const auto b = parameterBoundFromText(text);
    if (!b) return fail("expects NAME=LO:HI with LO <= HI (numbers, or -inf/inf), not " + inQuotes(text));
    if (spec.start->indexOf(b->name) < 0) return fail(unknownFitParameter(spec, b->name));
    options.bounds.push_back(*b);
    return true;
  }
  const bool valued = text.find('=') != std::string::npos;
  const auto v = parameterValueFromText(text);
  if ((valued || kind == ParameterOption::Start) && !v)
    return fail("expects NAME=VALUE (a finite number), not " + inQuotes(text));
  const std::string name = v ? v->name : text;
  const FitParameterRef ref = findFitParameter(spec, name);
  if (!ref.found()) return fail(unknownFitParameter(spec, name));
  if (ref.effect >= 0) {
    FitEffect f = spec.effects[static_cast<std::size_t>(ref.effect)];
    const auto k = static_cast<std::size_t>(ref.value);
    if (v) f.effect.values[k] = v->value;
    if (v && k == 1) f.scaleSmoothing = false;
    if (kind == ParameterOption::Fix && k < f.free.size()) f.free[k] = false;
    if (std::string reason; !f.effect.isValid(&reason)) return fail(reason);
    spec.effects[static_cast<std::size_t>(ref.effect)] = f;
    return true;
  }
  if (v) options.startValues.push_back(*v);
  if (kind == ParameterOption::Fix) {
    auto model = editableCopy(*spec.start);
    model->setFree(name, false);
    spec.start = model;
  }
  return true;
}

FitEffect fitEffectFor(EffectKind kind, const std::vector<Effect>& own) {
  FitEffect f = FitEffect::defaults(kind);
  for (const auto& e : own)
    if (e.kind == kind) {
      f.effect = e;
      f.scaleSmoothing = false;  // the model's own v_s, e.g. the one discovery found
    }
  return f;
}

}  // namespace flexarm
