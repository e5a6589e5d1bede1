// flexarm discover EST_LOG --model two-mass|three-mass [--validation-log VAL_LOG] [--json]
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "core/discovery/discovery.h"
#include "core/session/report.h"
#include "core/signal/excitation.h"

namespace flexarm::cli {
namespace {

const char* kDiscoverHelp =
    "Usage: flexarm discover EST_LOG --model two-mass|three-mass [--validation-log VAL_LOG]\n"
    "                        [--effects A,B,...] [--threads N] [--json]\n\n"
    "Finds the effect the physical model misses. The base model (chapter 3: (3.13) or (3.21),\n"
    "nominal parameters as the start) is fitted to the motor velocity differentiated from the\n"
    "motor angle (Section 5.2; a log whose output is the motor velocity, motor_velocity_rad_s\n"
    "or an output in rad/s, is integrated to an angle from zero and differentiated the same\n"
    "way) by prediction error, simulating the model from the torque\n"
    "reference at the data's rate with a slow load observer. Each candidate effect\n"
    "(coulomb_friction, backlash, nonlinear_spring, input_delay, torque_ripple, extra_mass) is\n"
    "added as a physical term and refitted with the base parameters. An effect is named only\n"
    "when the F-test of the extra parameters passes at 99 %, the AIC falls, the effect\n"
    "parameter's 99 % interval excludes zero and the validation residual RMS drops by 10 % or\n"
    "more; otherwise the answer is none. Logs faster than 1.1 kHz are fitted at about 1 kHz\n"
    "(torque averaged over blocks).\n\n"
    "  --model NAME          base model: two-mass, three-mass or four-mass (required)\n"
    "  --validation-log LOG  validation data (else the log's validation range, if stored)\n"
    "  --effects A,B         candidates to test (default: all six)\n"
    "  --threads N           candidates fitted in parallel (default 2)\n"
    "  --json                print the result as JSON\n\n"
    "JSON fields: effect (a name or \"none\"), tied, effect_parameters {name: {value, std,\n"
    "unit, lower, upper}}, evidence, candidates [{effect, loss_est, rms_val, aic, f, f_threshold,\n"
    "significant, reason, parameters}], base and augmented {fit_percent,\n"
    "fit_percent_validation (the seed's (5.2)), fit_percent_nrmse,\n"
    "fit_percent_validation_nrmse (MATLAB compare's NRMSE fit), rms_estimation,\n"
    "rms_validation}, disagreement (summary,\n"
    "whiteness and independence tests), sample_time, seconds.\n";

nlohmann::json scoreJson(const DiscoveryScore& s, bool hasValidation) {
  nlohmann::json j;
  j["fit_percent"] = s.fitPercent;
  j["fit_percent_nrmse"] = s.fitPercentNrmse;
  j["rms_estimation"] = s.rmsEstimation;
  if (hasValidation) {
    j["fit_percent_validation"] = s.fitPercentValidation;
    j["fit_percent_validation_nrmse"] = s.fitPercentValidationNrmse;
    j["rms_validation"] = s.rmsValidation;
  } else {
    j["fit_percent_validation"] = nullptr;
    j["fit_percent_validation_nrmse"] = nullptr;
    j["rms_validation"] = nullptr;
  }
  return j;
}

nlohmann::json finiteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json parametersJson(const std::vector<EffectParameterEstimate>& ps) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& p : ps)
    j[p.name] = {{"value", p.value},       {"std", finiteOrNull(p.std)},
                 {"unit", p.unit},         {"lower", finiteOrNull(p.lower)},
                 {"upper", finiteOrNull(p.upper)}, {"estimated", p.estimated}};
  return j;
}

}  // namespace

int runDiscover(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> valued = logReadOptionNames();
  for (const char* n : {"model", "validation-log", "effects", "threads"}) valued.push_back(n);
  ArgParser args({"json", "help"}, valued);
  if (!args.parse(argv)) {
    err << "flexarm discover: " << args.error() << "\n" << kDiscoverHelp;
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << kDiscoverHelp << "\n" << logReadOptionsHelp();
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
  if (!args.integer("threads", options.threads, 1, 64)) {
    err << pre << args.error() << "\n";
    return kExitUsage;
  }
  std::string why;
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
  const DiscoveryResult r = discoverMissingEffect(*base, *est, val ? &*val : nullptr, options);
  if (r.termination == Termination::Failed) {
    err << pre << r.message << "\n";
    return kExitNumerical;
  }
  const CandidateFit* best = r.best >= 0 ? &r.candidates[static_cast<std::size_t>(r.best)] : nullptr;
  if (!args.flag("json")) {
    out << "Effect: " << (r.effect ? toString(*r.effect) : "none") << "\n"
        << r.evidence << "\n\n"
        << r.disagreement.summary << "\n\nCandidates:\n";
    for (const auto& c : r.candidates) {
      char line[200];
      std::snprintf(line, sizeof line, "  %-17s loss %.4g  val RMS %.4g  AIC %+.1f  %s\n",
                    toString(c.kind), c.lossEst, c.score.rmsValidation, c.aic - r.baseAic,
                    c.significant ? "significant" : "-");
      out << line << "      " << c.reason << "\n";
    }
    if (r.effect) {  // the augmented model as `flexarm fit` refines it
      out << "Refine: flexarm fit " << args.positional()[0] << " --model " << *modelName;
      for (const auto& e : r.augmentedEffects) out << " --effect " << toString(e);
      // The refitted base as start values, so the fit starts where discovery ended.
      if (r.augmentedModel)
        for (const auto& p : r.augmentedModel->parameters()) {
          if (!p.free) continue;
          out << " --start " << p.name << "=" << formatSignificant(p.value, 8);
          // A damping the base fit took below zero needs its default bound opened.
          if (p.value < 0.0 && p.name.rfind("d_", 0) == 0) out << " --bound " << p.name << "=-inf:inf";
        }
      out << "\n";
    }
    out << "Seconds: " << r.seconds << "\n";
    return kExitOk;
  }
  nlohmann::json j;
  j["effect"] = r.effect ? toString(*r.effect) : "none";
  j["tied"] = nlohmann::json::array();
  for (EffectKind k : r.tied) j["tied"].push_back(toString(k));
  j["effect_parameters"] = best ? parametersJson(best->parameters) : nlohmann::json::object();
  j["evidence"] = r.evidence;
  j["candidates"] = nlohmann::json::array();
  for (const auto& c : r.candidates) {
    nlohmann::json cj;
    cj["effect"] = toString(c.kind);
    cj["loss_est"] = c.lossEst;
    cj["rms_val"] = r.hasValidation ? finiteOrNull(c.score.rmsValidation) : nlohmann::json();
    cj["aic"] = finiteOrNull(c.aic);
    cj["f"] = c.fStatistic;
    cj["f_threshold"] = c.fThreshold;
    cj["significant"] = c.significant;
    cj["reason"] = c.reason;
    cj["parameters"] = parametersJson(c.parameters);
    j["candidates"].push_back(cj);
  }
  j["base"] = scoreJson(r.base, r.hasValidation);
  j["base"]["aic"] = r.baseAic;
  j["augmented"] = scoreJson(r.augmented, r.hasValidation);
  // The augmented model's effects as `flexarm fit --effect` takes them.
  j["augmented"]["effects"] = nlohmann::json::array();
  for (const auto& e : r.augmentedEffects) j["augmented"]["effects"].push_back(toString(e));
  j["disagreement"] = {{"summary", r.disagreement.summary},
                       {"white", r.disagreement.tests.white},
                       {"independent", r.disagreement.tests.independent},
                       {"residual_peak_rad_s", r.disagreement.spectrumPeakRadS},
                       {"correlation_sign_velocity", r.disagreement.correlationSignVelocity},
                       {"resonances_rad_s", r.disagreement.resonancesRadS}};
  j["sample_time"] = r.sampleTime;
  j["seconds"] = r.seconds;
  out << j.dump(2) << "\n";
  return kExitOk;
}

}  // namespace flexarm::cli
