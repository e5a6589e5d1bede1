// flexarm discover EST_LOG --model two-mass|three-mass [--validation-log VAL_LOG]
//                  [--until-none [--max-effects N]] [--effect NAME[:values] ...] [--json]
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "core/discovery/discovery.h"
#include "core/discovery/discovery_json.h"
#include "core/session/report.h"
#include "core/signal/excitation.h"

namespace flexarm::cli {
namespace {

const char* kDiscoverHelp =
    "Usage: flexarm discover EST_LOG --model two-mass|three-mass [--validation-log VAL_LOG]\n"
    "                        [--until-none [--max-effects N]] [--effect NAME[:V1[,V2]] ...]\n"
    "                        [--effects A,B,...] [--threads N] [--json]\n\n"
    "Finds the effects the physical model misses. The base model (chapter 3: (3.13) or (3.21),\n"
    "nominal parameters as the start) is fitted to the motor velocity differentiated from the\n"
    "motor angle (Section 5.2; a log whose output is the motor velocity, motor_velocity_rad_s\n"
    "or an output in rad/s, is integrated to an angle from zero and differentiated the same\n"
    "way) by prediction error, simulating the model from the torque reference at the data's\n"
    "rate with a slow load observer (the predictor `flexarm fit --effect` uses on closed-loop\n"
    "logs). Each candidate effect (every effect below; encoder_skew only on a log with an arm\n"
    "encoder) is added as a physical term and refitted with the base parameters and every\n"
    "effect already in the model. An effect is named only when the F-test of its parameters\n"
    "passes at 99 %, the AIC falls, its size's 99 % interval excludes zero (F_c = 0, b = 0,\n"
    "T_d = 0, ...), the torque it adds is at least 2 % of the model's own friction and gear\n"
    "spring torques at the log's speeds, and the residual on held-out data (the validation\n"
    "log, else the last 30 % of every second of the log) is explained by the change the\n"
    "effect predicts (z-test at 99 %); otherwise the answer is none.\n"
    "When several are significant, each pair is refitted together and the one whose\n"
    "parameters still pass the F-test with the other in the model is named. Every verdict is\n"
    "then confirmed or not by a second method on the held-out data: the residual before and\n"
    "after, and a test specific to the effect (its signature regressed beside its\n"
    "look-alikes'). Logs faster than 1.1 kHz are fitted at about 1 kHz (torque averaged over\n"
    "blocks).\n\n"
    "  --model NAME          base model: two-mass, three-mass or four-mass (required)\n"
    "  --validation-log LOG  validation data (else the log's validation range, if stored;\n"
    "                        else the last 0.3 s of every second of the log is held out)\n"
    "  --until-none          the loop: find, add, refit the base and every effect so far,\n"
    "                        find again, until none is missing (or --max-effects)\n"
    "  --max-effects N       effects the loop finds at most (default 4)\n"
    "  --effect NAME[:V1[,V2]]  an effect the base already has (repeatable, as in `fit`):\n"
    "                        refitted with it and not looked for again\n"
    "  --effects A,B         candidates to test (default: every effect listed below)\n"
    "  --threads N           candidates fitted in parallel (default 2)\n"
    "  --observer-bandwidth HZ  the load observer's bandwidth (default 1; 0: simulation)\n"
    "  --json                print the result as JSON\n\n"
    "JSON (the shape sessions and reports keep, schema 2): effect (the first effect named, or\n"
    "\"none\"), effects [{effect, spec, parameters [{name, unit, value, std, lower, upper,\n"
    "estimated, derived}], magnitude, size {torque_rms, friction_rms, spring_rms, share},\n"
    "evidence, confirmed, confirmation {...}, before, after}] in the order found, also_tried\n"
    "[{round, effect, spec, magnitude, size, reason}], stop_reason, tied, evidence,\n"
    "candidates (of the first round) and rounds [{effects, effect, decision, candidates}],\n"
    "base and augmented {fit_percent, fit_percent_validation (the seed's (5.2)),\n"
    "fit_percent_nrmse, fit_percent_validation_nrmse (MATLAB compare's NRMSE fit),\n"
    "rms_estimation, rms_validation}, fit_percent_definition, validation_data, disagreement,\n"
    "sample_time, seconds.\n";

// The `flexarm fit` command that refines the final model from where discovery ended: an
// extra mass folded into the larger structure, the other effects as --effect.
std::string refineLine(const std::string& log, const DiscoveryResult& r) {
  const auto merged = mergedModel(*r.augmentedModel, r.augmentedEffects);
  std::string s = "flexarm fit " + log + " --model " + merged.first->structureName();
  for (const auto& e : merged.second) s += " --effect " + toString(e);
  for (const auto& p : merged.first->parameters()) {
    if (!p.free) continue;
    s += " --start " + p.name + "=" + formatSignificant(p.value, 8);
    // A damping the fit took below zero needs its default bound opened.
    if (p.value < 0.0 && p.name.rfind("d_", 0) == 0) s += " --bound " + p.name + "=-inf:inf";
  }
  return s;
}

}  // namespace

int runDiscover(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> valued = logReadOptionNames();
  for (const char* n : {"model", "validation-log", "effects", "threads", "effect", "max-effects", "observer-bandwidth"}) valued.push_back(n);
  ArgParser args({"json", "help", "until-none"}, valued);
  if (!args.parse(argv)) {
    err << "flexarm discover: " << args.error() << "\n" << kDiscoverHelp;
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << kDiscoverHelp << "\nEffects (candidates and --effect; values default as shown):\n" << effectHelpLines()
        << "\n" << logReadOptionsHelp();
    return kExitOk;
  }
  const std::string pre = "flexarm discover: ";
  if (args.positional().size() != 1) {
    err << pre << "expected exactly one EST_LOG\n";
    return kExitUsage;
  }
  const auto modelName = args.value("model");
  if (!modelName) {
    err << pre << "--model is required (two-mass, three-mass or four-mass)\n";
    return kExitUsage;
  }
  if (*modelName != "two-mass" && *modelName != "three-mass" && *modelName != "four-mass") {
    err << pre << "--model must be two-mass, three-mass or four-mass (a model with a gear "
                  "spring), not '" << *modelName << "'\n";
    return kExitUsage;
  }
  DiscoveryOptions options;
  if (auto list = args.value("effects")) {
    options.candidates.clear();
    std::size_t pos = 0;
    while (pos <= list->size()) {
      const std::size_t comma = std::min(list->find(',', pos), list->size());
      const std::string name = list->substr(pos, comma - pos);
      const auto kind = effectKindFromString(name);
      if (!kind) {
        err << pre << "--effects: unknown effect '" << name << "'\n";
        return kExitUsage;
      }
      options.candidates.push_back(*kind);
      pos = comma + 1;
    }
  }
  std::string why;
  for (const auto& spec : args.values("effect")) {
    auto e = parseEffect(spec, &why);
    if (!e) {
      err << pre << "--effect " << spec << ": " << why << "\n";
      return kExitUsage;
    }
    options.startEffects.push_back(*e);
  }
  if (!args.integer("threads", options.threads, 1, 64) ||
      !args.number("observer-bandwidth", options.observerBandwidthHz)) {
    err << pre << args.error() << "\n";
    return kExitUsage;
  }
  if (args.value("max-effects") && !args.flag("until-none")) {
    err << pre << "--max-effects needs --until-none\n";
    return kExitUsage;
  }
  if (args.flag("until-none")) {
    options.maxEffects = 4;
    if (!args.integer("max-effects", options.maxEffects, 1, 6)) {
      err << pre << args.error() << "\n";
      return kExitUsage;
    }
  }
  if (!options.isValid(&why)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  auto readOptions = logReadOptions(args, err);
  if (!readOptions) return kExitUsage;
  auto est = loadLog(args.positional()[0], *readOptions, err);
  if (!est) return kExitBadInput;
  std::optional<IdData> val;
  if (auto v = args.value("validation-log")) {
    val = loadLog(*v, *readOptions, err);
    if (!val) return kExitBadInput;
  } else if (est->validationRange && !est->validationRange->empty()) {
    val = est->select(*est->validationRange);
    if (est->estimationRange && !est->estimationRange->empty())
      *est = est->select(*est->estimationRange);
  }
  // Dead data are bad input, named by channel, before the search starts.
  for (const auto& [data, file] : {std::pair{&*est, args.positional()[0]},
                                   std::pair{val ? &*val : nullptr, args.value("validation-log").value_or(args.positional()[0])}}) {
    if (!data) continue;
    if (const std::string dead = deadDataProblem(*data); !dead.empty()) {
      err << pre << file << ": " << dead << "\n";
      return kExitBadInput;
    }
  }
  const auto base = makeModel(*modelName);
  DiscoveryResult r;
  try {
    r = discoverMissingEffect(*base, *est, val ? &*val : nullptr, options);
  } catch (const std::invalid_argument& e) {
    err << pre << e.what() << "\n";
    return kExitUsage;
  }
  if (r.termination == Termination::Failed) {
    err << pre << r.message << "\n";
    return kExitNumerical;
  }
  if (!args.flag("json")) {
    if (options.maxEffects > 1) {
      out << "Effects: ";
      if (r.found.empty()) out << "none";
      for (std::size_t i = 0; i < r.found.size(); ++i) out << (i ? ", " : "") << toString(r.found[i].kind);
      out << " (" << r.stopReason << ")\n";
      // The gap step by step: the held-out residual and fit % after each confirmed effect.
      if (!r.found.empty()) {
        char line[240];
        std::snprintf(line, sizeof line, "  step 0  %-36s held-out RMS %.4g rad/s  fit %.2f %%\n", "base",
                      r.found.front().before.rmsValidation, r.found.front().before.fitPercentValidation);
        out << line;
        std::string model = "base";
        for (std::size_t i = 0; i < r.found.size(); ++i) {
          const FoundEffect& f = r.found[i];
          model += " + " + std::string(toString(f.kind));
          std::snprintf(line, sizeof line, "  step %zu  %-36s held-out RMS %.4g rad/s  fit %.2f %%  %s\n", i + 1,
                        model.c_str(), f.after.rmsValidation, f.after.fitPercentValidation,
                        f.confirmation.confirmed ? "confirmed" : "not confirmed");
          out << line;
        }
      }
    }
    if (!r.alsoTried.empty()) {
      out << "Also tried:\n";
      for (const auto& t : r.alsoTried)
        out << "  round " << t.round + 1 << " " << toString(t.kind) << ": " << t.reason << "\n";
    }
    for (std::size_t i = 0; i < r.rounds.size(); ++i) {
      const DiscoveryRound& d = r.rounds[i];
      out << (options.maxEffects > 1 ? "\nStep " + std::to_string(i + 1) + ": " : std::string()) << "Effect: "
          << (d.effect ? toString(*d.effect) : "none") << "\n"
          << d.evidence << "\n\n"
          << d.disagreement.summary << "\n\nCandidates:\n";
      for (const auto& c : d.candidates) {
        char line[200];
        std::snprintf(line, sizeof line, "  %-17s loss %.4g  held-out RMS %.4g  AIC %+.1f  %s\n", toString(c.kind),
                      c.lossEst, c.score.rmsValidation, c.aic - d.aic, c.significant ? "significant" : "-");
        out << line << "      " << c.reason << "\n";
      }
    }
    if (!r.found.empty() && r.augmentedModel) out << "Refine: " << refineLine(args.positional()[0], r) << "\n";
    out << "Fit %: the seed's (5.2), " << r.fitBasis << "\n";
    out << "Seconds: " << r.seconds << "\n";
    return kExitOk;
  }
  const nlohmann::json j = discoveryResultJson(r);
  out << j.dump(2) << "\n";
  return kExitOk;
}

}  // namespace flexarm::cli
