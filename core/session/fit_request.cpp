#include "core/session/fit_request.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/ident/evaluation.h"
#include "core/ident/nonparametric.h"
#include "core/ident/residuals.h"
#include "core/session/model_json.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"

namespace flexarm {

using nlohmann::json;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kLevel = 0.99;

std::shared_ptr<PhysicalModel> clonePhysicalModel(const ParametricModel& m) {
  std::unique_ptr<ParametricModel> c = m.clone();
  return std::shared_ptr<PhysicalModel>(static_cast<PhysicalModel*>(c.release()));
}

bool readInt(const json& j, const char* key, int lo, int hi, int& out, std::string* why) {
  if (!j.contains(key)) return true;  // the default
  if (!j[key].is_number_integer() || j[key].get<long long>() < lo || j[key].get<long long>() > hi) {
    if (why) *why = std::string(key) + " must be a whole number from " + std::to_string(lo) +
                    " to " + std::to_string(hi);
    return false;
  }
  out = j[key].get<int>();
  return true;
}

}  // namespace

json secondsRangeToJson(const std::optional<SecondsRange>& r) {
  return r ? json::array({r->start, r->end}) : json(nullptr);
}

bool readSecondsRange(const json& j, const char* key, std::optional<SecondsRange>& out, std::string* why) {
  out.reset();
  if (!j.contains(key) || j[key].is_null()) return true;
  const json& r = j[key];
  if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number() ||
      !(r[0].get<double>() < r[1].get<double>())) {
    if (why) *why = std::string(key) + " must be [start, end] in seconds with start < end";
    return false;
  }
  out = SecondsRange{r[0].get<double>(), r[1].get<double>()};
  return true;
}


bool FitRequest::isValid(std::string* why) const {
  auto fail = [why](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (decimation < 1) return fail("the decimation factor must be at least 1");
  if (randomStarts < 0) return fail("the number of random starts cannot be negative");
  if (maxIterations < 1) return fail("at least one iteration is needed");
  if (estimation && !(estimation->start < estimation->end))
    return fail("the estimation range must have start < end");
  if (validation && !(validation->start < validation->end))
    return fail("the validation range must have start < end");
  if (physical()) {
    bool anyFree = false;
    for (const auto& p : start->parameters()) anyFree = anyFree || p.free;
    if (!anyFree) return fail("a physical fit needs at least one free parameter");
    return true;
  }
  std::string reason;
  if (!orders.isValid(&reason)) return fail("orders: " + reason);
  return true;
}

json fitRequestToJson(const FitRequest& r) {
  json j = {{"name", r.name},
            {"decimation", r.decimation},
            {"max_iterations", r.maxIterations},
            {"estimation_s", secondsRangeToJson(r.estimation)},
            {"validation_s", secondsRangeToJson(r.validation)}};
  if (r.physical()) {
    j["kind"] = "physical";
    j["start"] = modelToJson(r.name, *r.start, {});
    j["noise_model"] = toString(r.noiseModel);
    j["closed_loop"] = toString(r.closedLoop);
    j["random_starts"] = r.randomStarts;
    j["seed"] = r.seed;
  } else {
    j["kind"] = "black-box";
    j["structure"] = toString(r.structure);
    j["orders"] = {{"na", r.orders.na}, {"nb", r.orders.nb}, {"nc", r.orders.nc},
                   {"nd", r.orders.nd}, {"nf", r.orders.nf}, {"nk", r.orders.nk}};
  }
  return j;
}

std::optional<FitRequest> fitRequestFromJson(const json& j, std::string* why) {
  auto fail = [why](const std::string& w) -> std::optional<FitRequest> {
    if (why) *why = w;
    return std::nullopt;
  };
  if (!j.is_object()) return fail("a fit must be an object");
  FitRequest r;
  if (!j.contains("name") || !j["name"].is_string()) return fail("a fit needs a name");
  r.name = j["name"].get<std::string>();
  const std::string where = "fit '" + r.name + "': ";
  std::string reason;
  if (!j.contains("kind") || !j["kind"].is_string()) return fail(where + "kind must be \"physical\" or \"black-box\"");
  const std::string kind = j["kind"].get<std::string>();
  if (!readInt(j, "decimation", 1, 1000, r.decimation, &reason) ||
      !readInt(j, "max_iterations", 1, 100000, r.maxIterations, &reason) ||
      !readSecondsRange(j, "estimation_s", r.estimation, &reason) ||
      !readSecondsRange(j, "validation_s", r.validation, &reason))
    return fail(where + reason);
  if (kind == "physical") {
    if (!j.contains("start")) return fail(where + "a physical fit needs its start model");
    auto spec = modelFromJson(j["start"], &reason);
    if (!spec) return fail(where + reason);
    r.start = spec->model;
    if (j.contains("noise_model")) {
      auto m = j["noise_model"].is_string() ? noiseModelFromString(j["noise_model"].get<std::string>())
                                            : std::nullopt;
      if (!m) return fail(where + "noise_model must be \"" + toString(NoiseModel::OutputError) +
                          "\" or \"" + toString(NoiseModel::Innovations) + "\"");
      r.noiseModel = *m;
    }
    // Sessions written before fits stored their closed-loop method ran direct fits.
    r.closedLoop = ClosedLoopMethod::Direct;
    if (j.contains("closed_loop")) {
      auto m = j["closed_loop"].is_string() ? closedLoopMethodFromString(j["closed_loop"].get<std::string>())
                                            : std::nullopt;
      if (!m)
        return fail(where + "closed_loop must be \"" + toString(ClosedLoopMethod::TwoStage) +
                    "\", \"" + toString(ClosedLoopMethod::Direct) + "\" or \"" +
                    toString(ClosedLoopMethod::Indirect) + "\"");
      r.closedLoop = *m;
    }
    int seed = 1;
    if (!readInt(j, "random_starts", 0, 1000, r.randomStarts, &reason) ||
        !readInt(j, "seed", 0, 1 << 30, seed, &reason))
      return fail(where + reason);
    r.seed = static_cast<unsigned>(seed);
  } else if (kind == "black-box") {
    auto s = j.contains("structure") && j["structure"].is_string()
                 ? polyStructureFromString(j["structure"].get<std::string>())
                 : std::nullopt;
    if (!s) return fail(where + "structure must be arx, armax, oe or bj");
    r.structure = *s;
    if (!j.contains("orders") || !j["orders"].is_object()) return fail(where + "a black-box fit needs orders");
    const json& o = j["orders"];
    int* fields[] = {&r.orders.na, &r.orders.nb, &r.orders.nc, &r.orders.nd, &r.orders.nf, &r.orders.nk};
    const char* names[] = {"na", "nb", "nc", "nd", "nf", "nk"};
    for (int i = 0; i < 6; ++i)
      if (!readInt(o, names[i], 0, 200, *fields[i], &reason)) return fail(where + reason);
  } else {
    return fail(where + "kind must be \"physical\" or \"black-box\", not \"" + kind + "\"");
  }
  if (!r.isValid(&reason)) return fail(where + reason);
  return r;
}

json polynomialEstimateToJson(const PolynomialModel& m) {
  json theta = json::array(), cov = json::array();
  const Eigen::VectorXd p = m.parameterVector();
  for (Eigen::Index i = 0; i < p.size(); ++i) theta.push_back(p(i));
  for (Eigen::Index i = 0; i < m.covariance.rows(); ++i) {
    json row = json::array();
    for (Eigen::Index k = 0; k < m.covariance.cols(); ++k) row.push_back(m.covariance(i, k));
    cov.push_back(row);
  }
  return {{"parameters", theta},
          {"sample_time", m.sampleTime},
          {"noise_variance", m.noiseVariance},
          {"covariance", m.covariance.size() ? cov : json(nullptr)}};
}

std::optional<PolynomialModel> polynomialEstimateFromJson(const json& j, const FitRequest& request,
                                                          std::string* why) {
  auto fail = [&](const std::string& text) -> std::optional<PolynomialModel> {
    if (why) *why = "the estimate of fit '" + request.name + "': " + text;
    return std::nullopt;
  };
  if (request.physical()) return fail("a physical fit keeps its estimate in the model list");
  if (!j.is_object() || !j.contains("parameters") || !j["parameters"].is_array())
    return fail("needs a list of parameters");
  const int n = request.orders.parameters();
  if (static_cast<int>(j["parameters"].size()) != n)
    return fail("holds " + std::to_string(j["parameters"].size()) + " parameters, the orders give " +
                std::to_string(n));
  if (!j.contains("sample_time") || !j["sample_time"].is_number() || !(j["sample_time"].get<double>() > 0.0))
    return fail("sample_time must be a positive number");
  PolynomialModel m = PolynomialModel::zero(request.structure, request.orders, j["sample_time"].get<double>());
  Eigen::VectorXd theta(n);
  for (int i = 0; i < n; ++i) {
    const json& v = j["parameters"][static_cast<std::size_t>(i)];
    if (!v.is_number() || !std::isfinite(v.get<double>())) return fail("every parameter must be a finite number");
    theta(i) = v.get<double>();
  }
  m.setParameterVector(theta);
  if (j.contains("noise_variance")) {
    if (!j["noise_variance"].is_number()) return fail("noise_variance must be a number");
    m.noiseVariance = j["noise_variance"].get<double>();
  }
  if (j.contains("covariance") && !j["covariance"].is_null()) {
    const json& c = j["covariance"];
    if (!c.is_array() || static_cast<int>(c.size()) != n) return fail("covariance must be " + std::to_string(n) + " rows");
    m.covariance.resize(n, n);
    for (int i = 0; i < n; ++i) {
      const json& row = c[static_cast<std::size_t>(i)];
      if (!row.is_array() || static_cast<int>(row.size()) != n) return fail("covariance must be square");
      for (int k = 0; k < n; ++k) {
        if (!row[static_cast<std::size_t>(k)].is_number()) return fail("covariance entries must be numbers");
        m.covariance(i, k) = row[static_cast<std::size_t>(k)].get<double>();
      }
    }
  }
  return m;
}

std::optional<FitSignals> fitSignals(const IdData& source, int decimation, bool velocityOutput,
                                     const std::optional<SecondsRange>& estimation,
                                     const std::optional<SecondsRange>& validation,
                                     std::string* why) {
  if (!source.input() || !source.output()) {
    if (why) *why = "the log needs an input and an output channel";
    return std::nullopt;
  }
  IdData data = source;
  std::vector<std::string> notes;
  if (velocityOutput && data.output()->name == columns::kMotorAngle) {
    data = addDerivative(data);
    notes.push_back("motor velocity from the angle (central differences)");
  }
  if (decimation > 1) {
    DecimateOptions d;
    d.factor = decimation;
    if (!d.isValid(why)) return std::nullopt;
    data = decimate(data, d);
    notes.push_back("decimated by " + std::to_string(decimation));
  }
  FitSignals s;
  s.sampleTime = data.sampleTime;
  s.startTime = data.startTime;
  s.closedLoop = data.isClosedLoop();
  inputOutput(data, s.u, s.y);
  if (const Channel* ref = data.withRole(ChannelRole::Reference))
    s.r = Eigen::Map<const Eigen::VectorXd>(ref->values.data(), static_cast<Eigen::Index>(ref->values.size()));
  s.estimation = estimation ? data.rangeForTimes(estimation->start, estimation->end) : SampleRange{};
  if (!estimation) s.estimation = {0, data.samples()};
  if (validation) s.validation = data.rangeForTimes(validation->start, validation->end);
  const auto n = static_cast<Eigen::Index>(s.estimation.size());
  if (n < 20) {
    if (why) *why = "the estimation range holds only " + std::to_string(n) + " samples";
    return std::nullopt;
  }
  const auto b = static_cast<Eigen::Index>(s.estimation.begin);
  s.u.array() -= s.u.segment(b, n).mean();
  s.y.array() -= s.y.segment(b, n).mean();
  if (s.r.size()) s.r.array() -= s.r.segment(b, n).mean();
  notes.push_back("estimation means removed");
  for (std::size_t i = 0; i < notes.size(); ++i) s.note += (i ? ", " : "") + notes[i];
  return s;
}

FitRun runFitRequest(const FitRequest& request, const IdData& data, const ProgressCallback& progress) {
  std::string why;
  if (!request.isValid(&why)) throw std::invalid_argument(why);
  const auto t0 = std::chrono::steady_clock::now();
  FitRun run;
  auto finish = [&](Termination t, std::string message) {
    run.termination = t;
    run.message = std::move(message);
    run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return run;
  };
  const bool velocity = !request.physical() || request.start->options().output == ModelOutput::MotorVelocity;
  auto sig = fitSignals(data, request.decimation, velocity, request.estimation, request.validation, &why);
  if (!sig) return finish(Termination::Failed, why);
  run.data = std::move(*sig);
  const FitSignals& s = run.data;
  const auto b = static_cast<Eigen::Index>(s.estimation.begin);
  const auto n = static_cast<Eigen::Index>(s.estimation.size());
  const Eigen::VectorXd u = s.u.segment(b, n), y = s.y.segment(b, n);
  const double T = s.sampleTime;
  try {
    if (request.physical()) {
      PemOptions po;
      po.maxIterations = request.maxIterations;
      po.noiseModel = request.noiseModel;
      po.randomStarts = request.randomStarts;
      po.seed = request.seed;
      po.level = kLevel;
      if (po.randomStarts > 0) {  // two more starts matching the SPA notches and peaks
        const auto np = notchesAndPeaks(spa(u, y, T).response, 3.0);
        po.targetNotches = np.notches;
        po.targetPeaks = np.peaks;
        if (!np.notches.empty() || !np.peaks.empty()) po.notchPeakStarts = 2;
      }
      ClosedLoopPemOptions co;
      co.pem = po;
      ClosedLoopPemResult cl;
      if (request.closedLoop == ClosedLoopMethod::Indirect) {
        // The log's controller closed around the model, fitted from the reference to the
        // measured angle as logged: the loop starts at rest at the first sample and runs to
        // the end of the estimation range, at the controller's own rate.
        if (po.noiseModel != NoiseModel::OutputError)
          return finish(Termination::Failed, "the indirect closed-loop fit is output error (K = 0)");
        const Channel* angle = data.channel(columns::kMotorAngle);
        const Channel* ref = data.withRole(ChannelRole::Reference);
        if (!angle || !ref)
          return finish(Termination::Failed, std::string("the indirect closed-loop fit needs the ") +
                                                 columns::kMotorAngle + " and reference channels");
        const auto controller = controllerFromMetadata(data, &why);
        if (!controller) return finish(Termination::Failed, "the indirect closed-loop fit: " + why);
        if (request.decimation > 1 || std::abs(controller->rateHz * data.sampleTime - 1.0) > 1e-6)
          return finish(Termination::Failed,
                        "the indirect closed-loop fit runs at the controller's rate (" +
                            std::to_string(static_cast<int>(controller->rateHz)) +
                            " Hz); fit the log undecimated");
        co.method = ClosedLoopMethod::Indirect;
        co.controller = *controller;
        const auto end = static_cast<Eigen::Index>(s.estimation.end);
        const Eigen::Map<const Eigen::VectorXd> a(angle->values.data(), end), rr(ref->values.data(), end);
        cl = pemClosedLoop(*request.start, {}, a, rr, T, co, progress);
        run.data.note += ", indirect closed-loop fit: the log's controller around the model, "
                         "from the reference to the motor angle";
      } else {
        co.method = request.closedLoop == ClosedLoopMethod::TwoStage && s.r.size() == s.u.size() &&
                            po.noiseModel == NoiseModel::OutputError
                        ? ClosedLoopMethod::TwoStage
                        : ClosedLoopMethod::Direct;
        const Eigen::VectorXd r0 =
            co.method == ClosedLoopMethod::TwoStage ? Eigen::VectorXd(s.r.segment(b, n)) : Eigen::VectorXd();
        cl = pemClosedLoop(*request.start, u, y, r0, T, co, progress);
      }
      if (cl.method == ClosedLoopMethod::TwoStage && cl.projection.ok) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      ", two-stage closed-loop fit: the reference explains %.1f %% of the input, "
                      "intervals allow coloured errors",
                      cl.projection.fitPercent);
        run.data.note += buf;
      } else if (s.closedLoop && cl.method == ClosedLoopMethod::Direct) {
        run.data.note += ", direct fit of closed-loop data";
      }
      PemResult r = std::move(cl.pem);
      run.summary = r.summary;
      for (const auto& p : r.parameters)
        run.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, p.free});
      run.physical = clonePhysicalModel(*r.model);
      run.K = r.K;
      const auto pf = static_cast<Eigen::Index>(r.freeIndices.size());
      if (pf > 0 && r.covariance.rows() >= pf) {
        run.covariance = r.covariance.topLeftCorner(pf, pf);
        run.freeIndices = r.freeIndices;
      }
    } else {
      PolyEstimateOptions po;
      po.maxIterations = request.maxIterations;
      PolyEstimate r = estimatePolynomial(u, y, request.structure, request.orders, T, po, progress);
      run.summary = r.summary;
      const auto names = r.model.parameterNames();
      const Eigen::VectorXd th = r.model.parameterVector(), sd = r.model.standardDeviations();
      const double z = twoSidedNormalQuantile(kLevel);
      for (std::size_t i = 0; i < names.size(); ++i) {
        const auto k = static_cast<Eigen::Index>(i);
        const double sk = sd.size() > k ? sd[k] : 0.0;
        run.parameters.push_back({names[i], "", th[k], sk, th[k] - z * sk, th[k] + z * sk, true});
      }
      run.polynomial = std::make_shared<PolynomialModel>(r.model);
    }
  } catch (const std::invalid_argument& e) {
    return finish(Termination::Failed, std::string("the fit was refused: ") + e.what());
  }
  if (!run.summary.ok()) return finish(run.summary.termination, run.summary.message);
  auto sim = [&](const Eigen::VectorXd& input) {
    return run.physical ? simulate(*run.physical, input, T) : simulate(*run.polynomial, input);
  };
  run.fitEstimation = fitPercent(y, sim(u));
  run.simulated = sim(s.u);  // from the log's first sample: no start-up transient in validation
  if (!s.validation.empty())
    run.fitValidation = fitPercent(s.y, run.simulated, static_cast<Eigen::Index>(s.validation.begin),
                                   static_cast<Eigen::Index>(s.validation.end));
  const std::vector<double> w = logGrid(2.0 * kPi / (static_cast<double>(n) * T), kPi / T, 2000);
  if (run.physical) {
    run.response = frequencyResponse(*run.physical, w, run.covariance, run.freeIndices, kLevel);
  } else {
    std::vector<double> below;  // a discrete response stops short of the Nyquist frequency
    for (double x : w)
      if (x < kPi / T) below.push_back(x);
    run.response = frequencyResponse(*run.polynomial, below, kLevel);
  }
  const auto np = notchesAndPeaks(run.response, 1.0);
  run.notches = np.notches;
  run.peaks = np.peaks;
  return finish(run.summary.termination, run.summary.message);
}

namespace {

std::string joinedFrequencies(const std::vector<double>& w) {
  std::string text;
  for (double x : w) text += (text.empty() ? "" : ", ") + formatFixed(x, 1);
  return text.empty() ? "none" : text + " rad/s";
}

// Bode magnitude and phase of a response with its 99 % band drawn as dashed bounds.
std::vector<ReportPlot> bodeWithBand(const FrequencyResponse& r, const std::string& name,
                                     const std::string& what) {
  const double deg = 180.0 / kPi;
  ReportPlot mag{"Bode magnitude, " + what, "frequency (rad/s)", "|G|", true, true, {}};
  ReportPlot ph{"Bode phase, " + what, "frequency (rad/s)", "phase (deg)", true, false, {}};
  mag.series.push_back({name, r.omega, r.magnitude, false});
  std::vector<double> phase;
  for (double p : r.phase) phase.push_back(p * deg);
  ph.series.push_back({name, r.omega, phase, false});
  if (r.hasBands()) {
    const std::string band = formatFixed(100.0 * r.level, 0) + " % bound";
    // A lower bound at or below zero has no place on a log axis: the curve has a gap there.
    std::vector<double> lower;
    for (double v : r.magnitudeLower) lower.push_back(v > 0.0 ? v : std::numeric_limits<double>::quiet_NaN());
    mag.series.push_back({"upper " + band, r.omega, r.magnitudeUpper, true, 1});
    mag.series.push_back({"lower " + band, r.omega, lower, true, 1});
    std::vector<double> lo, hi;
    for (std::size_t i = 0; i < r.phaseLower.size(); ++i) {
      lo.push_back(r.phaseLower[i] * deg);
      hi.push_back(r.phaseUpper[i] * deg);
    }
    ph.series.push_back({"upper " + band, r.omega, hi, true, 1});
    ph.series.push_back({"lower " + band, r.omega, lo, true, 1});
  }
  mag.legendBottomLeft = ph.legendBottomLeft = true;
  return {mag, ph};
}

ReportSeries stepSeries(const std::string& name, const std::vector<int>& lags,
                        const std::vector<double>& v, bool dashed) {
  ReportSeries s{name, {}, v, dashed};
  for (int l : lags) s.x.push_back(l);
  return s;
}

ReportSeries constantSeries(const std::string& name, const std::vector<int>& lags, double v) {
  ReportSeries s = stepSeries(name, lags, std::vector<double>(lags.size(), v), true);
  s.color = 1;
  return s;
}

class FitsPart : public SessionPart {
 public:
  std::string key() const override { return "fits"; }

  bool validate(const json& section, std::string* why) const override {
    if (!section.is_object()) {
      if (why) *why = "must be an object with \"requests\" and \"nonparametric\"";
      return false;
    }
    if (section.contains("nonparametric") && !section["nonparametric"].is_boolean()) {
      if (why) *why = "nonparametric must be true or false";
      return false;
    }
    if (!section.contains("requests") || !section["requests"].is_array()) {
      if (why) *why = "requests must be a list of fits";
      return false;
    }
    if (section["requests"].size() > kMaxPartItems) {
      if (why) *why = "more than " + std::to_string(kMaxPartItems) + " fits";
      return false;
    }
    for (const auto& r : section["requests"]) {
      auto request = fitRequestFromJson(r, why);
      if (!request) return false;
      if (r.contains("estimate") && !polynomialEstimateFromJson(r["estimate"], *request, why)) return false;
    }
    return true;
  }

  void replay(const json& section, const ReplayContext& context, Report& report) const override {
    if (section.value("nonparametric", false))
      report.sections.push_back(spaSection(context));
    for (const auto& j : section["requests"]) {
      std::string why;
      auto request = fitRequestFromJson(j, &why);
      if (!request) continue;  // validated on load
      report.sections.push_back(fitSection(*request, context));
    }
  }

 private:
  // SPA (4.28) of the estimation data with its 99 % band, notches and peaks.
  static ReportSection spaSection(const ReplayContext& context) {
    ReportSection s;
    s.title = "Non-parametric estimate (SPA)";
    std::string why;
    auto sig = fitSignals(context.data, 1, true, context.session.estimation, context.session.validation, &why);
    if (!sig) {
      s.paragraphs.push_back("No estimate: " + why + ".");
      return s;
    }
    const auto b = static_cast<Eigen::Index>(sig->estimation.begin);
    const auto n = static_cast<Eigen::Index>(sig->estimation.size());
    SpaOptions o;
    o.level = kLevel;
    o.omega = logGrid(2.0 * kPi / (static_cast<double>(n) * sig->sampleTime), kPi / sig->sampleTime, 400);
    const NonparametricEstimate e = spa(sig->u.segment(b, n), sig->y.segment(b, n), sig->sampleTime, o);
    if (e.termination != Termination::Converged) {
      s.paragraphs.push_back("No estimate: " + e.message + ".");
      return s;
    }
    const int m = o.windowWidth > 0 ? o.windowWidth : static_cast<int>(std::min<Eigen::Index>(n / 10, 30));
    s.paragraphs.push_back("Blackman-Tukey spectral analysis (4.28) of the estimation data (" +
                           std::to_string(n) + " samples, " + sig->note + "), Hann lag window M = " +
                           std::to_string(m) + ", 99 % band from (6.62).");
    if (sig->closedLoop) s.paragraphs.push_back(kClosedLoopBiasWarning);
    std::size_t undefined = 0;
    for (std::size_t i = 0; i < e.response.omega.size(); ++i)
      undefined += !std::isfinite(e.response.magnitude[i]) || !std::isfinite(e.response.phase[i]);
    if (undefined > 0)
      s.paragraphs.push_back("The estimate is undefined at " + std::to_string(undefined) + " of " +
                             std::to_string(e.response.omega.size()) +
                             " frequencies; the plots leave gaps there.");
    const auto np = notchesAndPeaks(e.response, 3.0);
    s.paragraphs.push_back("Notches: " + joinedFrequencies(np.notches) + ". Peaks: " +
                           joinedFrequencies(np.peaks) + ".");
    s.plots = bodeWithBand(e.response, "SPA", "SPA of the estimation data");
    s.values = {{"samples", n},
                {"lag_window", m},
                {"undefined_frequencies", undefined},
                {"notches_rad_s", np.notches},
                {"peaks_rad_s", np.peaks}};
    return s;
  }

  static ReportSection fitSection(const FitRequest& request, const ReplayContext& context) {
    ReportSection s;
    s.title = "Fit " + request.name;
    FitRequest r = request;  // ranges the request does not name are the session's
    if (!r.estimation) r.estimation = context.session.estimation;
    if (!r.validation) r.validation = context.session.validation;
    std::string structure;
    if (r.physical()) {
      std::string free;
      for (const auto& p : r.start->parameters())
        if (p.free) free += (free.empty() ? "" : ", ") + p.name + " from " + formatSignificant(p.value);
      structure = r.start->structureName() + " grey-box model (5.3), prediction-error fit (5.7) in " +
                  (r.noiseModel == NoiseModel::OutputError ? "output-error form (K = 0)"
                                                           : "innovations form (K estimated)") +
                  "; free parameters (start values) " + free + "; the others held as listed" +
                  (r.randomStarts > 0 ? "; " + std::to_string(r.randomStarts) +
                                            " random starts and two at the SPA notches and peaks (seed " +
                                            std::to_string(r.seed) + ")"
                                      : "");
    } else {
      PolynomialModel probe = PolynomialModel::zero(r.structure, r.orders, 1.0);
      structure = "black-box model " + probe.name() + " (4.8), prediction-error fit (4.6)";
    }
    s.paragraphs.push_back(structure + ".");
    FitRun run;
    try {
      run = runFitRequest(r, context.data, context.progress);
    } catch (const std::invalid_argument& e) {
      s.paragraphs.push_back(std::string("No fit: ") + e.what() + ".");
      return s;
    }
    s.values = {{"name", r.name}, {"termination", toString(run.termination)}};
    if (!run.summary.ok()) {
      s.paragraphs.push_back("No fit: " + run.message + ".");
      return s;
    }
    const FitSignals& sig = run.data;
    s.paragraphs.push_back("Data: " + std::to_string(sig.estimation.size()) + " estimation samples at " +
                           formatSignificant(1.0 / sig.sampleTime, 6) + " Hz (" + sig.note + "); " +
                           toString(run.summary.termination) + " after " +
                           std::to_string(run.summary.iterations) + " iterations.");
    if (sig.closedLoop)
      s.paragraphs.push_back("The log is closed loop: an output-error fit is biased by the noise "
                             "fed back into the input (4.43).");

    ReportTable params{"Estimated parameters (value +- std, 99 % interval)",
                       {"Parameter", "Value", "+- std", "99 % lower", "99 % upper", "Unit"}, {}};
    json values = json::object(), stds = json::object();
    for (const auto& p : run.parameters) {
      if (p.free)
        params.rows.push_back({p.name, formatSignificant(p.value, 6), formatSignificant(p.std, 3),
                               formatSignificant(p.lower, 6), formatSignificant(p.upper, 6), p.unit});
      else
        params.rows.push_back({p.name, formatSignificant(p.value, 6), "fixed", "", "", p.unit});
      values[p.name] = p.value;
      stds[p.name] = p.std;
    }
    s.tables.push_back(params);

    ReportTable quality{"Loss and fit % (5.2)", {"Quantity", "Value"}, {}};
    quality.rows.push_back({"loss V_N (4.6)", formatSignificant(run.summary.loss, 6)});
    quality.rows.push_back({"FPE", formatSignificant(run.summary.fpe, 6)});
    quality.rows.push_back({"fit % on the estimation range", formatFixed(run.fitEstimation, 2)});
    if (run.fitValidation)
      quality.rows.push_back({"fit % on the validation range", formatFixed(*run.fitValidation, 2)});
    else
      s.paragraphs.push_back("No validation range: the fit is not validated.");
    s.tables.push_back(quality);

    ReportTable modes{"Notches and peaks of the estimate (5.4)", {"Kind", "Frequency (rad/s)"}, {}};
    for (double w : run.notches) modes.rows.push_back({"notch", formatSignificant(w, 5)});
    for (double w : run.peaks) modes.rows.push_back({"peak", formatSignificant(w, 5)});
    s.tables.push_back(modes);

    s.values["parameters"] = values;
    s.values["std"] = stds;
    s.values["loss"] = run.summary.loss;
    s.values["fit_estimation_percent"] = run.fitEstimation;
    if (run.fitValidation) s.values["fit_validation_percent"] = *run.fitValidation;
    s.values["notches_rad_s"] = run.notches;
    s.values["peaks_rad_s"] = run.peaks;
    s.values["iterations"] = run.summary.iterations;

    s.plots = bodeWithBand(run.response, r.name, r.name + " with its 99 % band");
    addCompare(run, r.name, s);
    addResiduals(run, s);
    return s;
  }

  // Measured and simulated output on the validation range (the estimation range without one).
  static void addCompare(const FitRun& run, const std::string& name, ReportSection& s) {
    const FitSignals& sig = run.data;
    const SampleRange range = sig.validation.empty() ? sig.estimation : sig.validation;
    ReportSeries meas{"measured", {}, {}, false}, sim{"simulated " + name, {}, {}, true};
    for (std::size_t i = range.begin; i < range.end; ++i) {
      const double t = sig.startTime + static_cast<double>(i) * sig.sampleTime;
      meas.x.push_back(t);
      meas.y.push_back(sig.y[static_cast<Eigen::Index>(i)]);
      sim.y.push_back(run.simulated[static_cast<Eigen::Index>(i)]);
    }
    sim.x = meas.x;
    thinSeries(meas.x, meas.y, 3000);
    thinSeries(sim.x, sim.y, 3000);
    const std::string where = sig.validation.empty() ? "estimation" : "validation";
    s.plots.push_back(ReportPlot{"Measured and simulated output on the " + where + " range, " + name,
                                 "time (s)", "output minus its estimation mean",
                                 false, false, {meas, sim}});
  }

  // Correlation tests of the residuals on the validation range (the estimation range
  // without one), with their 99 % bounds and verdicts.
  static void addResiduals(const FitRun& run, ReportSection& s) {
    const FitSignals& sig = run.data;
    const SampleRange range = sig.validation.empty() ? sig.estimation : sig.validation;
    const Eigen::VectorXd eps = run.physical
                                    ? predictionErrors(*run.physical, run.K, sig.u, sig.y, sig.sampleTime)
                                    : predictionErrors(*run.polynomial, sig.u, sig.y);
    const auto b = static_cast<Eigen::Index>(range.begin), n = static_cast<Eigen::Index>(range.size());
    ResidualOptions o;
    o.level = kLevel;
    if (n < 2 * o.maxLag + 10) {
      s.paragraphs.push_back("No residual tests: the range holds only " + std::to_string(n) + " samples.");
      return;
    }
    const ResidualAnalysis a = residualAnalysis(eps.segment(b, n), sig.u.segment(b, n), o);
    const std::string where = sig.validation.empty() ? "estimation" : "validation";
    ReportTable tests{"Residual tests on the " + where + " range (99 %)",
                      {"Test", "Statistic", "Threshold", "Verdict"}, {}};
    tests.rows.push_back({"whiteness (autocorrelation)", formatSignificant(a.whitenessStatistic, 4),
                          formatSignificant(a.whitenessThreshold, 4), a.white ? "white" : "not white"});
    tests.rows.push_back({"independence of the input (cross-correlation)",
                          formatSignificant(a.independenceStatistic, 4),
                          formatSignificant(a.independenceThreshold, 4),
                          a.independent ? "independent" : "correlated"});
    s.tables.push_back(tests);
    s.paragraphs.push_back("Residual tests: " + a.verdict);
    s.plots.push_back(ReportPlot{"Residual autocorrelation", "lag (samples)", "r_eps(tau) / r_eps(0)", false,
                                 false,
                                 {stepSeries("autocorrelation", a.lags, a.autocorrelation, false),
                                  constantSeries("+99 % bound", a.lags, a.autocorrelationBound),
                                  constantSeries("-99 % bound", a.lags, -a.autocorrelationBound)}});
    s.plots.push_back(ReportPlot{"Cross-correlation of residuals and input", "lag (samples)",
                                 "r_eps,u(tau), normalized", false, false,
                                 {stepSeries("cross-correlation", a.crossLags, a.crossCorrelation, false),
                                  constantSeries("+99 % bound", a.crossLags, a.crossCorrelationBound),
                                  constantSeries("-99 % bound", a.crossLags, -a.crossCorrelationBound)}});
    s.values["residuals"] = {{"white", a.white},
                             {"independent", a.independent},
                             {"whiteness_statistic", a.whitenessStatistic},
                             {"independence_statistic", a.independenceStatistic}};
  }
};

}  // namespace

std::shared_ptr<const SessionPart> makeFitsPart() { return std::make_shared<FitsPart>(); }

}  // namespace flexarm
