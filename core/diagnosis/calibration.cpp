#include "core/diagnosis/calibration.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace flexarm {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<double> defaultScales() {
  std::vector<double> s;
  for (int i = 0; i < 48; ++i) s.push_back(0.5 * std::pow(16.0, i / 47.0));
  return s;
}

// The 95 % upper confidence bound of a Poisson mean after n events.
double poissonUpper(int n) {
  auto cdf = [n](double mu) {
    double term = std::exp(-mu), sum = term;
    for (int k = 1; k <= n; ++k) sum += (term *= mu / k);
    return sum;
  };
  double lo = 0.0, hi = 10.0 + 5.0 * n;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) > 0.05 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Median with missed runs as +infinity; 95th percentile likewise.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(q * v.size()) - 1));
  return v[i];
}

// What the calibration keeps of a run: the ratio traces (as floats) and the times.
struct RunTrace {
  bool ok = false;
  std::string message;
  int fault = -1;  // monitored parameter that steps, -1: fault-free
  double from = 0.0;
  std::vector<double> time;
  std::vector<TestTrace> traces;  // ratio only
};

// One simulated run through the whole pipeline.
RunTrace runOnce(const DiagnosisReference& simReference, const PhysicalModel& plant,
                 const LogConditions& conditions, double noiseScale, const DiagnosisOptions& options,
                 const CalibrationOptions& c, int fault, std::uint64_t seed) {
  RunTrace out;
  out.fault = fault;
  const double duration = c.durationS > 0.0 ? c.durationS : conditions.simulation.durationS;
  const double faultTime = c.faultTimeS > 0.0 ? c.faultTimeS : 0.5 * duration;
  std::vector<ParameterStep> steps;
  if (fault >= 0) {
    const std::string& name = options.parameters[static_cast<std::size_t>(fault)];
    const bool inverted =
        std::find(options.inverted.begin(), options.inverted.end(), name) != options.inverted.end();
    const double v = plant.value(name);
    steps.push_back({name, inverted ? v / (1.0 + c.faultSize) : v * (1.0 + c.faultSize), faultTime});
  }
  const auto run = simulateClosedLoop(plant, {}, runOptions(conditions, noiseScale, seed, steps, duration));
  if (run.termination != Termination::Converged) {
    out.message = run.message;
    return out;
  }
  std::string why;
  const auto signals = diagnosisSignals(run.data, simReference.predictor, &why);
  if (!signals) {
    out.message = why;
    return out;
  }
  DiagnosisResult r = diagnoseSignals(simReference, *signals, options);
  if (r.termination != Termination::Converged) {
    out.message = r.message;
    return out;
  }
  out.ok = true;
  out.from = fault >= 0 ? faultTime : options.settleS;
  out.time = std::move(r.time);
  for (auto& t : r.tests) {
    TestTrace compact;
    compact.test = t.test;
    compact.columns = t.columns;
    compact.ratio = std::move(t.ratio);
    out.traces.push_back(std::move(compact));
  }
  return out;
}

}  // namespace

bool CalibrationOptions::isValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (healthyRuns < 1 || healthyRuns > 100000 || faultyRuns < 0 || faultyRuns > 100000)
    return fail("the calibration needs at least one fault-free run");
  if (!(faultSize > -0.9 && faultSize < 10.0) || faultSize == 0.0)
    return fail("the fault size must be a non-zero part in (-0.9, 10)");
  if (!(faultTimeS >= 0.0) || !(durationS >= 0.0) || !(horizonS > 0.0))
    return fail("fault time and duration must be >= 0 s and the horizon > 0 s");
  if (!(targetFalseAlarmsPerHour >= 0.0) || !std::isfinite(targetFalseAlarmsPerHour))
    return fail("the false-alarm rate must be a number >= 0");
  for (double s : scales)
    if (!(s > 0.0) || !std::isfinite(s)) return fail("threshold scales must be > 0");
  if (threads < 1 || threads > 256) return fail("threads must be in 1..256");
  if (why) why->clear();
  return true;
}

double designThreshold(DiagnosisTest test, const DiagnosisOptions& o) {
  switch (test) {
    case DiagnosisTest::Classical: return o.classicalK;
    case DiagnosisTest::Robust: return o.robustK;
    case DiagnosisTest::Cusum: return o.cusumAlpha2;
    case DiagnosisTest::Hypothesis: return o.hypothesisThreshold;
  }
  return 1.0;
}

DiagnosisOptions withThresholdScale(const DiagnosisOptions& options, DiagnosisTest test, double scale) {
  DiagnosisOptions o = options;
  switch (test) {
    case DiagnosisTest::Classical: o.classicalK *= scale; break;
    case DiagnosisTest::Robust: o.robustK *= scale; break;
    case DiagnosisTest::Cusum: o.cusumAlpha2 *= scale; break;
    case DiagnosisTest::Hypothesis: o.hypothesisThreshold *= scale; break;
  }
  return o;
}

CalibrationResult calibrateUnder(const DiagnosisReference& reference, const LogConditions& conditions,
                                 double noiseScale, const DiagnosisOptions& options,
                                 const CalibrationOptions& calibration,
                                 const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("calibration: " + why);
  if (!calibration.isValid(&why)) throw std::invalid_argument("calibration: " + why);
  if (!reference.ok() || !reference.plant)
    throw std::invalid_argument("calibration: the reference is not usable: " + reference.message);
  const auto begin = std::chrono::steady_clock::now();
  CalibrationResult result;
  result.noiseScale = noiseScale;
  result.calibrated = options;
  auto finish = [&](Termination t, std::string message) {
    result.termination = t;
    result.message = std::move(message);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    return result;
  };
  const PhysicalModel& plant = *reference.plant;
  for (const auto& name : options.parameters) {
    if (plant.indexOf(name) < 0)
      throw std::invalid_argument("calibration: the plant has no parameter " + name);
    result.faults.push_back(name);
  }
  const double duration = calibration.durationS > 0.0 ? calibration.durationS : conditions.simulation.durationS;
  const double faultTime = calibration.faultTimeS > 0.0 ? calibration.faultTimeS : 0.5 * duration;
  if (faultTime >= duration) return finish(Termination::Failed, "the fault would step in after the run's end");
  char text[400];
  std::snprintf(text, sizeof text,
                "%d fault-free and %d x %zu faulty runs of %.3g s (fault of %+.0f %% at %.3g s) of the "
                "plant under %s, noise %.3g times the simulator's defaults",
                calibration.healthyRuns, calibration.faultyRuns, options.parameters.size(), duration,
                100.0 * calibration.faultSize, faultTime, conditions.note.c_str(), noiseScale);
  result.conditions = text;

  // theta_0 of the simulated arm, fitted on a fault-free run as on the real log.
  const auto referenceRun =
      simulateClosedLoop(plant, {}, runOptions(conditions, noiseScale, calibration.seed, {}, duration));
  const auto referenceSignals = referenceRun.termination == Termination::Converged
                                    ? diagnosisSignals(referenceRun.data, reference.predictor, &why)
                                    : std::nullopt;
  if (!referenceSignals)
    return finish(Termination::Failed, "the fault-free reference run could not be simulated: " +
                                           (referenceRun.termination == Termination::Converged ? why : referenceRun.message));
  ReferenceOptions ro;
  ro.fitPlant = false;
  DiagnosisOptions same = options;
  same.predictor = reference.predictor;
  const DiagnosisReference simReference = referenceFromSignals(plant, *referenceSignals, same, ro);
  if (!simReference.ok())
    return finish(Termination::Failed, "the reference of the simulated arm failed: " + simReference.message);

  // The runs, in parallel; progress and cancellation from this thread.
  std::vector<int> faultOf;
  for (int i = 0; i < calibration.healthyRuns; ++i) faultOf.push_back(-1);
  for (std::size_t p = 0; p < options.parameters.size(); ++p)
    for (int i = 0; i < calibration.faultyRuns; ++i) faultOf.push_back(static_cast<int>(p));
  std::vector<RunTrace> runs(faultOf.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> cancel{false};
  auto worker = [&]() {
    for (std::size_t i = next++; i < runs.size() && !cancel; i = next++) {
      try {
        runs[i] = runOnce(simReference, plant, conditions, noiseScale, options, calibration, faultOf[i],
                          calibration.seed + 1 + i);
      } catch (const std::exception& e) {
        runs[i].message = e.what();
      }
      ++done;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < calibration.threads; ++t) pool.emplace_back(worker);
  for (std::size_t i = next++; i < runs.size() && !cancel; i = next++) {
    try {
      runs[i] = runOnce(simReference, plant, conditions, noiseScale, options, calibration, faultOf[i],
                        calibration.seed + 1 + i);
    } catch (const std::exception& e) {
      runs[i].message = e.what();
    }
    ++done;
    if (reportProgress(progress, static_cast<double>(done) / static_cast<double>(runs.size()), "calibrate"))
      cancel = true;
  }
  for (auto& t : pool) t.join();
  if (cancel) return finish(Termination::Cancelled, "cancelled");
  for (const auto& r : runs)
    if (!r.ok) return finish(Termination::Failed, "a simulated run could not be diagnosed: " + r.message);

  result.healthyRuns = calibration.healthyRuns;
  result.faultyRuns = calibration.faultyRuns * static_cast<int>(options.parameters.size());
  for (const auto& r : runs)
    if (r.fault < 0 && !r.time.empty())
      result.healthyHours += std::max(0.0, r.time.back() - r.from + (r.time.size() > 1 ? r.time[1] - r.time[0] : 0.0)) / 3600.0;

  // One threshold of a set of tests over every run: false alarms, isolation and delays.
  const std::size_t faults = options.parameters.size();
  auto evaluate = [&](const std::vector<std::size_t>& which, const std::vector<double>& scales,
                      std::vector<double>* isolatedPerFault, std::vector<double>* delayPerFault) {
    CalibrationPoint point;
    std::vector<std::vector<double>> delays(faults);
    int isolated = 0, wrong = 0, faulty = 0;
    for (const auto& r : runs) {
      std::vector<const TestTrace*> traces;
      for (std::size_t k : which) traces.push_back(&r.traces[k]);
      const TestOutcome o = evaluateTests(traces, scales, r.time, result.faults, options.confirmS, r.from);
      if (r.fault < 0) {
        point.falseAlarms += o.detectionEvents;
        continue;
      }
      ++faulty;
      double delay = kInf;
      if (o.verdict && *o.verdict == static_cast<std::size_t>(r.fault) &&
          *o.verdictTime - r.from <= calibration.horizonS + 1e-9)
        delay = *o.verdictTime - r.from;
      else if (o.verdict && *o.verdict != static_cast<std::size_t>(r.fault))
        ++wrong;
      if (std::isfinite(delay)) ++isolated;
      delays[static_cast<std::size_t>(r.fault)].push_back(delay);
    }
    point.falseAlarmsPerHour = result.healthyHours > 0.0 ? point.falseAlarms / result.healthyHours : 0.0;
    point.falseAlarmsPerHourUpper =
        result.healthyHours > 0.0 ? poissonUpper(point.falseAlarms) / result.healthyHours : kInf;
    std::vector<double> all;
    for (const auto& d : delays) all.insert(all.end(), d.begin(), d.end());
    point.isolatedFraction = faulty ? static_cast<double>(isolated) / faulty : 0.0;
    point.wrongFraction = faulty ? static_cast<double>(wrong) / faulty : 0.0;
    point.medianDelayS = quantile(all, 0.5);
    point.p95DelayS = quantile(all, 0.95);
    if (isolatedPerFault && delayPerFault) {
      isolatedPerFault->clear();
      delayPerFault->clear();
      for (const auto& d : delays) {
        const auto n = std::count_if(d.begin(), d.end(), [](double v) { return std::isfinite(v); });
        isolatedPerFault->push_back(d.empty() ? 0.0 : static_cast<double>(n) / static_cast<double>(d.size()));
        delayPerFault->push_back(quantile(d, 0.5));
      }
    }
    return point;
  };

  const std::vector<double> scales = calibration.scales.empty() ? defaultScales() : calibration.scales;
  for (std::size_t k = 0; k < options.tests.size(); ++k) {
    TestCalibration tc;
    tc.test = options.tests[k];
    for (double s : scales) {
      CalibrationPoint p = evaluate({k}, {s}, nullptr, nullptr);
      p.scale = s;
      p.threshold = s * designThreshold(tc.test, options);
      tc.curve.push_back(p);
    }
    std::sort(tc.curve.begin(), tc.curve.end(),
              [](const CalibrationPoint& a, const CalibrationPoint& b) { return a.scale < b.scale; });
    for (std::size_t i = 0; i < tc.curve.size(); ++i)
      if (tc.curve[i].falseAlarmsPerHour <= calibration.targetFalseAlarmsPerHour) {
        tc.chosen = static_cast<int>(i);
        break;
      }
    if (tc.chosen >= 0) {
      const double s = tc.curve[static_cast<std::size_t>(tc.chosen)].scale;
      evaluate({k}, {s}, &tc.isolatedFraction, &tc.medianDelayS);
      result.calibrated = withThresholdScale(result.calibrated, tc.test, s);
    }
    result.tests.push_back(tc);
  }

  // The decision over the calibrated thresholds.
  std::vector<std::size_t> which;
  std::vector<double> decisionScales;
  for (DiagnosisTest t : options.decision)
    for (std::size_t k = 0; k < options.tests.size(); ++k)
      if (options.tests[k] == t) {
        which.push_back(k);
        const auto& tc = result.tests[k];
        decisionScales.push_back(tc.chosen >= 0 ? tc.curve[static_cast<std::size_t>(tc.chosen)].scale : 1.0);
      }
  result.decision = evaluate(which, decisionScales, &result.decisionIsolatedFraction,
                             &result.decisionMedianDelayS);
  std::snprintf(text, sizeof text,
                "%.3g h of fault-free simulated time: the decision raised %d false alarms (%.3g per "
                "hour, at most %.3g at 95 %%) and isolated %.0f %% of the faults within %.3g s",
                result.healthyHours, result.decision.falseAlarms, result.decision.falseAlarmsPerHour,
                result.decision.falseAlarmsPerHourUpper, 100.0 * result.decision.isolatedFraction,
                calibration.horizonS);
  return finish(Termination::Converged, text);
}

CalibrationResult calibrate(const DiagnosisReference& reference, const IdData& log,
                            const DiagnosisOptions& options, const CalibrationOptions& calibration,
                            const ProgressCallback& progress) {
  std::string why;
  const auto conditions = logConditions(log, &why);
  if (!conditions) {
    CalibrationResult r;
    r.message = "the log's conditions cannot be simulated: " + why;
    return r;
  }
  std::string note;
  const double scale = matchNoiseScale(*reference.plant, *conditions, reference.predictor,
                                       reference.plantNoiseVariance, &note);
  CalibrationResult r = calibrateUnder(reference, *conditions, scale, options, calibration, progress);
  if (r.termination == Termination::Converged) r.conditions += "; " + note;
  return r;
}

}  // namespace flexarm
