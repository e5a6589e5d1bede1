#include "core/session/fit_request.h"

#include <cmath>
#include <stdexcept>

#include "core/ident/fit_json.h"
#include "core/session/json_fields.h"
#include "core/session/model_json.h"

namespace flexarm {

using nlohmann::json;

namespace {

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

FitOptions fitOptionsOf(const FitRequest& request, std::shared_ptr<const IdData> data) {
  FitOptions o = request.options;
  o.estimation = {FitExperiment{data, request.estimation}};
  o.validation.clear();
  if (request.validation) o.validation.push_back(FitExperiment{data, request.validation});
  return o;
}

FitRequest fitRequestOf(const FitOptions& options, const std::vector<ExperimentSource>& more) {
  FitRequest r;
  r.options = options;
  r.options.estimation.clear();
  r.options.validation.clear();
  if (!options.estimation.empty()) r.estimation = options.estimation.front().range;
  if (!options.validation.empty()) r.validation = options.validation.front().range;
  r.experiments = more;
  return r;
}

StoredFit storedFitOf(const FitResult& result) {
  StoredFit s;
  s.parameters = result.parameters;
  s.loss = result.summary.loss;
  s.fitEstimation = result.fitEstimation;
  s.fitValidation = result.fitValidation();
  s.notches = result.notches;
  s.peaks = result.peaks;
  return s;
}

json storedFitToJson(const StoredFit& fit) {
  // The keys of fitResultJson, written by its pieces: a stored fit is a part of a fit result.
  json j = {{"format", kFitJsonFormat},
            {"version", kFitJsonVersion},
            {"loss", fit.loss},
            {"fit_percent", fitPercentJson(fit.fitEstimation)},
            {"fit_percent_validation", fitPercentJson(fit.fitValidation)},
            {"notches_rad_s", fit.notches},
            {"peaks_rad_s", fit.peaks}};
  addFitParameters(j, fit.parameters);
  return j;
}

std::optional<StoredFit> storedFitFromJson(const json& j, std::string* why) {
  const std::string where = "result: ";
  auto fail = [&](const std::string& w) -> std::optional<StoredFit> {
    if (why) *why = where + w;
    return std::nullopt;
  };
  if (!j.is_object()) return fail("must be an object");
  // Sessions written before the fit schema's version 2 name the rows "parameters" and the fit
  // percentages fit_estimation_percent and fit_validation_percent.
  const bool before2 = !j.contains("version");
  if (!before2 && (!j["version"].is_number_integer() || j["version"].get<int>() > kFitJsonVersion))
    return fail("is of a fit schema newer than version " + std::to_string(kFitJsonVersion));
  const char* rowsKey = before2 ? "parameters" : "parameter_rows";
  StoredFit s;
  if (!j.contains(rowsKey) || !j[rowsKey].is_array()) return fail(std::string(rowsKey) + " must be a list");
  if (j[rowsKey].size() > 1000) return fail("more than 1000 parameters");
  for (const auto& p : j[rowsKey]) {
    FitParameter q;
    if (!readText(p, "name", q.name, true, why, where) || !readText(p, "unit", q.unit, false, why, where) ||
        !readNumber(p, "value", q.value, true, why, where) || !readNumber(p, "std", q.std, false, why, where) ||
        !readNumber(p, "lower", q.lower, false, why, where) ||
        !readNumber(p, "upper", q.upper, false, why, where) || !readFlag(p, "free", q.free, why, where) ||
        !readText(p, "effect", q.effect, false, why, where))
      return std::nullopt;
    s.parameters.push_back(q);
  }
  if (!readNumber(j, "loss", s.loss, false, why, where)) return std::nullopt;
  for (auto [key, target] : {std::pair{before2 ? "fit_estimation_percent" : "fit_percent", &s.fitEstimation},
                             std::pair{before2 ? "fit_validation_percent" : "fit_percent_validation", &s.fitValidation}}) {
    if (!j.contains(key) || j[key].is_null()) continue;
    double v = 0.0;
    if (!readNumber(j, key, v, true, why, where)) return std::nullopt;
    *target = v;
  }
  for (auto [key, target] : {std::pair{"notches_rad_s", &s.notches}, std::pair{"peaks_rad_s", &s.peaks}}) {
    if (!j.contains(key)) continue;
    const json& list = j[key];
    if (!list.is_array() || list.size() > 1000) return fail(std::string(key) + " must be a list of frequencies");
    for (const auto& w : list) {
      if (!w.is_number()) return fail(std::string(key) + " must be a list of frequencies");
      target->push_back(w.get<double>());
    }
  }
  return s;
}

bool FitRequest::isValid(std::string* why) const {
  return fitOptionsOf(*this, nullptr).isValidExceptData(why);
}

json fitRequestToJson(const FitRequest& r) {
  const FitOptions& o = r.options;
  json j = {{"name", r.name},
            {"decimation", o.decimation},
            {"max_iterations", o.maxIterations},
            {"estimation_s", secondsRangeToJson(r.estimation)},
            {"validation_s", secondsRangeToJson(r.validation)}};
  if (r.physical()) {
    j["kind"] = toString(FitModelKind::Physical);
    std::vector<Effect> effects;
    json free = json::array(), scaled = json::array();
    for (const auto& f : o.model.effects) {
      effects.push_back(f.effect);
      free.push_back(f.free);
      scaled.push_back(f.scaleSmoothing);
    }
    j["start"] = modelToJson(r.name, *o.model.start, effects);
    if (!effects.empty()) {
      j["effects_free"] = free;
      j["effects_scale_smoothing"] = scaled;
    }
    j["noise_model"] = toString(o.noiseModel);
    if (o.model.armOutput) j["arm_output"] = true;
    j["closed_loop"] = toString(o.closedLoop);
    j["random_starts"] = o.randomStarts;
    j["seed"] = o.seed;
    json starts = json::object(), bounds = json::object();
    for (const auto& v : o.startValues) starts[v.name] = v.value;
    // JSON has no infinity: an open end is null.
    auto end = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    for (const auto& b : o.bounds) bounds[b.name] = json::array({end(b.lower), end(b.upper)});
    if (!starts.empty()) j["start_values"] = starts;
    if (!bounds.empty()) j["bounds"] = bounds;
  } else {
    const PolyOrders& q = o.model.orders;
    j["kind"] = toString(FitModelKind::BlackBox);
    j["structure"] = toString(o.model.structure);
    j["orders"] = {{"na", q.na}, {"nb", q.nb}, {"nc", q.nc}, {"nd", q.nd}, {"nf", q.nf}, {"nk", q.nk}};
  }
  if (!r.experiments.empty()) {
    json more = json::array();
    for (const auto& e : r.experiments)
      more.push_back({{"log", e.path}, {"range_s", secondsRangeToJson(e.range)}, {"validation", e.validation}});
    j["experiments"] = more;
  }
  if (r.provenance) j["provenance"] = provenanceToJson(*r.provenance);
  if (r.stored) j["result"] = storedFitToJson(*r.stored);
  return j;
}

std::optional<FitRequest> fitRequestFromJson(const json& j, std::string* why) {
  auto fail = [why](const std::string& w) -> std::optional<FitRequest> {
    if (why) *why = w;
    return std::nullopt;
  };
  if (!j.is_object()) return fail("a fit must be an object");
  FitRequest r;
  FitOptions& o = r.options;
  if (!j.contains("name") || !j["name"].is_string()) return fail("a fit needs a name");
  r.name = j["name"].get<std::string>();
  const std::string where = "fit '" + r.name + "': ";
  std::string reason;
  if (!j.contains("kind") || !j["kind"].is_string()) return fail(where + "kind must be \"physical\" or \"black-box\"");
  const std::string kind = j["kind"].get<std::string>();
  if (!readInt(j, "decimation", 1, 1000, o.decimation, &reason) ||
      !readInt(j, "max_iterations", 1, 100000, o.maxIterations, &reason) ||
      !readSecondsRange(j, "estimation_s", r.estimation, &reason) ||
      !readSecondsRange(j, "validation_s", r.validation, &reason))
    return fail(where + reason);
  if (kind == toString(FitModelKind::Physical)) {
    o.model.kind = FitModelKind::Physical;
    if (!j.contains("start")) return fail(where + "a physical fit needs its start model");
    auto spec = modelFromJson(j["start"], &reason);
    if (!spec) return fail(where + reason);
    o.model.start = spec->model;
    // The start model's effects, each value free or fixed as "effects_free" says (absent: the
    // first value free, the others fixed).
    const json* free = j.contains("effects_free") ? &j["effects_free"] : nullptr;
    if (free && (!free->is_array() || free->size() != spec->effects.size()))
      return fail(where + "effects_free must list the flags of every effect of the start model");
    // Whether each effect's smoothing speed follows the data (absent, as sessions stored before
    // it did: the value stored).
    const json* scaled = j.contains("effects_scale_smoothing") ? &j["effects_scale_smoothing"] : nullptr;
    if (scaled && (!scaled->is_array() || scaled->size() != spec->effects.size()))
      return fail(where + "effects_scale_smoothing must list one flag per effect of the start model");
    for (std::size_t i = 0; i < spec->effects.size(); ++i) {
      FitEffect f = FitEffect::of(spec->effects[i]);
      f.scaleSmoothing = scaled && (*scaled)[i].is_boolean() && (*scaled)[i].get<bool>();
      if (free) {
        const json& flags = (*free)[i];
        // One flag per value of the effect (sessions stored before effects took more than two
        // values hold a pair for every effect: the flags past its values are ignored).
        bool flagsOk = flags.is_array() && !flags.empty();
        for (std::size_t k = 0; flagsOk && k < flags.size(); ++k) flagsOk = flags[k].is_boolean();
        if (!flagsOk) return fail(where + "effects_free must list the flags of every effect of the start model");
        for (std::size_t k = 0; k < f.free.size() && k < flags.size(); ++k) f.free[k] = flags[k].get<bool>();
      }
      o.model.effects.push_back(f);
    }
    if (j.contains("noise_model")) {
      auto m = j["noise_model"].is_string() ? noiseModelFromString(j["noise_model"].get<std::string>())
                                            : std::nullopt;
      if (!m) return fail(where + "noise_model must be \"" + toString(NoiseModel::OutputError) +
                          "\" or \"" + toString(NoiseModel::Innovations) + "\"");
      o.noiseModel = *m;
    }
    if (j.contains("arm_output")) {
      if (!j["arm_output"].is_boolean()) return fail(where + "arm_output must be true or false");
      o.model.armOutput = j["arm_output"].get<bool>();
    }
    // Sessions written before fits stored their closed-loop method ran direct fits.
    o.closedLoop = ClosedLoopChoice::Direct;
    if (j.contains("closed_loop")) {
      auto m = j["closed_loop"].is_string() ? closedLoopChoiceFromString(j["closed_loop"].get<std::string>())
                                            : std::nullopt;
      if (!m)
        return fail(where + "closed_loop must be \"auto\", \"direct\", \"two-stage\" or \"indirect\"");
      o.closedLoop = *m;
    }
    int seed = 1;
    if (!readInt(j, "random_starts", 0, 1000, o.randomStarts, &reason) ||
        !readInt(j, "seed", 0, 1 << 30, seed, &reason))
      return fail(where + reason);
    o.seed = static_cast<unsigned>(seed);
    if (j.contains("start_values")) {
      if (!j["start_values"].is_object()) return fail(where + "start_values must map names to numbers");
      for (const auto& [name, v] : j["start_values"].items()) {
        if (!v.is_number()) return fail(where + "the start value of " + name + " must be a number");
        o.startValues.push_back({name, v.get<double>()});
      }
    }
    if (j.contains("bounds")) {
      if (!j["bounds"].is_object()) return fail(where + "bounds must map names to [lower, upper]");
      for (const auto& [name, v] : j["bounds"].items()) {
        if (!v.is_array() || v.size() != 2 || !(v[0].is_number() || v[0].is_null()) ||
            !(v[1].is_number() || v[1].is_null()))
          return fail(where + "the bounds of " + name + " must be [lower, upper] (numbers, null for an open end)");
        o.bounds.push_back({name, v[0].is_null() ? -INFINITY : v[0].get<double>(),
                            v[1].is_null() ? INFINITY : v[1].get<double>()});
      }
    }
  } else if (kind == toString(FitModelKind::BlackBox)) {
    o.model.kind = FitModelKind::BlackBox;
    auto s = j.contains("structure") && j["structure"].is_string()
                 ? polyStructureFromString(j["structure"].get<std::string>())
                 : std::nullopt;
    if (!s) return fail(where + "structure must be arx, armax, oe, bj or ss");
    o.model.structure = *s;
    if (!j.contains("orders") || !j["orders"].is_object()) return fail(where + "a black-box fit needs orders");
    const json& q = j["orders"];
    PolyOrders& orders = o.model.orders;
    int* fields[] = {&orders.na, &orders.nb, &orders.nc, &orders.nd, &orders.nf, &orders.nk};
    const char* names[] = {"na", "nb", "nc", "nd", "nf", "nk"};
    for (int i = 0; i < 6; ++i)
      if (!readInt(q, names[i], 0, 200, *fields[i], &reason)) return fail(where + reason);
  } else {
    return fail(where + "kind must be \"physical\" or \"black-box\", not \"" + kind + "\"");
  }
  if (j.contains("experiments")) {
    if (!j["experiments"].is_array()) return fail(where + "experiments must be a list");
    for (const auto& e : j["experiments"]) {
      ExperimentSource source;
      if (!e.is_object() || !e.contains("log") || !e["log"].is_string() || e["log"].get<std::string>().empty())
        return fail(where + "each of its experiments needs a \"log\" file name");
      source.path = e["log"].get<std::string>();
      if (!readSecondsRange(e, "range_s", source.range, &reason)) return fail(where + source.path + ": " + reason);
      if (e.contains("validation")) {
        if (!e["validation"].is_boolean()) return fail(where + source.path + ": validation must be true or false");
        source.validation = e["validation"].get<bool>();
      }
      r.experiments.push_back(source);
    }
  }
  if (j.contains("provenance")) {
    r.provenance = provenanceFromJson(j["provenance"], &reason);
    if (!r.provenance) return fail(where + reason);
  }
  if (j.contains("result")) {
    r.stored = storedFitFromJson(j["result"], &reason);
    if (!r.stored) return fail(where + reason);
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
  const int n = request.options.model.orders.parameters();
  if (static_cast<int>(j["parameters"].size()) != n)
    return fail("holds " + std::to_string(j["parameters"].size()) + " parameters, the orders give " +
                std::to_string(n));
  if (!j.contains("sample_time") || !j["sample_time"].is_number() || !(j["sample_time"].get<double>() > 0.0))
    return fail("sample_time must be a positive number");
  PolynomialModel m = PolynomialModel::zero(request.options.model.structure, request.options.model.orders, j["sample_time"].get<double>());
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

FitResult runFitRequest(const FitRequest& request, const IdData& data, const ProgressCallback& progress) {
  std::string why;
  if (!request.isValid(&why)) throw std::invalid_argument(why);
  // The data outlive the call: a non-owning pointer is enough.
  const std::shared_ptr<const IdData> view(&data, [](const IdData*) {});
  FitOptions options = fitOptionsOf(request, view);
  ExperimentLogs logs;
  if (!appendExperiments(options, request.experiments, LogReadOptions{}, logs, &why)) {
    FitResult failed;
    failed.status = FitStatus::BadData;
    failed.message = why;
    return failed;
  }
  return fitModel(options, progress);
}

}  // namespace flexarm
