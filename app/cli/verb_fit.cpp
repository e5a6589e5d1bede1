// flexarm fit LOG --model SPEC [options] [--json]
#include "app/cli/verb_fit.h"

#include <cmath>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "app/cli/log_args.h"
#include "app/cli/progress_line.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit_experiments.h"

namespace flexarm::cli {

namespace {

const char* kFitHelp =
    "Usage: flexarm fit LOG --model SPEC [options] [--json]\n\n"
    "Estimates a model by prediction error (the seed's chapters 4 and 5) and reports its\n"
    "parameters with standard deviations, loss, fit % (5.2) of the simulated output on the\n"
    "estimation and validation data, and the notch and peak frequencies.\n\n";

bool parseInts(const std::string& text, std::vector<int>& out) {
  out.clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      const int v = std::stoi(item, &used);
      if (used != item.size()) return false;
      out.push_back(v);
    } catch (const std::exception&) {
      return false;
    }
  }
  return !out.empty();
}

std::vector<std::string> splitComma(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// The parameter names of model and its effects, for messages.
std::string parameterNames(const PhysicalModel& model, const std::vector<FitEffect>& effects) {
  std::string out;
  for (const auto& p : model.parameters()) out += (out.empty() ? "" : ", ") + p.name;
  for (const auto& e : effects)
    for (const auto& info : effectParameters(e.effect.kind)) out += ", " + info.name;
  return out;
}

// The effect value named `name` ("F_c", "beta", ...) of the fit's effects: (effect, index), or
// (-1, -1) when none of them has it.
std::pair<int, int> effectValue(const std::vector<FitEffect>& effects, const std::string& name) {
  for (std::size_t e = 0; e < effects.size(); ++e) {
    const auto& info = effectParameters(effects[e].effect.kind);
    for (std::size_t k = 0; k < info.size(); ++k)
      if (info[k].name == name) return {static_cast<int>(e), static_cast<int>(k)};
  }
  return {-1, -1};
}

// --free, --fix, --start and --bound of a physical fit, in command-line order (a later --free
// or --fix of a parameter overrides an earlier one): free flags on the start model and its
// effects, start values and bounds into the options; an effect's value given by --fix or
// --start is set in the effect itself. False after printing a usage error.
bool applyStartOptions(ArgParser& args, PhysicalModel& model, FitOptions& o, const std::string& pre,
                       std::ostream& err) {
  auto& effects = o.model.effects;
  auto known = [&](const char* option, const std::string& name) {
    if (model.indexOf(name) >= 0) return true;
    err << pre << "--" << option << ": the " << model.structureName() << " model"
        << (effects.empty() ? "" : " and its effects") << " have no parameter '" << name
        << "' (its parameters: " << parameterNames(model, effects) << ")\n";
    return false;
  };
  for (const auto& [option, text] : args.sequence()) {
    if (option == "free") {
      for (const auto& p : model.parameters()) model.setFree(p.name, false);
      for (auto& e : effects) e.free = {false, false};
      for (const auto& n : splitComma(text)) {
        if (const auto [e, k] = effectValue(effects, n); e >= 0) {
          effects[static_cast<std::size_t>(e)].free[static_cast<std::size_t>(k)] = true;
          continue;
        }
        if (!known("free", n)) return false;
        model.setFree(n, true);
      }
    } else if (option == "fix" || option == "start") {
      const bool valued = text.find('=') != std::string::npos;
      const auto v = parameterValueFromText(text);
      if ((valued || option == "start") && !v) {
        err << pre << "--" << option << " expects NAME=VALUE (a finite number), not '" << text << "'\n";
        return false;
      }
      const std::string name = v ? v->name : text;
      if (const auto [e, k] = effectValue(effects, name); e >= 0) {
        FitEffect& f = effects[static_cast<std::size_t>(e)];
        if (v) f.effect.values[static_cast<std::size_t>(k)] = v->value;
        if (v && k == 1) f.scaleSmoothing = false;
        if (option == "fix") f.free[static_cast<std::size_t>(k)] = false;
        std::string why;
        if (!f.effect.isValid(&why)) {
          err << pre << "--" << option << " " << why << "\n";
          return false;
        }
        continue;
      }
      if (!known(option.c_str(), name)) return false;
      if (v) o.startValues.push_back(*v);
      if (option == "fix") model.setFree(name, false);
    } else if (option == "bound") {
      const auto b = parameterBoundFromText(text);
      if (!b) {
        err << pre << "--bound expects NAME=LO:HI with LO <= HI (numbers, or -inf/inf), not '" << text << "'\n";
        return false;
      }
      if (!known("bound", b->name)) return false;
      o.bounds.push_back(*b);
    }
  }
  return true;
}

// The range of a log in seconds as the command line names it: --range (or, for validation,
// --validation-range), else the range stored in the log's metadata. False after printing.
bool rangeOption(ArgParser& args, const char* option, const IdData& data, const std::optional<SampleRange>& stored,
                 std::optional<SecondsRange>& out, const std::string& pre, std::ostream& err) {
  out.reset();
  if (auto text = args.value(option)) {
    std::string why;
    auto r = secondsRangeFromText(*text, &why);
    if (!r) {
      err << pre << why << "\n";
      return false;
    }
    if (samplesIn(data, *r).empty()) {
      err << pre << "the range " << *text << " s holds no samples of the log\n";
      return false;
    }
    out = r;
  } else if (stored && !stored->empty()) {
    out = secondsOf(data, *stored);
  }
  return true;
}

// A log named by --log or --validation-log: FILE or FILE@A:B (fit_experiments.h). Exit code,
// kExitOk when `out` is set.
int experimentOption(const std::string& text, const char* option, const LogReadOptions& readOptions,
                     bool validation, ExperimentLogs& read, FitExperiment& out, std::string& file,
                     const std::string& pre, std::ostream& err) {
  std::string why;
  auto source = experimentSourceFromText(text, validation, &why);
  if (!source) {
    err << pre << "--" << option << " " << text << ": " << why << "\n";
    return kExitUsage;
  }
  ExperimentLoad l = loadExperiment(*source, readOptions, read);
  if (!l.experiment) {
    if (l.badInput) err << "flexarm: " << l.message << "\n";
    else err << pre << "--" << option << " " << text << ": " << l.message << "\n";
    return l.badInput ? kExitBadInput : kExitUsage;
  }
  out = *l.experiment;
  file = source->path;
  return kExitOk;
}

}  // namespace

bool parseModelSpec(const std::string& text, FitModelSpec& spec, std::string* why,
                    bool allowNonparametric) {
  spec = FitModelSpec{};
  const std::string head = text.substr(0, text.find(':'));
  if (allowNonparametric && (head == "spa" || head == "etfe")) {
    spec.kind = head == "spa" ? FitModelKind::Spa : FitModelKind::Etfe;
    std::vector<int> v;
    if (text.size() > head.size() &&
        (!parseInts(text.substr(head.size() + 1), v) || v.size() != 1 || v[0] < 0)) {
      if (why) *why = "--model " + head + ":W takes one non-negative window width";
      return false;
    }
    spec.windowWidth = v.empty() ? 0 : v[0];
    return true;
  }
  if (isPhysicalModelName(text)) {
    spec.kind = FitModelKind::Physical;
    spec.start = makePhysicalModel(text);
    if (!spec.start) {
      if (why)
        *why = "the physical model '" + text + "' is not available in this build yet (core/models "
               "does not provide it); use a black-box structure such as bj:5,5,5,5,1";
      return false;
    }
    return true;
  }
  const auto colon = text.find(':');
  const std::string name = text.substr(0, colon);
  auto s = polyStructureFromString(name);
  if (!s || colon == std::string::npos) {
    if (why)
      *why = "--model must be arx:NA,NB,NK, armax:NA,NB,NC,NK, oe:NB,NF,NK, "
             "bj:NB,NC,ND,NF,NK or two-mass|three-mass|four-mass|rigid, not '" + text + "'";
    return false;
  }
  std::vector<int> v;
  const std::size_t want[] = {3, 4, 3, 5};
  if (!parseInts(text.substr(colon + 1), v) || v.size() != want[static_cast<int>(*s)]) {
    if (why)
      *why = "--model " + name + " needs " + std::to_string(want[static_cast<int>(*s)]) +
             " comma-separated integers, not '" + text.substr(colon + 1) + "'";
    return false;
  }
  spec.kind = FitModelKind::BlackBox;
  spec.structure = *s;
  PolyOrders& o = spec.orders;
  o = PolyOrders{0, 1, 0, 0, 0, 1};
  switch (*s) {
    case PolyStructure::Arx: o.na = v[0]; o.nb = v[1]; o.nk = v[2]; break;
    case PolyStructure::Armax: o.na = v[0]; o.nb = v[1]; o.nc = v[2]; o.nk = v[3]; break;
    case PolyStructure::Oe: o.nb = v[0]; o.nf = v[1]; o.nk = v[2]; break;
    case PolyStructure::Bj:
      o.nb = v[0]; o.nc = v[1]; o.nd = v[2]; o.nf = v[3]; o.nk = v[4];
      break;
  }
  return o.isValid(why);
}

std::vector<std::string> fitValuedOptionNames() {
  std::vector<std::string> v = logReadOptionNames();
  for (const char* n : {"model", "effect", "free", "fix", "start", "bound", "decimate", "range", "log", "validation-log",
                        "validation-range", "max-iterations", "starts", "seed", "closed-loop", "method",
                        "cutoff", "friction", "outputs", "reference"})
    v.push_back(n);
  return v;
}

std::vector<std::string> fitFlagNames() {
  return {"json", "help", "noise-model", "keep-means", "no-idim-start", "same-instant"};
}

const char* fitOptionsHelp() {
  return "  --model SPEC          arx:NA,NB,NK | armax:NA,NB,NC,NK | oe:NB,NF,NK |\n"
         "                        bj:NB,NC,ND,NF,NK (orders of (4.8), delay NK), or a physical\n"
         "                        model two-mass|three-mass|four-mass|rigid (required)\n"
         "  --effect NAME[:V1,...] physical models: switch on a named effect (repeatable; the list\n"
         "                        under Effects below) and fit its sizes with the model's\n"
         "                        parameters (nonlinear grey-box estimation); the values given\n"
         "                        (else the defaults listed) are the start. A smoothing speed\n"
         "                        (v_s), the ripple's order n and gravity's phase phi_0 are held\n"
         "                        unless --free names them; --fix NAME=V holds any of them.\n"
         "                        The plant is simulated by Runge-Kutta from the measured torque\n"
         "                        (output error (5.7), each experiment from rigid-body motion at\n"
         "                        its first sample's speed, the means kept), the gradient by\n"
         "                        finite differences; standard deviations from the Gauss-Newton\n"
         "                        Jacobian (4.37). Closed-loop logs take the direct fit. The\n"
         "                        frequency response, notches and peaks are the linear part's.\n"
         "                        The smooth signs' speed v_s is 1 % of the data's RMS motor\n"
         "                        speed unless given\n"
         "  --outputs motor,arm   physical models on a log with an arm-side encoder: fit the arm\n"
         "                        too, the deflection r phi_m - phi_a with the motor output\n"
         "                        (nonlinear estimator), each weighted by its noise level (a\n"
         "                        first fit estimates both, then the fit is refined)\n"
         "  --free P1,P2          physical models: estimate only these parameters (model or\n"
         "                        effect parameters, e.g. J_m,k_g,beta)\n"
         "  --fix P[=V]           physical models: hold P, a model or effect parameter (at V,\n"
         "                        else its start value; repeatable).\n"
         "                        --free and --fix are applied in order: the last one naming a\n"
         "                        parameter wins (--fix J_m=1e-3 --free J_m estimates J_m from\n"
         "                        1e-3)\n"
         "  --start P=V           physical models: start P from V (repeatable); names as the\n"
         "                        parameter table prints them (J_m, k_g, d_a, ...). A fixed P is\n"
         "                        held at V. --start r=1 fits motor-side parameters (gear ratio\n"
         "                        1): the default J_a, J_g, k_*, d_* are referred to the motor\n"
         "                        side (times r_default^2 = 1/118^2) unless given, so the start\n"
         "                        has the default's dynamics; --fix r=V does the same\n"
         "  --bound P=LO:HI       physical models: search P only in [LO, HI] (repeatable; -inf\n"
         "                        and inf allowed). Defaults: the model's bounds with dampings\n"
         "                        d_* >= 0 and inertias and stiffnesses > 0; a parameter that\n"
         "                        ends on a bound is named in a warning (--bound d_g=-inf:inf\n"
         "                        allows the seed's negative dampings, Table 5.7)\n"
         "  --noise-model         physical models: innovations form, K estimated (else K = 0)\n"
         "  --starts N            physical models: N random starts besides the nominal one,\n"
         "                        plus two whose notches and peaks match the SPA estimate\n"
         "  --seed N              random seed for the starts (default 1)\n"
         "  --closed-loop M       physical models on a log with a reference channel:\n"
         "                        auto|direct|two-stage|indirect (default auto).\n"
         "                        direct fits output error to the logged input; in closed loop\n"
         "                        the noise fed back into the input biases it (4.43).\n"
         "                        two-stage fits output error to the part of the input the\n"
         "                        reference explains (an FIR of the reference), consistent in\n"
         "                        closed loop, with a covariance that allows coloured errors.\n"
         "                        indirect closes the log's controller around the model and\n"
         "                        fits the loop from the reference to the measured motor angle\n"
         "                        (its loss is that of the angle, in rad^2), at the log's own\n"
         "                        rate, from the log's first sample (the loss counts the\n"
         "                        estimation range). The controller is the one in the log's\n"
         "                        metadata (controller_rate_hz, controller_kp, controller_kv,\n"
         "                        controller_ti), else the cascade of Figure 5.1 (P position\n"
         "                        loop, PI velocity loop) identified from the reference, angle\n"
         "                        and torque; it is refused when it explains less than 99 % of\n"
         "                        the torque (5.2).\n"
         "                        auto (without --noise-model) uses the indirect fit whenever\n"
         "                        the log is undecimated and its controller explains the\n"
         "                        torque: on simulated logs (bench/bench_fit_closed_loop) it\n"
         "                        was unbiased with honest 99 % intervals at every noise\n"
         "                        level (0.03 to 10 times the sample logs'), where the direct\n"
         "                        fit was biased beyond its spread at every level and the\n"
         "                        two-stage fit at the lowest and the highest. Otherwise\n"
         "                        two-stage on a log with a reference, direct without one.\n"
         "                        It says which and why.\n"
         "  --method M            physical models: pem (prediction error, default), idim or\n"
         "                        idim-iv: the rigid part by inverse dynamics in closed form\n"
         "                        (Gautier and Janot's IDIM): tau = J q'' + F_v q' + F_c sign(q')\n"
         "                        + offset by least squares on the position low-passed by a\n"
         "                        Butterworth filter run both ways (--cutoff HZ, default a\n"
         "                        twentieth of the sample rate) and differentiated, every column\n"
         "                        low-passed and decimated alike; idim-iv takes instruments from\n"
         "                        the position reference (closed loop). --friction asymmetric\n"
         "                        fits F_v+, F_v-, F_c+, F_c- instead. A prismatic axis (metadata\n"
         "                        axis: prismatic, or an output in m) reports M, N s/m and N.\n"
         "                        The torque, held over each sample, is paired with the motion\n"
         "                        half a sample later; --same-instant pairs them at the same\n"
         "                        sample, as the EMPS reference does\n"
         "  --reference CHANNEL   the channel holding the position reference (default: the\n"
         "                        log's reference, angle_ref_rad), e.g. qg of a .mat file\n"
         "  --no-idim-start       a prediction-error fit of a flexible model starts from the\n"
         "                        model as given; by default inverse dynamics below its first\n"
         "                        notch scales its inertias, stiffnesses, dampings and f_m when\n"
         "                        its inertia is off by more than a factor of two (the fit says\n"
         "                        so; not when start values of them are given)\n"
         "  --decimate N          decimate by N with the anti-alias FIR before fitting (a\n"
         "                        physical model then holds each torque sample's mean over its\n"
         "                        period; its zero-order hold is an approximation there, and a\n"
         "                        warning says how far its 99 % intervals were measured to miss)\n"
         "  --range A:B           estimation data from A to B seconds (default: the log's\n"
         "                        stored estimation range, else everything)\n"
         "  --log LOG2[@A:B]      one more estimation experiment (repeatable): LOG2, or its\n"
         "                        part from A to B seconds (without @A:B its stored estimation\n"
         "                        range, else all of it; a range of LOG itself is LOG@A:B).\n"
         "                        The loss is summed over LOG and every --log, each simulated\n"
         "                        from zero state at its own first sample with its own means\n"
         "                        removed and its errors weighted by its own noise level;\n"
         "                        physical models then take the direct fit\n"
         "  --validation-log LOG2[@A:B] a validation experiment (repeatable; same reading\n"
         "                        options; without @A:B its stored validation range, else all\n"
         "                        of it), with the means of the estimation experiment on the\n"
         "                        same file, else LOG's\n"
         "  --validation-range A:B validation data from A to B seconds of LOG\n"
         "Every experiment's fit % is listed (JSON: fit_percent_experiments and\n"
         "fit_percent_validation_experiments, with their files and ranges).\n"
         "  --max-iterations N    Gauss-Newton iterations (default 100)\n"
         "  --keep-means          do not remove the estimation data's means (the seed does)\n"
         "  --json                print the result as JSON\n"
         "Physical, black-box and non-parametric models give the motor velocity: a log whose\n"
         "output is the motor angle is differentiated first (central differences, Section 5.2).\n"
         "Fit % is printed both ways, of the output simulated from zero initial state (input\n"
         "held constant between samples), from the start of the estimation range, and for\n"
         "validation from the first sample of the log holding the validation range:\n"
         "  (5.2)  the seed's 1 - sum e^2 / sum (y - mean y)^2 (JSON: fit_percent,\n"
         "         fit_percent_validation, and fit_percent in each experiment)\n"
         "  NRMSE  MATLAB compare's 1 - ||e|| / ||y - mean y|| (JSON: fit_percent_nrmse,\n"
         "         fit_percent_validation_nrmse); 96.4 % (5.2) is 81.0 % NRMSE.\n"
         "On a log with an arm-side encoder (arm_angle_rad) a physical fit says how well it\n"
         "predicts the deflection r phi_m - phi_a from the torque alone (JSON deflection:\n"
         "fit_percent, fit_percent_validation, their _nrmse twins, rms_estimation,\n"
         "rms_validation in rad, and the encoders' skew skew_s by least squares).\n"
         "Notches and peaks (JSON notches_rad_s, peaks_rad_s): the frequencies of the local\n"
         "minima and maxima of |G(i w)| of the estimate, what a click on the Bode plot reads\n"
         "(the same rule as `flexarm model`).\n";
}

int runFitPipeline(ArgParser& args, const std::string& verb, FitResult& result, std::ostream& err,
                   bool allowNonparametric, FitFiles* files) {
  const std::string pre = "flexarm " + verb + ": ";
  if (args.positional().size() != 1) {
    err << pre << "expected exactly one LOG\n";
    return kExitUsage;
  }
  auto modelText = args.value("model");
  if (!modelText) {
    err << pre << "--model is required\n";
    return kExitUsage;
  }
  FitOptions o;
  std::string why;
  if (!parseModelSpec(*modelText, o.model, &why, allowNonparametric)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  const bool physical = o.model.kind == FitModelKind::Physical;
  if (!physical && (args.value("free") || !args.values("fix").empty() || !args.values("start").empty() ||
                    !args.values("bound").empty() || args.flag("noise-model") || args.value("starts") ||
                    args.value("closed-loop"))) {
    err << pre << "--free, --fix, --start, --bound, --noise-model, --starts and --closed-loop apply to "
                  "physical models only\n";
    return kExitUsage;
  }
  int decimation = 1, maxIter = 100, starts = 0;
  long seed = 1;
  if (!args.integer("decimate", decimation, 1, 1000000) ||
      !args.integer("max-iterations", maxIter, 0, 100000) ||
      !args.integer("starts", starts, 0, 1000) || !args.integer("seed", seed)) {
    err << pre << args.error() << "\n";
    return kExitUsage;
  }
  if (maxIter < 1 || starts < 0 || decimation < 1 || seed < 0) {
    err << pre << "--decimate and --max-iterations must be at least 1, --starts and --seed not "
                  "negative\n";
    return kExitUsage;
  }
  o.decimation = static_cast<int>(decimation);
  o.maxIterations = static_cast<int>(maxIter);
  o.randomStarts = static_cast<int>(starts);
  o.seed = static_cast<unsigned>(seed);
  o.removeMeans = !args.flag("keep-means");
  o.noiseModel = args.flag("noise-model") ? NoiseModel::Innovations : NoiseModel::OutputError;
  if (auto m = args.value("closed-loop")) {
    auto c = closedLoopChoiceFromString(*m);
    if (!c) {
      err << pre << "--closed-loop expects auto, direct, two-stage or indirect, not '" << *m << "'\n";
      return kExitUsage;
    }
    o.closedLoop = *c;
    const bool outputErrorOnly = *c == ClosedLoopChoice::TwoStage || *c == ClosedLoopChoice::Indirect;
    if (outputErrorOnly && args.flag("noise-model")) {
      err << pre << "--closed-loop " << *m << " fits output error; it excludes --noise-model\n";
      return kExitUsage;
    }
    if (*c == ClosedLoopChoice::Indirect && decimation > 1) {
      err << pre << "--closed-loop indirect runs the controller at its own rate; it excludes --decimate\n";
      return kExitUsage;
    }
  }
  if (auto m = args.value("method")) {
    auto method = fitMethodFromString(*m);
    if (!method) {
      err << pre << "--method expects pem, idim or idim-iv, not '" << *m << "'\n";
      return kExitUsage;
    }
    o.method = *method;
  }
  if (!args.number("cutoff", o.idim.cutoffHz)) {
    err << pre << args.error() << "\n";
    return kExitUsage;
  }
  if (auto f = args.value("friction")) {
    if (*f != "symmetric" && *f != "asymmetric") {
      err << pre << "--friction expects symmetric or asymmetric, not '" << *f << "'\n";
      return kExitUsage;
    }
    o.idim.friction = *f == "asymmetric" ? IdimFriction::Asymmetric : IdimFriction::Symmetric;
  }
  o.idimStart = !args.flag("no-idim-start");
  o.idim.heldTorque = !args.flag("same-instant");
  if (auto ref = args.value("reference")) o.reference = *ref;
  if (auto outputs = args.value("outputs")) {
    if (*outputs != "motor" && *outputs != "motor,arm") {
      err << pre << "--outputs expects motor or motor,arm, not '" << *outputs << "'\n";
      return kExitUsage;
    }
    if (!physical) {
      err << pre << "--outputs applies to physical models only\n";
      return kExitUsage;
    }
    o.model.armOutput = *outputs == "motor,arm";
  }
  if (!physical && !args.values("effect").empty()) {
    err << pre << "--effect applies to physical models only\n";
    return kExitUsage;
  }
  for (const auto& spec : args.values("effect")) {
    auto e = parseEffect(spec, &why);
    if (!e) {
      err << pre << "--effect " << spec << ": " << why << "\n";
      return kExitUsage;
    }
    FitEffect f = FitEffect::defaults(e->kind);
    f.effect = *e;
    f.scaleSmoothing = spec.find(',') == std::string::npos;  // v_s given: kept
    o.model.effects.push_back(f);
  }
  if (physical) {
    auto start = std::shared_ptr<PhysicalModel>(makePhysicalModel(*modelText));
    if (!applyStartOptions(args, *start, o, pre, err)) return kExitUsage;
    o.model.start = start;
  }
  auto readOptions = logReadOptions(args, err);
  if (!readOptions) return kExitUsage;
  auto loaded = loadLog(args.positional()[0], *readOptions, err);
  if (!loaded) return kExitBadInput;
  auto data = std::make_shared<const IdData>(std::move(*loaded));
  if (!data->input() || !data->output()) {
    err << "flexarm: " << args.positional()[0] << ": the log has no input or no output channel\n";
    return kExitBadInput;
  }
  FitExperiment est{data, std::nullopt};
  if (!rangeOption(args, "range", *data, data->estimationRange, est.range, pre, err)) return kExitUsage;
  o.estimation = {est};
  ExperimentLogs read{{args.positional()[0], data}};
  auto experiment = [&](const std::string& text, const char* option, bool validation) {
    FitExperiment e;
    std::string file;
    const int rc = experimentOption(text, option, *readOptions, validation, read, e, file, pre, err);
    if (rc == kExitOk) {
      (validation ? o.validation : o.estimation).push_back(e);
      if (files) (validation ? files->validation : files->estimation).push_back(file);
    }
    return rc;
  };
  if (files) *files = FitFiles{{args.positional()[0]}, {}};
  for (const auto& text : args.values("log"))
    if (const int rc = experiment(text, "log", false); rc != kExitOk) return rc;
  FitExperiment val{data, std::nullopt};
  if (!rangeOption(args, "validation-range", *data, data->validationRange, val.range, pre, err))
    return kExitUsage;
  if (args.value("validation-range") || (val.range && args.values("validation-log").empty())) {
    o.validation.push_back(val);
    if (files) files->validation.push_back(args.positional()[0]);
  }
  for (const auto& text : args.values("validation-log"))
    if (const int rc = experiment(text, "validation-log", true); rc != kExitOk) return rc;
  if (!o.isValid(&why)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  result = fitModel(o, progressLine(err, "fit"));
  if (result.ok()) return kExitOk;
  if (result.badRequest) {
    err << pre << result.message << "\n";
    return kExitUsage;
  }
  if (result.badData) {
    err << "flexarm: " << args.positional()[0] << ": " << result.message << "\n";
    return kExitBadInput;
  }
  err << pre << "the fit failed: " << result.message << "\n";
  return kExitNumerical;
}

int runFit(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(fitFlagNames(), fitValuedOptionNames());
  if (!args.parse(argv)) {
    err << "flexarm fit: " << args.error() << "\n" << kFitHelp << fitOptionsHelp();
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << kFitHelp << fitOptionsHelp() << "\nEffects (--effect NAME[:V1,...]; values default as shown):\n"
        << effectHelpLines() << "\n" << logReadOptionsHelp();
    return kExitOk;
  }
  FitResult fit;
  FitFiles files;
  if (const int rc = runFitPipeline(args, "fit", fit, err, false, &files); rc != kExitOk) return rc;
  const auto& s = fit.summary;
  auto optJson = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  // Every experiment: its file, its range (s, first and last sample) and its fit % (5.2).
  auto experiments = [&](const std::vector<FitValidation>& list, const std::vector<std::string>& names,
                         bool validation) {
    nlohmann::json a = nlohmann::json::array();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const PreparedData& d = list[i].data;
      const SampleRange& range = validation ? d.validation : d.estimation;
      a.push_back({{"log", i < names.size() ? names[i] : std::string()},
                   {"range_s", {d.timeAt(range.begin), d.timeAt(range.end - 1)}},
                   {"samples", range.size()},
                   {"fit_percent", optJson(list[i].fitPercent)},
                   {"fit_percent_nrmse", optJson(list[i].fitPercentNrmse)}});
    }
    return a;
  };
  std::size_t samples = 0;  // of every estimation experiment
  for (const auto& e : fit.estimation) samples += e.data.estimation.size();
  nlohmann::json params = nlohmann::json::object(), stds = nlohmann::json::object();
  for (const auto& p : fit.parameters) {
    params[p.name] = p.value;
    stds[p.name] = p.std;
  }
  // The effects with their estimated values: {"name", "spec" (for --effect), "parameters":
  // {NAME: {"value", "std", "lower", "upper", "free", "unit"}}}.
  nlohmann::json effects = nlohmann::json::array();
  for (const auto& e : fit.effects) {
    nlohmann::json values = nlohmann::json::object();
    for (const auto& p : fit.parameters)
      if (p.effect == toString(e.kind))
        values[p.name] = {{"value", p.value}, {"std", p.std}, {"lower", p.lower},
                          {"upper", p.upper}, {"free", p.free}, {"unit", p.unit}};
    effects.push_back({{"name", toString(e.kind)}, {"spec", toString(e)}, {"parameters", values}});
  }
  nlohmann::json controller = nullptr;
  if (fit.controller)
    controller = {{"rate_hz", fit.controller->rateHz},
                  {"kp", fit.controller->kp},
                  {"kv", fit.controller->kv},
                  {"ti", fit.controller->ti},
                  {"torque_fit_percent", optJson(fit.controllerFitPercent)},
                  {"source", fit.controllerSource}};
  // Inverse dynamics (the method's result, or the start it gave): its parameter rows, its
  // filters and the torque it explains.
  nlohmann::json idimJ = nullptr;
  if (fit.idim) {
    const IdimResult& e = *fit.idim;
    nlohmann::json rows = nlohmann::json::object();
    for (const auto& p : e.parameters)
      rows[p.name] = {{"value", p.value}, {"std", p.std}, {"lower", p.lower}, {"upper", p.upper}, {"unit", p.unit}};
    idimJ = {{"parameters", rows},
             {"cutoff_hz", e.cutoffHz},
             {"decimation", e.decimation},
             {"samples", e.samples},
             {"relative_error_percent", e.relativeError},
             {"torque_fit_percent", e.torqueFitPercent},
             {"condition_number", e.conditionNumber},
             {"message", e.message}};
  }
  // The deflection check: the fit's own keys, of the deflection r phi_m - phi_a.
  nlohmann::json deflectionJ = nullptr;
  if (fit.deflection) {
    const DeflectionCheck& c = *fit.deflection;
    auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    deflectionJ = {{"fit_percent", optJson(c.fitPercent)},
                   {"fit_percent_validation", optJson(c.fitPercentValidation)},
                   {"fit_percent_nrmse", optJson(c.fitPercentNrmse)},
                   {"fit_percent_validation_nrmse", optJson(c.fitPercentValidationNrmse)},
                   {"rms_estimation", finite(c.rmsEstimation)},
                   {"rms_validation", finite(c.rmsValidation)},
                   {"measured_rms", finite(c.measuredRms)},
                   {"gear_ratio", c.gearRatio},
                   {"skew_s", c.skewSeconds},
                   {"skew_std_s", c.skewStd},
                   {"fit_percent_without_skew", optJson(c.fitPercentWithoutSkew)}};
  }
  if (args.flag("json")) {
    nlohmann::json j = {{"model", fit.modelName()},
                        {"idim", idimJ},
                        {"idim_start", fit.idimNote},
                        {"deflection", deflectionJ},
                        {"plausibility", fit.plausibility},
                        {"parameters", params},
                        {"std", stds},
                        {"effects", effects},
                        {"fit_percent", optJson(fit.fitEstimation)},
                        {"fit_percent_validation", optJson(fit.fitValidation())},
                        {"fit_percent_nrmse", optJson(fit.fitEstimationNrmse)},
                        {"fit_percent_validation_nrmse", optJson(fit.fitValidationNrmse())},
                        {"fit_percent_experiments", experiments(fit.estimation, files.estimation, false)},
                        {"fit_percent_validation_experiments", experiments(fit.validation, files.validation, true)},
                        {"warnings", fit.warnings},
                        {"loss", s.loss},
                        {"fpe", s.fpe},
                        {"aic", s.aic},
                        {"notches_rad_s", fit.notches},
                        {"peaks_rad_s", fit.peaks},
                        {"termination", toString(s.termination)},
                        {"message", s.message},
                        {"iterations", s.iterations},
                        {"seconds", fit.seconds},
                        {"sample_time_s", fit.data.sampleTime},
                        {"samples_estimation", samples},
                        {"samples_validation", fit.validation.empty() ? 0 : fit.validation.front().data.validation.size()},
                        {"data", fit.data.note()},
                        {"closed_loop", fit.data.closedLoop},
                        {"closed_loop_method", fit.method ? nlohmann::json(toString(*fit.method)) : nlohmann::json(nullptr)},
                        {"closed_loop_description", fit.methodDescription},
                        {"closed_loop_reason", fit.methodReason},
                        {"controller", controller},
                        {"reference_fit_percent", optJson(fit.referenceFitPercent)},
                        {"covariance", toString(fit.covarianceKind)}};
    out << j.dump(2) << "\n";
    return kExitOk;
  }
  out << fit.modelName() << ": " << toString(s.termination) << " after " << s.iterations
      << " iterations (" << s.message << ")\n";
  out << "data: " << samples << " estimation samples"
      << (fit.estimation.size() > 1 ? " in " + std::to_string(fit.estimation.size()) + " experiments" : std::string())
      << " at " << 1.0 / fit.data.sampleTime
      << " Hz (" << fit.data.note() << ")\n";
  if (fit.method) out << "closed-loop method: " << fit.methodDescription << " (" << fit.methodReason << ")\n";
  if (fit.controller) out << "controller: " << fit.controllerSource << "\n";
  if (!fit.idimNote.empty()) out << "start: " << fit.idimNote << "\n";
  if (fit.idim && fit.idimNote.empty())
    out << "inverse dynamics: " << fit.idim->message << ", the torque explained " << fit.idim->torqueFitPercent
        << " % (5.2), condition number " << fit.idim->conditionNumber << "\n";
  for (const auto& p : fit.parameters)
    out << "  " << p.name << " = " << p.value << " +- " << p.std << (p.free ? "" : " (fixed)")
        << (p.effect.empty() ? "" : " " + p.unit + " (" + p.effect + ")") << "\n";
  out << "loss " << s.loss << ", FPE " << s.fpe;
  out << "\n";
  // Both fit percentages, named (evaluation.h): the seed's (5.2) and MATLAB compare's NRMSE.
  auto both = [&](const std::optional<double>& seed52, const std::optional<double>& nrmse) {
    out << *seed52 << " % (5.2), " << nrmse.value_or(NAN) << " % NRMSE";
  };
  if (fit.fitEstimation) {
    out << "fit on the estimation data: ";
    both(fit.fitEstimation, fit.fitEstimationNrmse);
    out << "\n";
  }
  if (auto v = fit.fitValidation()) {
    out << "fit on the validation data: ";
    both(v, fit.fitValidationNrmse());
    out << "\n";
  }
  // Each experiment's fit % when there are several of a kind.
  auto listFits = [&](const char* what, const std::vector<FitValidation>& list,
                      const std::vector<std::string>& names, bool validation) {
    if (list.size() < 2) return;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const PreparedData& d = list[i].data;
      const SampleRange& range = validation ? d.validation : d.estimation;
      out << what << " " << i + 1 << " (" << (i < names.size() ? names[i] : std::string()) << ", "
          << d.timeAt(range.begin) << "-" << d.timeAt(range.end - 1) << " s): fit ";
      if (list[i].fitPercent) {
        both(list[i].fitPercent, list[i].fitPercentNrmse);
        out << "\n";
      }
      else out << "undefined\n";
    }
  };
  listFits("estimation", fit.estimation, files.estimation, false);
  listFits("validation", fit.validation, files.validation, true);
  if (fit.deflection) {
    const DeflectionCheck& c = *fit.deflection;
    out << "deflection r phi_m - phi_a (arm encoder, r = " << c.gearRatio << ", measured " << c.measuredRms * 1e3
        << " mrad RMS): predicted from the torque ";
    if (c.fitPercent) both(c.fitPercent, c.fitPercentNrmse);
    out << ", error " << c.rmsEstimation * 1e3 << " mrad RMS";
    if (c.fitPercentValidation) {
      out << "; validation ";
      both(c.fitPercentValidation, c.fitPercentValidationNrmse);
    }
    out << "\n  encoder skew " << c.skewSeconds * 1e3 << " +- " << c.skewStd * 1e3 << " ms (arm reading late); without it "
        << c.fitPercentWithoutSkew.value_or(NAN) << " % (5.2)\n";
  }
  for (const auto& w : fit.warnings) out << "warning: " << w << "\n";
  for (const auto& w : fit.plausibility) out << "implausible: " << w << "\n";
  auto list = [&](const char* what, const std::vector<double>& w) {
    out << what;
    for (double x : w) out << " " << x;
    out << (w.empty() ? " none\n" : " rad/s\n");
  };
  list("notches:", fit.notches);
  list("peaks:", fit.peaks);
  return kExitOk;
}

}  // namespace flexarm::cli
