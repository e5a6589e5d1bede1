// flexarm fit LOG --model SPEC [options] [--json]: the command line of the fit pipeline. The
// options are read into FitOptions, which core/ident checks (FitOptions::check) and runs
// (fitModel); the result is written by fitResultJson or fitResultText.
#include "app/cli/verb_fit.h"

#include <ostream>

#include "app/cli/log_args.h"
#include "app/cli/progress_line.h"
#include "core/ident/fit_experiments.h"
#include "core/ident/fit_spec.h"
#include "core/ident/fit_text.h"
#include "core/ident/order_scan.h"
#include "core/models/effects.h"

namespace flexarm::cli {

namespace {

// What --effect does; the effects themselves are listed from the registry (effectHelpLines).
const char* kEffectHelp =
    "physical models: switch on a named effect (repeatable; the list under Effects below) and fit its sizes "
    "with the model's parameters (nonlinear grey-box estimation, the plant simulated by Runge-Kutta from the "
    "measured torque, output error (5.7)); the values given (else the defaults listed) are the start. A "
    "smoothing speed (v_s), the ripple's order n and gravity's phase phi_0 are held unless --free names them; "
    "--fix NAME=V holds any of them. The smooth signs' speed v_s is 1 % of the data's RMS motor speed unless "
    "given";

std::string closedLoopHelp() {
  std::string text = "physical output-error fits of a log with a reference channel: the closed-loop method; ";
  for (auto c : {ClosedLoopChoice::Auto, ClosedLoopChoice::Direct, ClosedLoopChoice::TwoStage,
                 ClosedLoopChoice::Indirect})
    text += std::string(toString(c)) + ": " + describe(c) + (c == ClosedLoopChoice::Indirect ? "" : "; ");
  return text + ". The indirect fit's controller is the log's metadata (controller_rate_hz, controller_kp, "
                "controller_kv, controller_ti), else the cascade of Figure 5.1 identified from the log";
}

std::string methodHelp() {
  std::string text = "physical models: ";
  for (auto m : {FitMethod::PredictionError, FitMethod::Idim, FitMethod::IdimIv})
    text += std::string(toString(m)) + ": " + describe(m) + (m == FitMethod::IdimIv ? "" : "; ");
  return text + ". A prismatic axis (metadata axis: prismatic, or an output in m) reports M, N s/m and N";
}

OptionTable fitTable() {
  OptionTable t("flexarm fit LOG --model SPEC [options] [--json]",
                "Estimates a model by prediction error (the seed's chapters 4 and 5) and reports its parameters "
                "with standard deviations and 99 % intervals, loss, fit % (5.2) of the simulated output on the "
                "estimation and validation data, and the notch and peak frequencies.");
  t.add(fitOptionList(false));
  t.add(flagOption("scan", "instead of a fit, scan the orders (as arxstruc and selstruc): with --model arx:NA,NB,NK "
                           "every ARX structure na <= NA, nb <= NB, nk up to NK by its loss on the validation data "
                           "(else the estimation data), AIC and MDL, and the state-space orders' singular values "
                           "and MDL; with --model ss[:N] the state-space orders up to N alone"));
  t.group("Reading the log").add(logReadOptionList());
  t.note("Physical, black-box and non-parametric models give the motor velocity: a log whose output is the motor "
         "angle is differentiated first (central differences, Section 5.2).");
  t.note("Fit % is printed both ways, of the output simulated from zero initial state (input held between "
         "samples) from the start of the estimation range, and for validation from the first sample of the log "
         "holding the validation range: (5.2), the seed's 1 - sum e^2 / sum (y - mean y)^2 (JSON fit_percent, "
         "fit_percent_validation, and fit_percent of each experiment in fit_percent_experiments and "
         "fit_percent_validation_experiments with its log and range); NRMSE, MATLAB compare's 1 - ||e|| / "
         "||y - mean y|| (JSON the _nrmse twins); 96.4 % (5.2) is 81.0 % NRMSE.");
  t.note("On a log with an arm-side encoder (arm_angle_rad) a physical fit says how well it predicts the "
         "deflection r phi_m - phi_a from the torque alone (JSON deflection). Notches and peaks (JSON "
         "notches_rad_s, peaks_rad_s) are the local minima and maxima of |G(i w)| of the estimate, what a click "
         "on the Bode plot reads. The JSON is the fit schema " + std::string(kFitJsonFormat) + " version " +
         std::to_string(kFitJsonVersion) + ", as a session's report gives it.");
  t.block("Effects (--effect NAME[:V1,...]; values default as shown):\n" + effectHelpLines());
  return t;
}

// The range of a log in seconds as the command line names it: --range (or, for validation,
// --validation-range), else the range stored in the log's metadata. False after printing.
bool rangeOption(const ArgParser& args, const char* option, const IdData& data,
                 const std::optional<SampleRange>& stored, std::optional<SecondsRange>& out, const std::string& pre,
                 std::ostream& err) {
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

// A log named by --log or --validation-log: FILE or FILE@A:B (fit_experiments.h), appended to
// the options' experiments and its file to logs. The exit code; kExitOk when it was added.
int experimentOption(const std::string& text, const char* option, const LogReadOptions& readOptions,
                     bool validation, ExperimentLogs& read, FitOptions& o, FitLogNames& logs,
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
  (validation ? o.validation : o.estimation).push_back(*l.experiment);
  (validation ? logs.validation : logs.estimation).push_back(source->path);
  return kExitOk;
}

// Everything but the data: model, effects, parameter options, method and preparation. False
// after printing a usage error.
bool readChoices(const ArgParser& args, bool allowNonparametric, FitOptions& o, const std::string& pre,
                 std::ostream& err) {
  std::string why;
  auto spec = fitModelSpecFromText(args.text("model"), allowNonparametric, &why);
  if (!spec) {
    err << pre << "--model: " << why << "\n";
    return false;
  }
  o.model = *spec;
  o.decimation = static_cast<int>(args.integer("decimate"));
  o.maxIterations = static_cast<int>(args.integer("max-iterations"));
  o.randomStarts = static_cast<int>(args.integer("starts"));
  o.seed = static_cast<unsigned>(args.integer("seed"));
  o.removeMeans = !args.flag("keep-means");
  o.noiseModel = args.flag("noise-model") ? NoiseModel::Innovations : NoiseModel::OutputError;
  o.closedLoop = *closedLoopChoiceFromString(args.text("closed-loop"));
  o.method = *fitMethodFromString(args.text("method"));
  o.idim.cutoffHz = args.number("cutoff");
  o.idim.friction = args.text("friction") == "asymmetric" ? IdimFriction::Asymmetric : IdimFriction::Symmetric;
  o.idimStart = !args.flag("no-idim-start");
  o.idim.heldTorque = !args.flag("same-instant");
  o.reference = args.text("reference");
  o.model.armOutput = args.text("outputs") == "motor,arm";
  for (const auto& text : args.values("effect")) {
    auto e = parseEffect(text, &why);
    if (!e) {
      err << pre << "--effect " << text << ": " << why << "\n";
      return false;
    }
    FitEffect f = FitEffect::defaults(e->kind);
    f.effect = *e;
    f.scaleSmoothing = text.find(',') == std::string::npos;  // v_s given: kept
    o.model.effects.push_back(f);
  }
  for (const auto& [option, text] : args.sequence()) {
    const ParameterOption kinds[] = {ParameterOption::Free, ParameterOption::Fix, ParameterOption::Start,
                                     ParameterOption::Bound};
    const char* names[] = {"free", "fix", "start", "bound"};
    for (int k = 0; k < 4; ++k)
      if (option == names[k] && !applyParameterOption(o, kinds[k], text, &why)) {
        err << pre << "--" << option << " " << text << ": " << why << "\n";
        return false;
      }
  }
  return true;
}

}  // namespace

std::vector<Option> fitOptionList(bool nonparametric) {
  std::vector<Option> v = {
      required(textOption("model", "SPEC",
                          "the model: " + fitModelSpecGrammar(nonparametric) +
                              " (black-box orders of (4.8) with the delay NK; a physical structure from its "
                              "nominal values" +
                              (nonparametric ? "; SPA (4.28) with a Hann lag window of width M, ETFE (4.24) "
                                               "smoothed over W bins, each chosen from the data when not given"
                                             : "") +
                              ")")),
      textOption("effect", "NAME[:V1,...]", kEffectHelp, true),
      choiceOption("outputs", {"motor", "motor,arm"}, "motor",
                   "physical models on a log with an arm-side encoder: motor,arm fits the deflection r phi_m - "
                   "phi_a with the motor output (nonlinear estimator), each weighted by its noise level"),
      textOption("free", "P1,P2", "physical models: estimate only these parameters (model or effect parameters, "
                                  "e.g. J_m,k_g,beta)"),
      textOption("fix", "P[=V]", "physical models: hold P, a model or effect parameter (at V, else its start "
                                 "value). --free and --fix apply in order: the last one naming a parameter wins",
                 true),
      textOption("start", "P=V", "physical models: start P from V, names as the parameter table prints them; "
                                 "--start r=1 fits motor-side parameters, the default J_a, J_g, k_*, d_* referred "
                                 "to the motor side (times r^2) so the start keeps the default's dynamics",
                 true),
      textOption("bound", "P=LO:HI", "physical models: search P only in [LO, HI] (-inf and inf allowed); by default "
                                     "dampings d_* >= 0, inertias and stiffnesses > 0, and a parameter that ends on "
                                     "a bound is named in a warning (--bound d_g=-inf:inf allows the seed's negative "
                                     "dampings, Table 5.7)",
                 true),
      flagOption("noise-model", "physical models: the innovations form, K estimated (else K = 0)"),
      integerOption("starts", "N", 0, 1000, "0", "physical models: N random starts besides the nominal one, plus "
                                                 "two whose notches and peaks match the SPA estimate"),
      integerOption("seed", "N", 0, 4294967295L, "1", "random seed of the starts"),
      choiceOption("closed-loop", {"auto", "direct", "two-stage", "indirect"}, "auto", closedLoopHelp()),
      choiceOption("method", {"pem", "idim", "idim-iv"}, "pem", methodHelp()),
      numberOption("cutoff", "HZ", 0.0, 1e308, "0", "idim: cut-off of the position's Butterworth filter, run both "
                                                  "ways (0: a twentieth of the sample rate)"),
      choiceOption("friction", {"symmetric", "asymmetric"}, "symmetric",
                   "idim: asymmetric fits F_v+, F_v-, F_c+, F_c- instead of F_v, F_c"),
      flagOption("same-instant", "idim: pair the torque with the motion at the same sample, as the EMPS reference "
                                 "does (by default half a sample later: the torque is held over each sample)"),
      textOption("reference", "CHANNEL", "the channel holding the position reference (default: the log's "
                                         "reference, angle_ref_rad), e.g. qg of a .mat file"),
      flagOption("no-idim-start", "a prediction-error fit of a flexible model starts from the model as given; by "
                                  "default inverse dynamics below its first notch scales its inertias, "
                                  "stiffnesses, dampings and f_m when its inertia is off by more than a factor of "
                                  "two (the fit says so)"),
      integerOption("decimate", "N", 1, 1000000, "1", "decimate by N behind the anti-alias FIR before fitting (a "
                                                      "physical model holds each torque sample's mean over its "
                                                      "period, and a warning says what that does to its 99 % "
                                                      "intervals)"),
      textOption("range", "A:B", "estimation data from A to B seconds (default: the log's stored estimation range, "
                                 "else everything)"),
      textOption("log", "LOG2[@A:B]", "one more estimation experiment, LOG2 or its part from A to B s (without @A:B "
                                      "its stored estimation range, else all of it); the loss is summed over every "
                                      "experiment, each simulated from its own first sample with its own means",
                 true),
      textOption("validation-log", "LOG2[@A:B]", "a validation experiment (without @A:B its stored validation range, "
                                                 "else all of it), with the means of the estimation experiment on "
                                                 "the same file, else LOG's",
                 true),
      textOption("validation-range", "A:B", "validation data from A to B seconds of LOG"),
      integerOption("max-iterations", "N", 1, 100000, "100", "Gauss-Newton iterations"),
      flagOption("keep-means", "do not remove the estimation data's means (the seed does)"),
      flagOption("json", "print the result as JSON"),
  };
  return v;
}

namespace {

// The fit request the options name, its logs read and its experiments listed; the exit code
// (kExitOk when o is ready to run).
int readFitRequest(ArgParser& args, const std::string& verb, bool allowNonparametric, FitOptions& o,
                   FitLogNames& logs, std::ostream& err) {
  const std::string pre = "flexarm " + verb + ": ";
  if (args.positional().size() != 1) {
    err << pre << "expected exactly one LOG\n";
    return kExitUsage;
  }
  if (!readChoices(args, allowNonparametric, o, pre, err)) return kExitUsage;
  auto readOptions = logReadOptions(args, err);
  if (!readOptions) return kExitUsage;
  const std::string& path = args.positional()[0];
  auto loaded = loadLog(path, *readOptions, err);
  if (!loaded) return kExitBadInput;
  auto data = std::make_shared<const IdData>(std::move(*loaded));
  if (!data->input() || !data->output()) {
    err << "flexarm: " << path << ": the log has no input or no output channel\n";
    return kExitBadInput;
  }
  logs = FitLogNames{{path}, {}};
  FitExperiment est{data, std::nullopt};
  if (!rangeOption(args, "range", *data, data->estimationRange, est.range, pre, err)) return kExitUsage;
  o.estimation = {est};
  ExperimentLogs read{{path, data}};
  for (const auto& text : args.values("log"))
    if (const int rc = experimentOption(text, "log", *readOptions, false, read, o, logs, pre, err); rc != kExitOk)
      return rc;
  FitExperiment val{data, std::nullopt};
  if (!rangeOption(args, "validation-range", *data, data->validationRange, val.range, pre, err)) return kExitUsage;
  if (args.value("validation-range") || (val.range && args.values("validation-log").empty())) {
    o.validation.push_back(val);
    logs.validation.push_back(path);
  }
  for (const auto& text : args.values("validation-log"))
    if (const int rc = experimentOption(text, "validation-log", *readOptions, true, read, o, logs, pre, err);
        rc != kExitOk)
      return rc;
  if (const FitCheck c = o.check(); !c.ok()) {
    err << pre << c.message << "\n";
    return kExitUsage;
  }
  return kExitOk;
}

// --scan: the order scan of the fit's data instead of the fit.
int runScan(ArgParser& args, std::ostream& out, std::ostream& err) {
  FitOptions o;
  FitLogNames logs;
  if (const int rc = readFitRequest(args, "fit", false, o, logs, err); rc != kExitOk) return rc;
  std::string why;
  const auto scan = OrderScanOptions::fromSpec(o.model, &why);
  if (!scan) {
    err << "flexarm fit: --scan: " << why << "\n";
    return kExitUsage;
  }
  const OrderScan s = scanOrders(o, *scan, progressLine(err, "scan"));
  if (args.flag("json")) out << orderScanJson(s).dump(2) << "\n";
  else out << orderScanText(s);
  if (s.ok) return kExitOk;
  err << "flexarm fit: the order scan failed: " << s.message << "\n";
  return kExitNumerical;
}

}  // namespace

int runFitPipeline(ArgParser& args, const std::string& verb, FitResult& result, std::ostream& err,
                   bool allowNonparametric, FitLogNames* logNames) {
  const std::string pre = "flexarm " + verb + ": ";
  FitOptions o;
  FitLogNames logs;
  if (const int rc = readFitRequest(args, verb, allowNonparametric, o, logs, err); rc != kExitOk) return rc;
  if (logNames) *logNames = logs;
  const std::string& path = logs.estimation.front();
  result = fitModel(o, progressLine(err, "fit"));
  switch (result.status) {
    case FitStatus::Ok: return kExitOk;
    case FitStatus::BadRequest: err << pre << result.message << "\n"; return kExitUsage;
    case FitStatus::BadData: err << "flexarm: " << path << ": " << result.message << "\n"; return kExitBadInput;
    case FitStatus::Failed:
    case FitStatus::Cancelled: break;
  }
  err << pre << "the fit failed: " << result.message << "\n";
  return kExitNumerical;
}

int runFit(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(fitTable());
  if (auto rc = parseArguments(args, argv, "fit", out, err)) return *rc;
  if (args.flag("scan")) return runScan(args, out, err);
  FitResult fit;
  FitLogNames logs;
  if (const int rc = runFitPipeline(args, "fit", fit, err, false, &logs); rc != kExitOk) return rc;
  if (args.flag("json")) out << fitResultJson(fit, logs).dump(2) << "\n";
  else out << fitResultText(fit, logs);
  return kExitOk;
}

}  // namespace flexarm::cli
