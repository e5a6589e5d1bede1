// flexarm fit LOG --model SPEC [options] [--json]
#include "app/cli/verb_fit.h"

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "app/cli/log_args.h"
#include "core/ident/evaluation.h"
#include "core/ident/nonparametric.h"
#include "core/signal/preprocess.h"

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

// Physical models give the motor velocity: a log whose output is the motor angle gets the
// velocity by differentiation first, as the seed does (Section 5.2). Then decimates every
// channel when asked (anti-alias FIR of the preprocess module).
bool prepareData(IdData& data, int decimation, std::ostream& err, const std::string& verb,
                 bool velocityOutput) {
  if (velocityOutput && data.output() && data.output()->name == columns::kMotorAngle)
    data = addDerivative(data);
  if (decimation > 1) {
    DecimateOptions d;
    d.factor = decimation;
    std::string why;
    if (!d.isValid(&why)) {
      err << "flexarm " << verb << ": " << why << "\n";
      return false;
    }
    data = decimate(data, d);
  }
  return true;
}

}  // namespace

bool parseModelSpec(const std::string& text, ModelSpec& spec, std::string* why,
                    bool allowNonparametric) {
  spec = ModelSpec{};
  const std::string head = text.substr(0, text.find(':'));
  if (allowNonparametric && (head == "spa" || head == "etfe")) {
    spec.nonparametric = true;
    spec.spa = head == "spa";
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
    spec.physical = true;
    spec.physicalName = text;
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
  for (const char* n : {"model", "free", "fix", "decimate", "range", "validation-log",
                        "validation-range", "max-iterations", "starts", "seed", "closed-loop"})
    v.push_back(n);
  return v;
}

std::vector<std::string> fitFlagNames() { return {"json", "help", "noise-model", "keep-means"}; }

const char* fitOptionsHelp() {
  return "  --model SPEC          arx:NA,NB,NK | armax:NA,NB,NC,NK | oe:NB,NF,NK |\n"
         "                        bj:NB,NC,ND,NF,NK (orders of (4.8), delay NK), or a physical\n"
         "                        model two-mass|three-mass|four-mass|rigid (required)\n"
         "  --free P1,P2          physical models: estimate only these parameters\n"
         "  --fix P=V             physical models: hold P at V (repeatable)\n"
         "  --noise-model         physical models: innovations form, K estimated (else K = 0)\n"
         "  --starts N            physical models: N random starts besides the nominal one,\n"
         "                        plus two whose notches and peaks match the SPA estimate\n"
         "  --seed N              random seed for the starts (default 1)\n"
         "  --closed-loop M       physical models: auto|direct|two-stage|indirect. two-stage\n"
         "                        fits output error to the part of the input the reference\n"
         "                        explains (an FIR of the reference channel), consistent in\n"
         "                        closed loop, with a covariance that allows coloured errors.\n"
         "                        indirect fits the whole loop (the log's controller from its\n"
         "                        metadata controller_kp, controller_kv, controller_ti,\n"
         "                        controller_rate_hz) from the reference to the measured\n"
         "                        angle, from the log's first sample to the end of the\n"
         "                        estimation range, at the log's own rate (its loss is that of\n"
         "                        the loop's angle, in rad^2). auto (default, without\n"
         "                        --noise-model): indirect when the log carries its controller,\n"
         "                        is at the controller's rate, is not decimated and the\n"
         "                        estimation range starts at its first sample; else two-stage\n"
         "                        when the log has a reference; else direct\n"
         "  --decimate N          decimate by N with the anti-alias FIR before fitting\n"
         "  --range A:B           estimation data from A to B seconds (default: the log's\n"
         "                        stored estimation range, else everything)\n"
         "  --validation-log LOG2 validation data from another log (same reading options)\n"
         "  --validation-range A:B validation data from A to B seconds of LOG\n"
         "  --max-iterations N    Gauss-Newton iterations (default 100)\n"
         "  --keep-means          do not remove the estimation data's means (the seed does)\n"
         "  --json                print the result as JSON\n"
         "Fit % is (5.2) of the output simulated from zero initial state (input held constant\n"
         "between samples), from the start of the estimation range, and for validation from\n"
         "the first sample of the log holding the validation range.\n";
}

std::string FitOutcome::modelName() const {
  if (spec.physical)
    return spec.physicalName +
           (grey.K.size() ? std::string(" (innovations form)") : std::string(" (K = 0)"));
  return poly.model.name();
}

Eigen::VectorXd FitOutcome::simulate(const Eigen::VectorXd& u) const {
  if (spec.physical) return flexarm::simulate(*grey.model, u, sampleTime);
  return flexarm::simulate(poly.model, u);
}

std::optional<double> FitOutcome::validationFit() const {
  if (validation.size() < 2 || validation.end > static_cast<std::size_t>(yVal.size()))
    return std::nullopt;
  return fitPercent(yVal, simulate(uVal), static_cast<Eigen::Index>(validation.begin),
                    static_cast<Eigen::Index>(validation.end));
}

FrequencyResponse FitOutcome::response(const std::vector<double>& omega, double level) const {
  if (spec.nonparametric) {
    if (spec.spa) {
      SpaOptions so;
      so.windowWidth = spec.windowWidth;
      so.omega = omega;
      so.level = level;
      return spa(uEst, yEst, sampleTime, so).response;
    }
    EtfeOptions eo;
    eo.smoothingWidth = spec.windowWidth;
    eo.omega = omega;
    return etfe(uEst, yEst, sampleTime, eo).response;
  }
  if (!spec.physical) return frequencyResponse(poly.model, omega, level);
  // Bands from the physical parameters only (the K block does not change G).
  const int pf = static_cast<int>(grey.freeIndices.size());
  Eigen::MatrixXd cov;
  if (grey.covariance.rows() >= pf && pf > 0) cov = grey.covariance.topLeftCorner(pf, pf);
  return frequencyResponse(*grey.model, omega, cov, grey.freeIndices, level);
}

int prepareAndFit(ArgParser& args, const std::string& verb, FitOutcome& out, std::ostream& err,
                  bool allowNonparametric) {
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
  std::string why;
  if (!parseModelSpec(*modelText, out.spec, &why, allowNonparametric)) {
    err << pre << why << "\n";
    return kExitUsage;
  }
  std::unique_ptr<ParametricModel> physical;
  if (out.spec.physical) {
    physical = makePhysicalModel(out.spec.physicalName);
    if (!physical) {
      err << pre << "the physical model '" << out.spec.physicalName
          << "' is not available in this build yet (core/models does not provide it); use a "
             "black-box structure such as bj:5,5,5,5,1\n";
      return kExitUsage;
    }
  } else if (args.value("free") || args.value("fix") || args.flag("noise-model") ||
             args.value("starts") || args.value("closed-loop")) {
    err << pre << "--free, --fix, --noise-model, --starts and --closed-loop apply to physical "
                  "models only\n";
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
  if (maxIter < 0 || starts < 0 || decimation < 1) {
    err << pre << "--decimate must be at least 1, --max-iterations and --starts not negative\n";
    return kExitUsage;
  }
  std::optional<ClosedLoopMethod> askedMethod;  // nullopt: automatic
  if (auto m = args.value("closed-loop"); m && *m != "auto") {
    askedMethod = closedLoopMethodFromString(*m);
    if (!askedMethod) {
      err << pre << "--closed-loop expects auto, direct, two-stage or indirect, not '" << *m
          << "'\n";
      return kExitUsage;
    }
    if (*askedMethod != ClosedLoopMethod::Direct && args.flag("noise-model")) {
      err << pre << "--closed-loop " << toString(*askedMethod)
          << " fits output error; it excludes --noise-model\n";
      return kExitUsage;
    }
    if (*askedMethod == ClosedLoopMethod::Indirect && decimation > 1) {
      err << pre << "--closed-loop indirect runs the controller at its own rate; it excludes "
                    "--decimate\n";
      return kExitUsage;
    }
  }
  if (args.value("validation-log") && args.value("validation-range")) {
    err << pre << "give --validation-log or --validation-range, not both\n";
    return kExitUsage;
  }
  auto readOptions = logReadOptions(args, err);
  if (!readOptions) return kExitUsage;
  auto data = loadLog(args.positional()[0], *readOptions, err);
  if (!data) return kExitBadInput;
  if (!data->input() || !data->output()) {
    err << "flexarm: " << args.positional()[0] << ": the log has no input or no output channel\n";
    return kExitBadInput;
  }
  // The indirect method closes the logged controller around the model: it needs the measured
  // angle and the reference as logged, and the controller from the log's metadata. Asked for,
  // anything missing is an error naming it; under auto it is used whenever all of it is there
  // (a physical output-error fit at the log's own rate), as the consistent closed-loop choice.
  Eigen::VectorXd loopAngle, loopReference;
  ControllerOptions loopController;
  const bool loopWanted = askedMethod == ClosedLoopMethod::Indirect;
  const bool loopPossible = out.spec.physical && decimation == 1 && !args.flag("noise-model") &&
                            (loopWanted || !askedMethod);
  bool loopReady = false;
  if (loopPossible) {
    std::string loopWhy;  // printed only when the indirect fit was asked for
    auto refuse = [&loopWhy](const std::string& text) {
      loopWhy = text;
      return false;
    };
    auto readLoop = [&]() {
      const Channel* angle = data->channel(columns::kMotorAngle);
      const Channel* ref = data->withRole(ChannelRole::Reference);
      if (!angle || !ref)
        return refuse(std::string("--closed-loop indirect needs the ") + columns::kMotorAngle +
                      " and reference channels, and the log lacks " +
                      (angle ? "the reference" : columns::kMotorAngle));
      std::string bad;
      const auto controller = controllerFromMetadata(*data, &bad);
      if (!controller) return refuse("--closed-loop indirect needs the controller, and " + bad);
      loopController = *controller;
      if (std::abs(loopController.rateHz * data->sampleTime - 1.0) > 1e-6)
        return refuse("--closed-loop indirect needs the log at the controller's rate");
      loopAngle = Eigen::Map<const Eigen::VectorXd>(angle->values.data(),
                                                    static_cast<Eigen::Index>(angle->values.size()));
      loopReference = Eigen::Map<const Eigen::VectorXd>(ref->values.data(),
                                                        static_cast<Eigen::Index>(ref->values.size()));
      return true;
    };
    loopReady = readLoop();
    if (loopWanted && !loopReady) {
      err << "flexarm: " << args.positional()[0] << ": " << loopWhy << "\n";
      return kExitBadInput;
    }
  }
  if (!prepareData(*data, static_cast<int>(decimation), err, verb, out.spec.physical))
    return kExitUsage;
  SampleRange est{0, data->samples()};
  if (auto r = args.value("range")) {
    if (!parseTimeRange(*r, *data, est, &why)) {
      err << pre << why << "\n";
      return kExitUsage;
    }
  } else if (data->estimationRange && !data->estimationRange->empty()) {
    est = *data->estimationRange;
  }
  inputOutput(*data, out.uEst, out.yEst, est);
  out.sampleTime = data->sampleTime;
  out.closedLoop = data->isClosedLoop();
  Eigen::VectorXd rEst;
  if (const Channel* ref = data->withRole(ChannelRole::Reference)) {
    rEst = Eigen::Map<const Eigen::VectorXd>(ref->values.data() + est.begin, est.size());
    rEst.array() -= rEst.mean();
  }
  if (askedMethod == ClosedLoopMethod::TwoStage && rEst.size() == 0) {
    err << "flexarm: " << args.positional()[0]
        << ": --closed-loop two-stage needs a reference channel, and the log has none\n";
    return kExitBadInput;
  }
  const double uMean = args.flag("keep-means") ? 0.0 : out.uEst.mean();
  const double yMean = args.flag("keep-means") ? 0.0 : out.yEst.mean();
  out.uEst.array() -= uMean;
  out.yEst.array() -= yMean;
  if (auto vlog = args.value("validation-log")) {
    auto vdata = loadLog(*vlog, *readOptions, err);
    if (!vdata) return kExitBadInput;
    if (!prepareData(*vdata, static_cast<int>(decimation), err, verb, out.spec.physical))
      return kExitUsage;
    if (std::abs(vdata->sampleTime - data->sampleTime) > 1e-9 * data->sampleTime) {
      err << "flexarm: " << *vlog << ": its sample time differs from the estimation log's\n";
      return kExitBadInput;
    }
    try {
      inputOutput(*vdata, out.uVal, out.yVal);
      out.validation = vdata->validationRange ? *vdata->validationRange
                                              : SampleRange{0, vdata->samples()};
    } catch (const std::invalid_argument& e) {
      err << "flexarm: " << *vlog << ": " << e.what() << "\n";
      return kExitBadInput;
    }
  } else {
    SampleRange val;
    if (auto r = args.value("validation-range")) {
      if (!parseTimeRange(*r, *data, val, &why)) {
        err << pre << why << "\n";
        return kExitUsage;
      }
    } else if (data->validationRange) {
      val = *data->validationRange;
    }
    if (!val.empty()) {
      inputOutput(*data, out.uVal, out.yVal);
      out.validation = val;
    }
  }
  out.uVal.array() -= uMean;
  out.yVal.array() -= yMean;
  if (!out.spec.nonparametric && (out.uEst.array() - out.uEst.mean()).abs().maxCoeff() == 0.0) {
    err << pre << "the fit failed: the input is constant over the estimation range, so the "
                  "data say nothing about the system\n";
    return kExitNumerical;
  }

  if (out.spec.nonparametric) {
    if (out.spec.spa) {
      SpaOptions so;
      so.windowWidth = out.spec.windowWidth;
      so.omega = {M_PI / out.sampleTime};  // replaced by the caller's grid
      out.nonparametric = spa(out.uEst, out.yEst, out.sampleTime, so);
    } else {
      EtfeOptions eo;
      eo.smoothingWidth = out.spec.windowWidth;
      out.nonparametric = etfe(out.uEst, out.yEst, out.sampleTime, eo);
    }
    if (out.closedLoop) {
      out.nonparametric.closedLoopBias = true;
      out.nonparametric.warning = kClosedLoopBiasWarning;
    }
    if (out.nonparametric.termination == Termination::Failed) {
      err << pre << out.nonparametric.message << "\n";
      return kExitNumerical;
    }
    return kExitOk;
  }
  if (!out.spec.physical) {
    if (!out.spec.orders.fitsData(out.spec.structure, out.yEst.size(), &why)) {
      err << pre << why << "\n";
      return kExitUsage;
    }
    PolyEstimateOptions po;
    po.maxIterations = static_cast<int>(maxIter);
    try {
      out.poly = estimatePolynomial(out.uEst, out.yEst, out.spec.structure, out.spec.orders,
                                    out.sampleTime, po);
    } catch (const std::invalid_argument& e) {
      err << pre << e.what() << "\n";
      return kExitUsage;
    }
  } else {
    if (auto f = args.value("free")) {
      const auto names = splitComma(*f);
      for (const auto& p : physical->parameters()) physical->setFree(p.name, false);
      for (const auto& n : names) {
        if (physical->indexOf(n) < 0) {
          err << pre << "--free: the " << out.spec.physicalName << " model has no parameter '"
              << n << "'\n";
          return kExitUsage;
        }
        physical->setFree(n, true);
      }
    }
    for (const auto& fx : args.values("fix")) {
      const auto eq = fx.find('=');
      double v = 0.0;
      try {
        if (eq == std::string::npos) throw std::invalid_argument(fx);
        std::size_t used = 0;
        v = std::stod(fx.substr(eq + 1), &used);
        if (used != fx.size() - eq - 1) throw std::invalid_argument(fx);
      } catch (const std::exception&) {
        err << pre << "--fix expects NAME=VALUE, not '" << fx << "'\n";
        return kExitUsage;
      }
      const std::string name = fx.substr(0, eq);
      if (physical->indexOf(name) < 0) {
        err << pre << "--fix: the " << out.spec.physicalName << " model has no parameter '"
            << name << "'\n";
        return kExitUsage;
      }
      try {
        physical->setParameter(name, v);
      } catch (const std::invalid_argument& e) {
        err << pre << "--fix " << e.what() << "\n";
        return kExitUsage;
      }
      physical->setFree(name, false);
    }
    PemOptions po;
    po.maxIterations = static_cast<int>(maxIter);
    po.noiseModel = args.flag("noise-model") ? NoiseModel::Innovations : NoiseModel::OutputError;
    po.randomStarts = static_cast<int>(starts);
    po.seed = static_cast<unsigned>(seed);
    if (starts > 0) {
      // Two more starts whose notches and peaks match those of the SPA estimate.
      const NonparametricEstimate sp = spa(out.uEst, out.yEst, out.sampleTime);
      if (sp.termination == Termination::Converged) {
        const auto np = notchesAndPeaks(sp.response, 3.0);
        po.targetNotches = np.notches;
        po.targetPeaks = np.peaks;
        if (!np.notches.empty() || !np.peaks.empty()) po.notchPeakStarts = 2;
      }
    }
    ClosedLoopPemOptions co;
    co.pem = po;
    co.method = askedMethod.value_or(loopReady && est.begin == 0 ? ClosedLoopMethod::Indirect
                                     : rEst.size() && !args.flag("noise-model")
                                         ? ClosedLoopMethod::TwoStage
                                         : ClosedLoopMethod::Direct);
    co.controller = loopController;
    try {
      // The indirect loop starts at rest at the log's first sample: it runs from there to the
      // end of the estimation range.
      const Eigen::Index loopEnd = static_cast<Eigen::Index>(est.end);
      ClosedLoopPemResult cl =
          co.method == ClosedLoopMethod::Indirect
              ? pemClosedLoop(*physical, {}, loopAngle.head(loopEnd), loopReference.head(loopEnd),
                              out.sampleTime, co)
              : pemClosedLoop(*physical, out.uEst, out.yEst, rEst, out.sampleTime, co);
      out.closedLoopMethod = cl.method;
      if (cl.method == ClosedLoopMethod::TwoStage && cl.projection.ok)
        out.referenceFit = cl.projection.fitPercent;
      out.grey = std::move(cl.pem);
    } catch (const std::invalid_argument& e) {
      err << pre << e.what() << "\n";
      return kExitUsage;
    }
  }
  if (out.summary().termination == Termination::Failed) {
    err << pre << "the fit failed: " << out.summary().message << "\n";
    return kExitNumerical;
  }
  return kExitOk;
}

int runFit(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(fitFlagNames(), fitValuedOptionNames());
  if (!args.parse(argv)) {
    err << "flexarm fit: " << args.error() << "\n" << kFitHelp << fitOptionsHelp();
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << kFitHelp << fitOptionsHelp() << "\n" << logReadOptionsHelp();
    return kExitOk;
  }
  FitOutcome fit;
  if (const int rc = prepareAndFit(args, "fit", fit, err); rc != kExitOk) return rc;
  const auto& s = fit.summary();
  const double fitEstRaw = fitPercent(fit.yEst, fit.simulate(fit.uEst));
  const auto fitValRaw = fit.validationFit();
  std::optional<double> fitEst, fitVal;
  std::vector<std::string> warnings;
  if (std::isfinite(fitEstRaw) && (!fitValRaw || std::isfinite(*fitValRaw))) {
    fitEst = fitEstRaw;
    fitVal = fitValRaw;
  } else {
    warnings.push_back("the model's G is unstable, so its simulated output diverges and the "
                       "fit % is undefined; it can still predict one step ahead");
  }
  if (fit.closedLoop && fit.closedLoopMethod == ClosedLoopMethod::Direct)
    warnings.push_back("the log was recorded in closed loop: only models with a flexible, "
                       "independently parameterized noise model (BJ) are free of bias (4.43)");
  auto optJson = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  const double T = fit.sampleTime;
  const double wmin = 2.0 * M_PI / (static_cast<double>(fit.yEst.size()) * T);
  const auto fr = fit.response(logGrid(wmin, M_PI / T, 2000), 0.99);
  const auto np = notchesAndPeaks(fr, 1.0);

  nlohmann::json params = nlohmann::json::object(), stds = nlohmann::json::object();
  if (!fit.spec.physical) {
    const auto names = fit.poly.model.parameterNames();
    const Eigen::VectorXd th = fit.poly.model.parameterVector();
    const Eigen::VectorXd sd = fit.poly.model.standardDeviations();
    for (std::size_t i = 0; i < names.size(); ++i) {
      params[names[i]] = th[i];
      stds[names[i]] = sd.size() ? nlohmann::json(sd[i]) : nlohmann::json(nullptr);
    }
  } else {
    for (const auto& p : fit.grey.parameters) {
      params[p.name] = p.value;
      stds[p.name] = p.std;
    }
  }
  if (args.flag("json")) {
    nlohmann::json j = {{"model", fit.modelName()},
                        {"parameters", params},
                        {"std", stds},
                        {"fit_percent", optJson(fitEst)},
                        {"fit_percent_validation", optJson(fitVal)},
                        {"warnings", warnings},
                        {"loss", s.loss},
                        {"fpe", s.fpe},
                        {"aic", s.aic},
                        {"notches_rad_s", np.notches},
                        {"peaks_rad_s", np.peaks},
                        {"termination", toString(s.termination)},
                        {"message", s.message},
                        {"iterations", s.iterations},
                        {"seconds", s.seconds},
                        {"sample_time_s", T},
                        {"samples_estimation", fit.yEst.size()},
                        {"samples_validation", fit.validation.size()},
                        {"closed_loop", fit.closedLoop},
                        {"closed_loop_method", fit.closedLoopMethod
                                                   ? nlohmann::json(toString(*fit.closedLoopMethod))
                                                   : nlohmann::json(nullptr)},
                        {"reference_fit_percent", optJson(fit.referenceFit)},
                        {"covariance", fit.spec.physical
                                           ? nlohmann::json(toString(fit.grey.covarianceKind))
                                           : nlohmann::json("white")}};
    out << j.dump(2) << "\n";
    return kExitOk;
  }
  out << fit.modelName() << ": " << toString(s.termination) << " after " << s.iterations
      << " iterations (" << s.message << ")\n";
  if (fit.closedLoopMethod)
    out << "closed-loop method: " << toString(*fit.closedLoopMethod) << "\n";
  for (auto it = params.begin(); it != params.end(); ++it)
    out << "  " << it.key() << " = " << it.value().get<double>() << " +- "
        << (stds[it.key()].is_null() ? std::string("?") : stds[it.key()].dump()) << "\n";
  out << "loss " << s.loss << ", FPE " << s.fpe;
  if (fitEst) out << ", fit " << *fitEst << " %";
  if (fitVal) out << ", validation fit " << *fitVal << " %";
  out << "\n";
  for (const auto& w : warnings) out << "warning: " << w << "\n";
  auto list = [&](const char* what, const std::vector<double>& w) {
    out << what;
    for (double x : w) out << " " << x;
    out << (w.empty() ? " none\n" : " rad/s\n");
  };
  list("notches:", np.notches);
  list("peaks:", np.peaks);
  return kExitOk;
}

}  // namespace flexarm::cli
