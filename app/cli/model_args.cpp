#include "app/cli/model_args.h"

#include <charconv>
#include <cmath>
#include <ostream>
#include <stdexcept>

namespace flexarm::cli {

std::vector<std::string> modelValuedOptions() { return {"model", "param", "free", "fixed", "output"}; }
std::vector<std::string> modelFlagOptions() { return {"arm-accel"}; }

std::string modelOptionsHelp() {
  std::string names;
  for (const auto& n : modelStructureNames()) names += (names.empty() ? "" : "|") + n;
  return "  --model " + names +
         "\n"
         "                        the structure (default three-mass); defaults are IRB-1400-like:\n"
         "                        two-mass Table 5.2, three-mass Table 5.7 p6, four-mass p6 plus\n"
         "                        a parallel mass J_p = 0.3 kg m^2 tuned to 280 rad/s\n"
         "  --param NAME=VALUE    set a parameter (repeatable), e.g. --param J_a=10 --param k_T=1.2\n"
         "                        names: J_m J_g J_a J_p f_m k_g k_a k_p d_g d_a d_p r k_T (as the\n"
         "                        structure has them; SI units: kg m^2, N m s/rad, N m/rad)\n"
         "  --free NAME, --fixed NAME\n"
         "                        mark a parameter free or fixed (repeatable; r and k_T start fixed)\n"
         "  --output motor-velocity|motor-angle\n"
         "                        the model output (motor-angle adds the state phi_m)\n"
         "  --arm-accel           add the arm acceleration as a second output\n";
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
    for (const auto& p : args.values("param")) {
      const auto eq = p.find('=');
      if (eq == std::string::npos) {
        err << "flexarm " << verb << ": --param expects NAME=VALUE, got '" << p << "'\n";
        return nullptr;
      }
      const std::string name = p.substr(0, eq), text = p.substr(eq + 1);
      double v = 0.0;
      const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
      if (res.ec != std::errc() || res.ptr != text.data() + text.size() || !std::isfinite(v)) {
        err << "flexarm " << verb << ": --param " << name << ": '" << text
            << "' is not a number\n";
        return nullptr;
      }
      model->setParameter(name, v);
    }
    for (const auto& n : args.values("free")) model->setFree(n, true);
    for (const auto& n : args.values("fixed")) model->setFree(n, false);
  } catch (const std::invalid_argument& e) {
    err << "flexarm " << verb << ": " << e.what() << "\n";
    return nullptr;
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
