#include "core/diagnosis/calibration.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "core/recursive/recursive_log.h"

namespace flexarm {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<double> defaultScales() {
  std::vector<double> s;
  for (int i = 0; i < 64; ++i) s.push_back(0.1 * std::pow(100.0, i / 63.0));
  return s;
}

// Median with missed runs as +infinity; 95th percentile likewise.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(q * v.size()) - 1));
  return v[i];
}

// What the calibration keeps of a run: the ratio traces and the times.
struct RunTrace {
  bool ok = false;
  std::string message;
  int fault = -1;  // monitored parameter that steps, -1: fault-free
  double from = 0.0;
  std::vector<double> time;
  std::vector<TestTrace> traces;  // ratio only
  bool mismatch = false;          // the model check found the model no longer fits
};

// The reference of a run: its own, or fitted on a fault-free run of the same arm.
std::shared_ptr<const DiagnosisReference> referenceFor(const MonteCarloRun& m,
                                                       const DiagnosisOptions& options,
                                                       std::string* why) {
  if (m.reference) return m.reference;
  const auto run = simulateClosedLoop(
      *m.plant, {}, runOptions(m.conditions, m.noiseScale, m.referenceSeed, {}, m.durationS));
  if (run.termination != Termination::Converged) {
    *why = "the fault-free reference run failed: " + run.message;
    return nullptr;
  }
  ReferenceOptions ro;
  ro.fitPlant = false;
  auto ref = std::make_shared<DiagnosisReference>(referenceFromLog(*m.plant, run.data, options, ro));
  if (!ref->ok()) {
    *why = "the reference of the simulated arm failed: " + ref->message;
    return nullptr;
  }
  return ref;
}

// One simulated run through the whole pipeline.
RunTrace runOnce(const MonteCarloRun& m, const DiagnosisOptions& options) {
  RunTrace out;
  out.fault = m.fault;
  std::string why;
  const auto reference = referenceFor(m, options, &why);
  if (!reference) {
    out.message = why;
    return out;
  }
  const double duration = m.durationS > 0.0 ? m.durationS : m.conditions.simulation.durationS;
  std::vector<ParameterStep> steps;
  if (m.fault >= 0) {
    const std::string& name = options.parameters[static_cast<std::size_t>(m.fault)];
    const bool inverted =
        std::find(options.inverted.begin(), options.inverted.end(), name) != options.inverted.end();
    const double v = m.plant->value(name);
    steps.push_back({name, inverted ? v / (1.0 + m.faultSize) : v * (1.0 + m.faultSize), m.faultTimeS});
  }
  const auto run = simulateClosedLoop(*m.plant, {},
                                      runOptions(m.conditions, m.noiseScale, m.seed, steps, duration));
  if (run.termination != Termination::Converged) {
    out.message = run.message;
    return out;
  }
  const auto signals = diagnosisSignals(run.data, reference->predictor, &why);
  if (!signals) {
    out.message = why;
    return out;
  }
  DiagnosisResult r = diagnoseSignals(*reference, *signals, options);
  if (r.termination != Termination::Converged) {
    out.message = r.message;
    return out;
  }
  out.ok = true;
  out.mismatch = r.modelCheck.mismatch;
  out.from = m.fault >= 0 ? m.faultTimeS : options.settleS;
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
  if (healthyRuns < 1) return fail("the calibration needs at least one fault-free run");
  if (healthyRuns > kMaxRuns || faultyRuns < 0 || faultyRuns > kMaxRuns)
    return fail("the calibration takes 1 to 100000 fault-free runs and 0 to 100000 faulty runs per parameter");
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
    case DiagnosisTest::Joint: return o.jointScale;
  }
  return 1.0;
}

double poissonUpper95(int events) {
  if (events < 0) throw std::invalid_argument("poissonUpper95: a negative count of events");
  // P(N <= n; mu) summed term by term in logarithms: exp(-mu) alone underflows once mu passes
  // about 745, which a threshold far too low reaches in a few simulated hours.
  auto cdf = [events](double mu) {
    if (mu <= 0.0) return 1.0;
    double sum = 0.0;
    for (int k = 0; k <= events; ++k)
      sum += std::exp(k * std::log(mu) - mu - std::lgamma(k + 1.0));
    return sum;
  };
  double lo = 0.0, hi = 10.0 + 2.0 * events;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) > 0.05 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

DiagnosisOptions withColumnScales(const DiagnosisOptions& options, DiagnosisTest test,
                                  const std::vector<double>& scales) {
  DiagnosisOptions o = options;
  std::vector<double>* v = o.scales(test);
  if (!v) return withThresholdScale(o, test, scales.empty() ? 1.0 : scales.front());
  if (scales.size() != o.parameters.size())
    throw std::invalid_argument("one threshold factor per monitored parameter expected");
  if (v->empty()) v->assign(scales.size(), 1.0);
  for (std::size_t i = 0; i < scales.size(); ++i) (*v)[i] *= scales[i];
  return o;
}

DiagnosisOptions withThresholdScale(const DiagnosisOptions& options, DiagnosisTest test, double scale) {
  DiagnosisOptions o = options;
  switch (test) {
    case DiagnosisTest::Classical: o.classicalK *= scale; break;
    case DiagnosisTest::Robust: o.robustK *= scale; break;
    case DiagnosisTest::Cusum: o.cusumAlpha2 *= scale; break;
    case DiagnosisTest::Hypothesis: o.hypothesisThreshold *= scale; break;
    case DiagnosisTest::Joint: o.jointScale *= scale; break;
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
  const double duration = calibration.durationS > 0.0 ? calibration.durationS : conditions.simulation.durationS;
  const double faultTime = calibration.faultTimeS > 0.0 ? calibration.faultTimeS : 0.5 * duration;
  if (faultTime >= duration) {
    CalibrationResult r;
    r.message = "the fault would step in after the run's end";
    return r;
  }
  // theta_0 of the simulated arm, fitted on a fault-free run as on the real log, shared by
  // every run.
  MonteCarloRun base;
  base.plant = reference.plant;
  base.conditions = conditions;
  base.noiseScale = noiseScale;
  base.referenceSeed = calibration.seed;
  base.faultSize = calibration.faultSize;
  base.faultTimeS = faultTime;
  base.durationS = duration;
  DiagnosisOptions same = options;
  same.predictor = reference.predictor;
  base.reference = referenceFor(base, same, &why);
  if (!base.reference) {
    CalibrationResult r;
    r.message = why;
    return r;
  }
  // The budget, before any run is set up: every run keeps its conditions (the log's reference)
  // and its tests' statistics at the diagnosis rate until the thresholds are chosen.
  {
    const double rate = conditions.simulation.logRateHz /
                        recursiveDecimation(0, conditions.simulation.logRateHz);
    double columns = 1.0;  // the time
    for (DiagnosisTest t : options.tests)
      columns += t == DiagnosisTest::Hypothesis ? 1.0 : static_cast<double>(options.parameters.size());
    const double perRun = duration * rate * columns * sizeof(double) +
                          static_cast<double>(conditions.simulation.referenceSignal.size()) * sizeof(double);
    const double total = static_cast<double>(calibration.healthyRuns) +
                         static_cast<double>(calibration.faultyRuns) * static_cast<double>(options.parameters.size());
    if (total * perRun > CalibrationOptions::kMaxCalibrationBytes) {
      CalibrationResult r;
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "%.0f runs of %.4g s would hold %.3g GB (%.3g MB a run), more than the %.3g GB a calibration may "
                    "take; at most %.0f runs fit (with --runs N, N fault-free and N/5 faulty runs per parameter)",
                    total, duration, total * perRun / 1e9, perRun / 1e6,
                    CalibrationOptions::kMaxCalibrationBytes / 1e9,
                    std::floor(CalibrationOptions::kMaxCalibrationBytes / perRun));
      r.message = buf;
      r.badRequest = true;
      return r;
    }
  }
  std::vector<MonteCarloRun> runs;
  std::uint64_t seed = calibration.seed + 1;
  for (int i = 0; i < calibration.healthyRuns; ++i) {
    runs.push_back(base);
    runs.back().seed = seed++;
  }
  for (std::size_t p = 0; p < options.parameters.size(); ++p)
    for (int i = 0; i < calibration.faultyRuns; ++i) {
      runs.push_back(base);
      runs.back().seed = seed++;
      runs.back().fault = static_cast<int>(p);
    }
  CalibrationResult result = monteCarlo(runs, same, calibration, progress);
  char text[400];
  std::snprintf(text, sizeof text,
                "%d fault-free and %d x %zu faulty runs of %.3g s (fault of %+.0f %% at %.3g s) of the "
                "plant under %s, noise %.3g times the simulator's defaults",
                calibration.healthyRuns, calibration.faultyRuns, options.parameters.size(), duration,
                100.0 * calibration.faultSize, faultTime, conditions.note.c_str(), noiseScale);
  result.conditions = text;
  result.noiseScale = noiseScale;
  return result;
}

CalibrationResult monteCarlo(const std::vector<MonteCarloRun>& plan, const DiagnosisOptions& options,
                             const CalibrationOptions& calibration, const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("Monte Carlo: " + why);
  if (!calibration.isValid(&why)) throw std::invalid_argument("Monte Carlo: " + why);
  for (const auto& m : plan)
    if (!m.plant) throw std::invalid_argument("Monte Carlo: a run without a plant");
  const auto begin = std::chrono::steady_clock::now();
  CalibrationResult result;
  result.calibrated = options;
  auto finish = [&](Termination t, std::string message) {
    result.termination = t;
    result.message = std::move(message);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    return result;
  };
  result.faults = options.parameters;

  // Runs of one arm share its reference: fitted first, once per arm, then every run; both in
  // parallel, with progress and cancellation from this thread. The plan is not copied: each
  // run is drawn from it with its reference when its turn comes.
  std::vector<std::shared_ptr<const DiagnosisReference>> references(plan.size());
  std::vector<std::size_t> owner(plan.size());  // the first run of each arm fits its reference
  for (std::size_t i = 0; i < plan.size(); ++i) {
    owner[i] = i;
    for (std::size_t j = 0; j < i; ++j)
      if (!plan[i].reference && plan[j].plant == plan[i].plant &&
          plan[j].referenceSeed == plan[i].referenceSeed) {
        owner[i] = owner[j];
        break;
      }
  }
  std::vector<std::string> failures(plan.size());
  std::atomic<bool> cancel{false};
  auto parallel = [&](std::size_t count, const std::function<void(std::size_t)>& work, double from,
                      double to) {
    std::atomic<std::size_t> next{0}, done{0};
    auto body = [&](std::size_t i) {
      try {
        work(i);
      } catch (const std::exception& e) {
        failures[i] = e.what();
      }
      ++done;
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < calibration.threads; ++t)
      pool.emplace_back([&]() {
        for (std::size_t i = next++; i < count && !cancel; i = next++) body(i);
      });
    for (std::size_t i = next++; i < count && !cancel; i = next++) {
      body(i);
      if (reportProgress(progress, from + (to - from) * static_cast<double>(done) / static_cast<double>(count),
                         "calibrate"))
        cancel = true;
    }
    for (auto& t : pool) t.join();
  };
  parallel(plan.size(), [&](std::size_t i) {
    references[i] = plan[i].reference;
    if (owner[i] != i || plan[i].reference) return;
    std::string problem;
    references[i] = referenceFor(plan[i], options, &problem);
    if (!references[i]) failures[i] = problem;
  }, 0.0, 0.2);
  for (std::size_t i = 0; i < plan.size(); ++i)
    if (!failures[owner[i]].empty())
      return finish(Termination::Failed, "a simulated arm could not be referenced: " + failures[owner[i]]);
    else if (!references[i])
      references[i] = references[owner[i]];
  std::vector<RunTrace> runs(plan.size());
  if (!cancel)
    parallel(plan.size(), [&](std::size_t i) {
      MonteCarloRun run = plan[i];
      run.reference = references[i];
      runs[i] = runOnce(run, options);
    }, 0.2, 1.0);
  if (cancel) return finish(Termination::Cancelled, "cancelled");
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (!failures[i].empty()) runs[i].message = failures[i];
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (!runs[i].ok) {
      const MonteCarloRun& m = plan[i];
      char what[200];
      std::snprintf(what, sizeof what, "run %zu (%s, %s, noise %.3g, seed %llu)", i + 1,
                    m.fault < 0 ? "fault-free"
                                : ("fault in " + options.parameters[static_cast<std::size_t>(m.fault)] +
                                   " at " + std::to_string(m.faultTimeS) + " s").c_str(),
                    m.conditions.note.c_str(), m.noiseScale, static_cast<unsigned long long>(m.seed));
      return finish(Termination::Failed, std::string(what) + " could not be diagnosed: " + runs[i].message);
    }
  for (const RunTrace& r : runs)
    if (r.mismatch) ++(r.fault < 0 ? result.healthyMismatches : result.faultyMismatches);

  for (const auto& r : runs) {
    (r.fault < 0 ? result.healthyRuns : result.faultyRuns) += 1;
    if (r.fault < 0 && !r.time.empty())
      result.healthyHours += std::max(0.0, r.time.back() - r.from + (r.time.size() > 1 ? r.time[1] - r.time[0] : 0.0)) / 3600.0;
  }
  // Thresholds of a set of tests over every run: false alarms, isolation and delays; the
  // alarms of each column on the fault-free runs go to *columnAlarms.
  const std::size_t faults = options.parameters.size();
  auto evaluate = [&](const std::vector<std::size_t>& which, const std::vector<std::vector<double>>& scales,
                      std::vector<double>* isolatedPerFault, std::vector<double>* delayPerFault,
                      std::vector<int>* columnAlarms) {
    CalibrationPoint point;
    std::vector<std::vector<double>> delays(faults);
    int isolated = 0, wrong = 0, faulty = 0;
    for (const auto& r : runs) {
      std::vector<const TestTrace*> traces;
      for (std::size_t k : which) traces.push_back(&r.traces[k]);
      const TestOutcome o = evaluateTests(traces, scales, r.time, result.faults, options.confirmS, r.from);
      if (r.fault < 0) {
        point.falseAlarms += o.detectionEvents;
        if (columnAlarms) {
          columnAlarms->resize(o.alarmEvents.size(), 0);
          for (std::size_t q = 0; q < o.alarmEvents.size(); ++q) (*columnAlarms)[q] += o.alarmEvents[q];
        }
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
        result.healthyHours > 0.0 ? poissonUpper95(point.falseAlarms) / result.healthyHours : kInf;
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

  // The false-alarm budget: the stated rate shared by the tests of the decision, then by a
  // test's columns.
  std::size_t deciding = 0;
  for (DiagnosisTest t : options.tests) deciding += options.decides(t) ? 1 : 0;
  std::vector<double> scales = calibration.scales.empty() ? defaultScales() : calibration.scales;
  std::sort(scales.begin(), scales.end());
  for (std::size_t k = 0; k < options.tests.size(); ++k) {
    TestCalibration tc;
    tc.test = options.tests[k];
    // The hypothesis and joint tests have one threshold for all their columns.
    const bool hypothesis = tc.test == DiagnosisTest::Hypothesis || tc.test == DiagnosisTest::Joint;
    const std::size_t columns = runs.front().traces[k].columns.size();
    const double testBudget = calibration.targetFalseAlarmsPerHour /
                              static_cast<double>(options.decides(tc.test) ? std::max<std::size_t>(1, deciding) : 1);
    const double columnBudget = hypothesis ? testBudget : testBudget / static_cast<double>(columns);
    std::vector<double> chosen(hypothesis ? 1 : columns, 0.0);
    for (double c : scales) {
      std::vector<int> alarms;
      CalibrationPoint p = evaluate({k}, {{c}}, nullptr, nullptr, &alarms);
      p.scale = c;
      p.threshold = c * designThreshold(tc.test, options);
      tc.curve.push_back(p);
      const double hours = std::max(result.healthyHours, 1e-12);
      if (hypothesis) {
        if (chosen[0] == 0.0 && p.falseAlarms / hours <= columnBudget) chosen[0] = c;
      } else {
        for (std::size_t q = 0; q < columns; ++q)
          if (chosen[q] == 0.0 && alarms[q] / hours <= columnBudget) chosen[q] = c;
      }
    }
    tc.met = std::all_of(chosen.begin(), chosen.end(), [](double c) { return c > 0.0; });
    for (double& c : chosen)
      if (c == 0.0) c = scales.back();
    tc.columnScales = chosen;
    for (std::size_t q = 0; q < chosen.size(); ++q)
      tc.thresholds.push_back(chosen[q] * designThreshold(tc.test, options) *
                              (hypothesis ? 1.0 : options.thresholdScale(tc.test, q)));
    tc.point = evaluate({k}, {chosen}, &tc.isolatedFraction, &tc.medianDelayS, nullptr);
    tc.point.scale = *std::max_element(chosen.begin(), chosen.end());
    tc.point.threshold = tc.thresholds.front();
    result.calibrated = withColumnScales(result.calibrated, tc.test, chosen);
    result.tests.push_back(tc);
  }

  // The decision over the calibrated thresholds.
  std::vector<std::size_t> which;
  std::vector<std::vector<double>> decisionScales;
  for (DiagnosisTest t : options.decision)
    for (std::size_t k = 0; k < options.tests.size(); ++k)
      if (options.tests[k] == t) {
        which.push_back(k);
        decisionScales.push_back(result.tests[k].columnScales);
      }
  result.decision = evaluate(which, decisionScales, &result.decisionIsolatedFraction,
                             &result.decisionMedianDelayS, nullptr);
  result.given = evaluate(which, std::vector<std::vector<double>>(which.size(), {1.0}),
                          &result.givenIsolatedFraction, &result.givenMedianDelayS, nullptr);
  char text[400];
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
  const double scale = matchNoiseScale(*reference.plant, *reference.plant, *conditions,
                                       reference.predictor, reference.noiseVariance, &note);
  CalibrationResult r = calibrateUnder(reference, *conditions, scale, options, calibration, progress);
  if (r.termination == Termination::Converged) r.conditions += "; " + note;
  return r;
}

}  // namespace flexarm
