#include "app/cli/model_args.h"

#include "core/io/input_file.h"
#include "core/session/model_json.h"

#include <charconv>
#include <cmath>
#include <ostream>
#include <stdexcept>

namespace flexarm::cli {

std::vector<Option> modelOptionList() {
  std::vector<std::string> structures = modelStructureNames();
  return {
      choiceOption("model", structures, "three-mass",
                   "the structure; defaults are IRB-1400-like: two-mass Table 5.2, three-mass Table 5.7 p6, "
                   "four-mass p6 plus a parallel mass J_p = 0.3 kg m^2 tuned to 280 rad/s"),
      textOption("param", "NAME=VALUE", "set a parameter, e.g. --param J_a=10 --param k_T=1.2; names: J_m J_g J_a J_p "
                                        "f_m k_g k_a k_p d_g d_a d_p r k_T (as the structure has them; SI units: kg "
                                        "m^2, N m s/rad, N m/rad)",
                 true),
      textOption("free", "NAME", "mark a parameter free (r and k_T start fixed)", true),
      textOption("fixed", "NAME", "mark a parameter fixed", true),
      choiceOption("output", {"motor-velocity", "motor-angle"}, "motor-velocity",
                   "the model output (motor-angle adds the state phi_m)"),
      flagOption("arm-accel", "add the arm acceleration as a second output"),
  };
}

std::vector<std::string> modelValuedOptions() {
  std::vector<std::string> names;
  for (const auto& o : modelOptionList())
    if (o.kind != OptionKind::Flag) names.push_back(o.name);
  return names;
}

std::vector<std::string> modelFlagOptions() {
  std::vector<std::string> names;
  for (const auto& o : modelOptionList())
    if (o.kind == OptionKind::Flag) names.push_back(o.name);
  return names;
}

std::string modelOptionsHelp() {
  OptionTable t("", "");
  t.add(modelOptionList());
  return t.help();
}

std::unique_ptr<PhysicalModel> modelFromArgs(const ArgParser& args, const std::string& verb,
                                             std::ostream& err) {
  ModelOptions options;
  if (auto o = args.value("output")) {
    auto parsed = modelOutputFromString(*o);
    if (!parsed) {
      err << "flexarm " << verb << ": --output must be motor-velocity or motor-angle, not '" << *o
          << "'\n";
      return nullptr;
    }
    options.output = *parsed;
  }
  options.armAcceleration = args.flag("arm-accel");
  std::unique_ptr<PhysicalModel> model;
  try {
    model = makeModel(args.value("model").value_or("three-mass"), options);
    if (!applyParams(args, *model, verb, err)) return nullptr;
    for (const auto& n : args.values("free")) model->setFree(n, true);
    for (const auto& n : args.values("fixed")) model->setFree(n, false);
  } catch (const std::invalid_argument& e) {
    err << "flexarm " << verb << ": " << e.what() << "\n";
    return nullptr;
  }
  return model;
}

bool applyParams(const ArgParser& args, PhysicalModel& model, const std::string& verb,
                 std::ostream& err) {
  for (const auto& p : args.values("param")) {
    const auto eq = p.find('=');
    if (eq == std::string::npos) {
      err << "flexarm " << verb << ": --param expects NAME=VALUE, got '" << p << "'\n";
      return false;
    }
    const std::string name = p.substr(0, eq), text = p.substr(eq + 1);
    double v = 0.0;
    const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
    if (res.ec != std::errc() || res.ptr != text.data() + text.size() || !std::isfinite(v)) {
      err << "flexarm " << verb << ": --param " << name << ": '" << text << "' is not a number\n";
      return false;
    }
    try {
      model.setParameter(name, v);
    } catch (const std::invalid_argument& e) {
      err << "flexarm " << verb << ": " << e.what() << "\n";
      return false;
    }
  }
  return true;
}

std::unique_ptr<PhysicalModel> modelFromFile(const std::string& path, std::string* why) {
  // A regular file of sensible size only: a pipe or device would block or never end.
  FileBytes bytes;
  if (!readInputFile(path, 64u << 20, bytes, why)) return nullptr;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(bytes.view());
  } catch (const nlohmann::json::parse_error& e) {
    *why = "is not JSON (a syntax error near byte " + std::to_string(e.byte) + ")";
    return nullptr;
  } catch (const nlohmann::json::exception&) {
    *why = "is not JSON";
    return nullptr;
  }
  if (!j.is_object()) {
    *why = "holds no model (a JSON object is expected)";
    return nullptr;
  }
  // A session's or `flexarm model`'s model: {"structure", "parameters": [{name, value}, ...]}.
  if (j.contains("structure")) {
    if (!j.contains("name")) j["name"] = path;  // `flexarm model --json` names none
    auto spec = modelFromJson(j, why);
    if (!spec) return nullptr;
    return std::unique_ptr<PhysicalModel>(
        dynamic_cast<PhysicalModel*>(spec->model->clone().release()));
  }
  // `flexarm fit --json`: "model": "three-mass (K = 0)", "parameters": {name: value}.
  if (!j.contains("model") || !j["model"].is_string() || !j.contains("parameters") ||
      !j["parameters"].is_object()) {
    *why = "is neither a fit (\"model\" and \"parameters\") nor a model (\"structure\")";
    return nullptr;
  }
  const std::string name = j["model"].get<std::string>();
  const std::string structure = name.substr(0, name.find(' '));
  std::unique_ptr<PhysicalModel> model;
  try {
    model = makeModel(structure);
  } catch (const std::invalid_argument&) {
    *why = "its model '" + name + "' is not a physical model (" + structure + ")";
    return nullptr;
  }
  for (const auto& [key, value] : j["parameters"].items()) {
    if (model->indexOf(key) < 0) continue;  // e.g. the innovations gain K1..Kn
    if (!value.is_number()) {
      *why = "the value of " + key + " is not a number";
      return nullptr;
    }
    try {
      model->setParameter(key, value.get<double>());
    } catch (const std::invalid_argument& e) {
      *why = e.what();
      return nullptr;
    }
  }
  return model;
}

nlohmann::json modelJson(const PhysicalModel& model) {
  nlohmann::json params = nlohmann::json::array();
  for (const auto& p : model.parameters())
    params.push_back({{"name", p.name},
                      {"unit", p.unit},
                      {"value", p.value},
                      {"lower", p.lower},
                      {"upper", p.upper},
                      {"free", p.free}});
  return {{"structure", model.structureName()},
          {"description", model.description()},
          {"output", toString(model.options().output)},
          {"arm_acceleration", model.options().armAcceleration},
          {"parameters", params}};
}

}  // namespace flexarm::cli
