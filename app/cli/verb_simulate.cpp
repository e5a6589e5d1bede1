// flexarm simulate --model ... [--effect NAME[:VALUE] ...] --excitation KIND --duration S
//                  --seed N [--rate HZ] --out LOG.csv
#include <algorithm>
#include <cstdio>
#include <map>
#include <utility>
#include <nlohmann/json.hpp>
#include <ostream>

#include "core/common/text.h"
#include "app/cli/cli.h"
#include "app/cli/model_args.h"
#include "app/cli/verb_fleet.h"
#include "core/io/log_io.h"
#include "core/sim/closed_loop.h"

namespace flexarm::cli {
namespace {

const char* kSimulateHelp =
    "Usage: flexarm simulate [--model STRUCTURE] [--param NAME=VALUE ...]\n"
    "                        [--effect NAME[:V1[,V2]] ...] --excitation chirp|multisine|prbs|none\n"
    "                        [--step NAME=VALUE@S ...] --duration S --seed N [--rate HZ]\n"
    "                        --out LOG.csv [--json]\n\n"
    "Simulates the model with the effects under the cascaded position (P) / velocity (PI)\n"
    "controller of the seed's Figure 5.1 and writes a FlexArm CSV log (time_s,\n"
    "motor_angle_rad, torque_ref_nm, angle_ref_rad) plus LOG.truth.json with everything that\n"
    "made it: model and parameters, effects, controller, disturbances, excitation and seed.\n"
    "The same options and seed give the same bytes.\n\n";

const char* kSimulateHelpTail =
    "\nExcitation (added to the motor position reference):\n"
    "  --excitation KIND     chirp (default; 30 -> 0.5 Hz, Section 5.1), multisine (lines\n"
    "                        2 pi k/12 rad/s, k = 1..360, random phases, (6.50)), prbs, none\n"
    "  --amplitude RAD       excitation amplitude on the motor side (default 0.05 rad)\n"
    "  --chirp HZ0:HZ1       chirp start and end frequency\n"
    "  --multisine-lines K0:K1, --multisine-period S\n"
    "  --prbs-clock S        PRBS bit length (default 0.01 s)\n"
    "  --reference-velocity RAD_S  constant motor speed added to the reference (default 0)\n\n"
    "Faults (repeatable):\n"
    "  --step NAME=VALUE@S   the model parameter NAME steps to VALUE at S seconds, e.g.\n"
    "                        k_T=1.2@20 (a 20 % torque-constant fault at 20 s); the state is\n"
    "                        continuous, the log's metadata and truth name the step\n\n"
    "Simulation:\n"
    "  --duration S          length of the log (default 20 s)\n"
    "  --seed N              random seed for noise, multisine phases, PRBS (default 1)\n"
    "  --rate HZ             log sample rate; must divide the controller rate (default 2000)\n"
    "  --controller-rate HZ  controller sample rate (default 2000)\n"
    "  --kp, --kv, --ti      position gain 1/s (40), velocity gain N m s/rad (0.3), integral\n"
    "                        time s (0.05)\n"
    "  --torque-noise NM     std of white noise on the torque reference (default 0.02)\n"
    "  --load-noise NM       std of the low-pass load torque on the arm (default 2)\n"
    "  --encoder-counts N    motor encoder counts per revolution, 0 for ideal (default 65536)\n"
    "  --substeps N          Runge-Kutta steps per controller period (default 10)\n"
    "  --motor-velocity      also log the true motor_velocity_rad_s\n"
    "  --log-arm-accel       also log the true arm_accel_rad_s2\n"
    "  --arm-angle           also log arm_angle_rad, an arm-side encoder (2^22 counts per\n"
    "                        revolution) reading the truth's arm angle phi_a, so that fits\n"
    "                        report the deflection r phi_m - phi_a they predict\n"
    "  --velocity-feedforward F  a controller other than Figure 5.1's: F times the\n"
    "                        reference's velocity fed forward into the velocity loop\n"
    "  --velocity-filter HZ  ... and a first-order low-pass of HZ on its velocity estimate\n"
    "                        (both written to the log's metadata)\n"
    "  --out FILE            the CSV log to write (required); the truth goes to FILE with\n"
    "                        .csv replaced by .truth.json\n"
    "  --json                print a JSON summary\n";

std::string truthPath(const std::string& csv) {
  const std::string ext = ".csv";
  if (csv.size() > ext.size() && csv.compare(csv.size() - ext.size(), ext.size(), ext) == 0)
    return csv.substr(0, csv.size() - ext.size()) + ".truth.json";
  return csv + ".truth.json";
}

bool parsePair(const std::string& text, double& a, double& b) {
  char extra = 0;
  return std::sscanf(text.c_str(), "%lf:%lf%c", &a, &b, &extra) == 2;
}

nlohmann::json truthJson(const PhysicalModel& model, const std::vector<Effect>& effects,
                         const SimulationOptions& o) {
  nlohmann::json fx = nlohmann::json::array();
  for (const auto& e : effects) {
    nlohmann::json params = nlohmann::json::object();
    const auto info = effectParameters(e);
    for (std::size_t i = 0; i < info.size(); ++i)
      params[info[i].name] = {{"value", e.values[i]}, {"unit", info[i].unit}};
    fx.push_back({{"name", toString(e.kind)}, {"parameters", params}});
  }
  const auto& c = o.controller;
  const auto& d = o.disturbance;
  const auto& x = o.excitation;
  nlohmann::json truth = {{"generator", "FlexArm simulator (flexarm simulate)"},
          {"model", modelJson(model)},
          {"effects", fx},
          {"controller",
           {{"structure", "P position loop, PI velocity loop (Figure 5.1)"},
            {"rate_hz", c.rateHz},
            {"kp_1_s", c.kp},
            {"kv_nm_s_rad", c.kv},
            {"ti_s", c.ti}}},
          {"disturbance",
           {{"torque_noise_std_nm", d.torqueNoiseStd},
            {"load_noise_std_nm", d.loadTorqueStd},
            {"load_bandwidth_hz", d.loadBandwidthHz},
            {"encoder_counts_per_rev", d.encoderCountsPerRev}}},
          {"excitation",
           {{"kind", toString(x.kind)},
            {"amplitude_rad", x.amplitude},
            {"chirp_start_hz", x.chirpStartHz},
            {"chirp_end_hz", x.chirpEndHz},
            {"multisine_period_s", x.multisinePeriodS},
            {"multisine_lines", {x.multisineFirstLine, x.multisineLastLine}},
            {"prbs_clock_s", x.prbsClockS},
            {"prbs_bits", x.prbsBits},
            {"taper_s", x.taperS},
            {"reference_velocity_rad_s", o.referenceVelocity}}},
          {"seed", o.seed},
          {"duration_s", o.durationS},
          {"log_rate_hz", o.logRateHz},
          {"substeps", o.substeps}};
  if (!o.parameterSteps.empty()) {
    // Only logs with a fault carry the key, so that the others keep their bytes.
    nlohmann::json steps = nlohmann::json::array();
    std::map<std::string, double> current;
    for (const auto& p : model.parameters()) current[p.name] = p.value;
    auto ordered = o.parameterSteps;
    std::stable_sort(ordered.begin(), ordered.end(),
                     [](const ParameterStep& a, const ParameterStep& b) { return a.timeS < b.timeS; });
    for (const auto& s : ordered)
      steps.push_back({{"name", s.name},
                       {"value_before", std::exchange(current[s.name], s.value)},
                       {"value", s.value},
                       {"time_s", s.timeS}});
    truth["parameter_steps"] = steps;
  }
  return truth;
}

}  // namespace

int runSimulate(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  auto valued = modelValuedOptions();
  for (const char* v : {"effect", "step", "excitation", "amplitude", "chirp", "multisine-lines",
                        "multisine-period", "prbs-clock", "reference-velocity", "duration", "seed",
                        "rate", "controller-rate", "kp", "kv", "ti", "torque-noise", "load-noise",
                        "encoder-counts", "substeps", "velocity-feedforward", "velocity-filter", "out"})
    valued.push_back(v);
  for (const char* v : kSimulateFleetOptions) valued.push_back(v);
  auto flags = modelFlagOptions();
  for (const char* f : {"json", "help", "motor-velocity", "log-arm-accel", "arm-angle"}) flags.push_back(f);
  ArgParser args(flags, valued);
  auto usage = [&err](const std::string& why) {
    err << "flexarm simulate: " << why << "\n(flexarm simulate --help explains the options)\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << kSimulateHelp << modelOptionsHelp() << "\nEffects (repeatable; values default as shown):\n" << effectHelpLines()
        << kSimulateHelpTail << kSimulateFleetHelp;
    return kExitOk;
  }
  if (args.value("fleet")) return runSimulateFleet(args, out, err);
  if (!args.positional().empty()) return usage("unexpected argument '" + args.positional()[0] + "'");
  const auto outPath = args.value("out");
  if (!outPath) return usage("--out LOG.csv is required");

  SimulationOptions o;
  if (auto e = args.value("excitation")) {
    auto kind = excitationKindFromString(*e);
    if (!kind) return usage("--excitation must be chirp, multisine, prbs or none, not " + inQuotes(*e));
    o.excitation.kind = *kind;
  }
  long seed = 1;
  int counts = static_cast<int>(o.disturbance.encoderCountsPerRev);
  double prbsClock = o.excitation.prbsClockS;
  if (!args.number("amplitude", o.excitation.amplitude) ||
      !args.number("multisine-period", o.excitation.multisinePeriodS) ||
      !args.number("prbs-clock", prbsClock) ||
      !args.number("reference-velocity", o.referenceVelocity) ||
      !args.number("duration", o.durationS) || !args.number("controller-rate", o.controller.rateHz) ||
      !args.number("kp", o.controller.kp) || !args.number("kv", o.controller.kv) ||
      !args.number("ti", o.controller.ti) ||
      !args.number("torque-noise", o.disturbance.torqueNoiseStd) ||
      !args.number("load-noise", o.disturbance.loadTorqueStd) || !args.integer("seed", seed) ||
      !args.integer("encoder-counts", counts, 0, 1 << 30) ||
      !args.integer("substeps", o.substeps, 1, 10000) ||
      !args.number("velocity-feedforward", o.velocityFeedForward) ||
      !args.number("velocity-filter", o.velocityFilterHz))
    return usage(args.error());
  o.excitation.prbsClockS = prbsClock;
  o.disturbance.encoderCountsPerRev = counts;
  if (seed < 0) return usage("--seed must be >= 0");
  o.seed = static_cast<std::uint64_t>(seed);
  o.logRateHz = o.controller.rateHz;
  if (!args.number("rate", o.logRateHz)) return usage(args.error());
  if (auto c = args.value("chirp");
      c && !parsePair(*c, o.excitation.chirpStartHz, o.excitation.chirpEndHz))
    return usage("--chirp expects HZ0:HZ1, got " + inQuotes(*c));
  if (auto l = args.value("multisine-lines")) {
    double a = 0, b = 0;
    if (!parsePair(*l, a, b) || a != std::floor(a) || b != std::floor(b))
      return usage("--multisine-lines expects K0:K1 (integers), got " + inQuotes(*l));
    o.excitation.multisineFirstLine = static_cast<int>(a);
    o.excitation.multisineLastLine = static_cast<int>(b);
  }
  o.logMotorVelocity = args.flag("motor-velocity");
  o.logArmAcceleration = args.flag("log-arm-accel");
  o.logArmAngle = args.flag("arm-angle");
  std::string why;
  if (!o.isValid(&why)) return usage(why);
  if (o.excitation.kind == ExcitationKind::Multisine &&
      2.0 * M_PI * o.excitation.multisineLastLine / o.excitation.multisinePeriodS >=
          M_PI * o.controller.rateHz)
    return usage("the multisine lines reach the Nyquist frequency of the controller rate");

  std::vector<Effect> effects;
  for (const auto& spec : args.values("effect")) {
    auto e = parseEffect(spec, &why);
    if (!e) return usage("--effect " + spec + ": " + why);
    effects.push_back(*e);
  }
  for (const auto& spec : args.values("step")) {
    auto step = parseParameterStep(spec, &why);
    if (!step) return usage("--step: " + why);
    o.parameterSteps.push_back(*step);
  }
  auto model = modelFromArgs(args, "simulate", err);
  if (!model) return kExitUsage;
  for (const auto& s : o.parameterSteps) {
    const int i = model->indexOf(s.name);
    if (i < 0) return usage("--step: the " + model->structureName() + " model has no parameter " + inQuotes(s.name));
    const auto& p = model->parameters()[static_cast<std::size_t>(i)];
    if (s.value < p.lower || s.value > p.upper)
      return usage("--step " + toString(s) + ": the value is outside " + s.name + "'s bounds");
    if (s.timeS > o.durationS) return usage("--step " + toString(s) + ": the time is after the log's end");
  }

  SimulationResult r;
  try {
    r = simulateClosedLoop(*model, effects, o);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  if (r.termination != Termination::Converged) {
    err << "flexarm simulate: " << r.message << "\n";
    return kExitNumerical;
  }
  std::string effectText;
  for (const auto& e : effects) effectText += std::string(effectText.empty() ? "" : ", ") + toString(e.kind);
  r.data.setMeta("description", "simulated " + std::string(toString(o.excitation.kind)) + ", " +
                                    model->structureName() + " model" +
                                    (effectText.empty() ? "" : " with " + effectText));
  ReadError werr;
  if (!writeFlexArmCsv(r.data, *outPath, &werr)) {
    err << "flexarm simulate: " << werr.toString() << "\n";
    return kExitBadInput;
  }
  const std::string truthFile = truthPath(*outPath);
  const nlohmann::json truth = truthJson(*model, effects, o);
  if (!writeFileAtomically(truthFile, truth.dump(2) + "\n", &why)) {
    err << "flexarm simulate: " << why << "\n";
    return kExitBadInput;
  }
  if (args.flag("json")) {
    out << nlohmann::json{{"output", *outPath},
                          {"truth", truthFile},
                          {"samples", r.data.samples()},
                          {"sample_rate_hz", r.data.sampleRateHz()},
                          {"controller_ticks", r.controllerTicks},
                          {"seconds", r.seconds}}
               .dump(2)
        << "\n";
  } else {
    out << "wrote " << *outPath << " (" << r.data.samples() << " samples at "
        << r.data.sampleRateHz() << " Hz) and " << truthFile << "\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
