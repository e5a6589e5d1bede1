#include "core/diagnosis/diagnosis_temperature.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/signal/seconds_range.h"

namespace flexarm {

namespace {

constexpr double kColdest = -50.0, kHottest = 250.0;

std::string degrees(double c) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f degC", c);
  return buf;
}

}  // namespace

LogTemperature logTemperature(const IdData& log) {
  LogTemperature t;
  if (const Channel* c = log.channel(columns::kTemperature); c && !c->values.empty()) {
    double sum = 0.0;
    for (std::size_t k = 0; k < c->values.size(); ++k) {
      const double v = c->values[k];
      if (!std::isfinite(v) || v < kColdest || v > kHottest) {
        t.problem = std::string("the ") + columns::kTemperature + " channel holds " +
                    std::to_string(v) + " at sample " + std::to_string(k) +
                    ", not a temperature between -50 and 250 degC";
        return t;
      }
      sum += v;
    }
    t.celsius = sum / static_cast<double>(c->values.size());
    t.source = std::string("the mean of its ") + columns::kTemperature + " channel (" +
               std::to_string(c->values.size()) + " samples)";
    return t;
  }
  for (const auto& [key, value] : log.metadata) {
    if (key != columns::kTemperature) continue;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0' || !std::isfinite(v) || v < kColdest || v > kHottest) {
      t.problem = std::string("the metadata value ") + columns::kTemperature + ": '" + value +
                  "' is not a temperature between -50 and 250 degC";
      return t;
    }
    t.celsius = v;
    t.source = std::string("its metadata value ") + columns::kTemperature;
    return t;
  }
  return t;
}

TemperatureCorrection correctForTemperature(DiagnosisReference& reference,
                                            const std::optional<double>& monitoredC,
                                            const std::optional<FrictionTemperatureModel>& model) {
  TemperatureCorrection c;
  c.monitoredC = monitoredC;
  c.referenceC = reference.temperatureC;
  if (model) c.model = *model;
  if (!reference.nominal || reference.nominal->indexOf("f_m") < 0) {
    c.message = "the model has no f_m: no temperature correction";
    return c;
  }
  c.fmReference = c.fmExpected = reference.nominal->value("f_m");
  if (!monitoredC && !reference.temperatureC) {
    c.message = "neither log states a temperature: f_m is compared as fitted";
    return c;
  }
  if (!monitoredC || !reference.temperatureC) {
    c.message = std::string("only the ") + (monitoredC ? "monitored" : "reference") +
                " log states a temperature (" + degrees(monitoredC ? *monitoredC : *reference.temperatureC) +
                "): f_m is compared as fitted";
    return c;
  }
  const double dT = *monitoredC - *reference.temperatureC;
  if (!model || model->alpha == 0.0) {
    c.message = "the monitored log is " + degrees(*monitoredC) + ", the reference " +
                degrees(*reference.temperatureC) +
                "; without alpha (give it, or estimate it from healthy logs at several "
                "temperatures) f_m is compared as fitted, and a warmer or colder axis can "
                "move it with nothing broken";
    return c;
  }
  // A given alpha (no healthy logs behind it) is relative to the reference log's friction:
  // T_ref is that log's temperature, f_m (T) = f_m,ref (1 + alpha (T - T_reference)).
  FrictionTemperatureModel given = *model;
  if (given.logs == 0) given.referenceC = *reference.temperatureC;
  c.model = given;
  const FrictionTemperatureModel& m = c.model;
  std::string why;
  if (!m.isValid(&why)) throw std::invalid_argument("the friction temperature model: " + why);
  // The model is the arm's friction: the plant's (free of the closed-loop bias). theta_0's f_m
  // (fitted through the diagnosis' predictor, which may offset it) moves by the same amount.
  const double plantFm = reference.plant ? reference.plant->value("f_m") : c.fmReference;
  const double plantWarm = m.atTemperature(m.toReference(plantFm, *reference.temperatureC), *monitoredC);
  const double shift = plantWarm - plantFm;
  c.fmExpected = c.fmReference + shift;
  if (!(c.fmExpected > 0.0)) {
    c.message = "the temperature correction would make theta_0's f_m negative: f_m is compared as fitted";
    c.fmExpected = c.fmReference;
    return c;
  }
  for (auto* part : {&reference.nominal, &reference.plant}) {
    if (!*part) continue;
    auto copy = (*part)->clone();
    copy->setParameter("f_m", (*part)->value("f_m") + shift);
    *part = std::shared_ptr<const PhysicalModel>(static_cast<PhysicalModel*>(copy.release()));
  }
  c.applied = true;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "f_m compared at the monitored log's %.1f degC: the arm's f_m %.4g at the reference's "
                "%.1f degC is %.4g there with alpha = %.3g %%/degC (%+.1f %% for %+.1f degC), so "
                "theta_0's f_m moves from %.4g to %.4g",
                *monitoredC, plantFm, *reference.temperatureC, plantWarm, 100.0 * m.alpha,
                100.0 * (plantWarm / plantFm - 1.0), dT, c.fmReference, c.fmExpected);
  c.message = buf;
  return c;
}

FrictionTemperatureFit frictionFromHealthyLogs(const PhysicalModel& start,
                                               const std::vector<const IdData*>& logs,
                                               const std::vector<std::string>& names,
                                               const DiagnosisOptions& options, double referenceC,
                                               const ProgressCallback& progress) {
  std::vector<double> temperature, fm, fmStd;
  // The arm's friction: the plant's closed-loop fit, free of the bias the diagnosis' predictor
  // may give theta_0 (on simulated logs the loop predictor puts f_m 0.006 low at every
  // temperature, which would inflate alpha by a fifth).
  const ReferenceOptions ro;
  auto nameOf = [&](std::size_t i) { return i < names.size() ? names[i] : "log " + std::to_string(i + 1); };
  // A log given twice (or two files of the same samples) is one point: counted twice it
  // would narrow alpha's interval with no new evidence.
  std::string repeated;
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const std::string name = nameOf(i);
    bool again = false;
    for (std::size_t k : used)
      if (!again && sameSamples(*logs[k], std::nullopt, *logs[i], std::nullopt)) {
        repeated += (repeated.empty() ? "" : "; ") + name + " holds the samples of " + nameOf(k);
        again = true;
      }
    if (again) continue;
    used.push_back(i);
    FrictionTemperatureFit failed;
    const LogTemperature t = logTemperature(*logs[i]);
    if (!t.celsius) {
      failed.message = name + ": " + (t.problem.empty() ? "the log states no temperature (a " +
                                                              std::string(columns::kTemperature) +
                                                              " channel or metadata value)"
                                                        : t.problem);
      return failed;
    }
    ProgressCallback part;
    if (progress)
      part = [&progress, i, n = logs.size()](double f, const std::string& stage) {
        return progress((static_cast<double>(i) + f) / static_cast<double>(n), stage);
      };
    const DiagnosisReference ref = referenceFromLog(start, *logs[i], options, ro, part);
    if (!ref.ok()) {
      failed.termination = ref.termination == Termination::Cancelled ? Termination::Cancelled : Termination::Failed;
      failed.message = name + ": " + ref.message;
      return failed;
    }
    temperature.push_back(*t.celsius);
    fm.push_back((ref.plant ? ref.plant : ref.nominal)->value("f_m"));
    // The plant fit gives no standard deviation; theta_0's, fitted on the same samples, stands
    // for it (fitFrictionTemperature widens alpha's when the logs scatter more).
    double s = 0.0;
    for (std::size_t k = 0; k < options.parameters.size() && k < ref.sigma0.size(); ++k)
      if (options.parameters[k] == "f_m") s = ref.sigma0[k];
    fmStd.push_back(s);
  }
  bool weighted = true;
  for (double s : fmStd) weighted = weighted && s > 0.0;
  FrictionTemperatureFit fit =
      fitFrictionTemperature(temperature, fm, weighted ? fmStd : std::vector<double>{}, referenceC);
  if (!repeated.empty()) fit.message += " Logs counted once: " + repeated + ".";
  return fit;
}

}  // namespace flexarm
