#include "core/diagnosis/diagnosis.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace flexarm {

namespace {

std::string seconds2(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", t);
  return buf;
}

}  // namespace

DecisionStructure decisionStructure(DiagnosisTest test, const std::vector<std::string>& faults) {
  return test == DiagnosisTest::Hypothesis || test == DiagnosisTest::Joint
             ? DecisionStructure::hypothesis(faults)
             : DecisionStructure::parameters(faults);
}

TestOutcome evaluateTests(const std::vector<const TestTrace*>& traces,
                          const std::vector<std::vector<double>>& scales,
                          const std::vector<double>& time, const std::vector<std::string>& faults,
                          double confirmS, double from) {
  if (traces.size() != scales.size())
    throw std::invalid_argument("evaluateTests: one scale per trace expected");
  TestOutcome out;
  std::vector<DecisionStructure> structures;
  std::size_t columns = 0;
  for (const TestTrace* t : traces) {
    structures.push_back(decisionStructure(t->test, faults));
    if (structures.back().columns().size() != t->columns.size())
      throw std::invalid_argument("evaluateTests: the trace does not match its decision structure");
    const auto& sc = scales[structures.size() - 1];
    if (sc.size() != 1 && sc.size() != t->columns.size())
      throw std::invalid_argument("evaluateTests: one scale, or one per column, for each trace");
    columns += t->columns.size();
  }
  out.firstAlarm.assign(columns, std::nullopt);
  out.alarmEvents.assign(columns, 0);
  std::vector<char> firing(columns, 0);
  out.statement.reserve(time.size());
  VerdictTracker tracker(confirmS);
  bool detected = false;
  const ModeSet all = DecisionStructure::hypothesis(faults).allModes();
  std::vector<bool> fired;
  for (std::size_t k = 0; k < time.size(); ++k) {
    ModeSet s = all;
    const bool live = time[k] >= from - 1e-12;
    std::size_t c = 0;
    for (std::size_t j = 0; j < traces.size(); ++j) {
      const TestTrace& t = *traces[j];
      fired.assign(t.columns.size(), false);
      for (std::size_t q = 0; q < t.columns.size(); ++q, ++c) {
        const bool f = live && t.ratio[q][k] > scales[j][scales[j].size() == 1 ? 0 : q];
        fired[q] = f;
        if (f && !firing[c]) {
          ++out.alarmEvents[c];
          if (!out.firstAlarm[c]) out.firstAlarm[c] = time[k];
        }
        firing[c] = f;
      }
      s &= structures[j].diagnose(fired);
    }
    out.statement.push_back(s);
    const bool nowDetected = !(s & 1u);
    if (nowDetected && !detected) ++out.detectionEvents;
    detected = nowDetected;
    if (live) tracker.update(time[k], s);
  }
  out.verdict = tracker.verdict();
  out.verdictTime = tracker.verdictTime();
  out.detectionTime = tracker.detectionTime();
  return out;
}

std::string DiagnosisResult::verdictName() const {
  if (modelCheck.mismatch) return "model_mismatch";
  if (decision.verdict) return faults.at(*decision.verdict);
  return decision.detectionTime ? "detected" : "none";
}

std::optional<double> DiagnosisResult::verdictTime() const {
  if (modelCheck.mismatch) return modelCheck.time;
  return decision.verdict ? decision.verdictTime : decision.detectionTime;
}

std::vector<std::string> DiagnosisResult::namedByTests() const {
  std::vector<std::string> named;
  for (const auto& o : outcomes)
    if (o.verdict && std::find(named.begin(), named.end(), faults.at(*o.verdict)) == named.end())
      named.push_back(faults.at(*o.verdict));
  return named;
}

std::string DiagnosisResult::windowText() const {
  if (window == HypothesisWindow::Cumulative) return "cumulative (from the first sample, as the seed)";
  char buf[64];
  std::snprintf(buf, sizeof buf, "sliding, the last %.3g s", windowS);
  return buf;
}

const TestTrace* DiagnosisResult::trace(DiagnosisTest t) const {
  for (const auto& x : tests)
    if (x.test == t) return &x;
  return nullptr;
}

const TestOutcome* DiagnosisResult::outcome(DiagnosisTest t) const {
  for (std::size_t i = 0; i < tests.size(); ++i)
    if (tests[i].test == t && i < outcomes.size()) return &outcomes[i];
  return nullptr;
}

std::size_t DiagnosisResult::sampleAt(double t) const {
  if (time.empty() || t <= time.front()) return 0;
  const auto it = std::upper_bound(time.begin(), time.end(), t + 1e-9);
  return static_cast<std::size_t>(it - time.begin()) - 1;
}

std::string DiagnosisResult::summary() const {
  std::string s;
  if (modelCheck.mismatch)
    s = "Verdict: the model no longer fits: " + modelCheck.what + " (established at " +
        seconds2(*modelCheck.time) + ")" +
        (decision.verdict ? "; the tests' " + faults.at(*decision.verdict) + " is not reported as a fault." : ".");
  else if (decision.verdict)
    s = "Verdict: " + verdictName() + " changed, isolated at " + seconds2(*decision.verdictTime) + ".";
  else if (decision.detectionTime) {
    const std::vector<std::string> named = namedByTests();
    std::string names;
    for (const auto& n : named) names += (names.empty() ? "" : ", ") + n;
    s = "Verdict: detected: a change at " + seconds2(*decision.detectionTime) +
        " that the decision does not isolate to one parameter" +
        (named.empty() ? std::string(" (no test names one).")
                       : "; the tests on their own name " + names + ".");
  }
  else
    s = "Verdict: none (no fault detected).";
  std::string used;
  for (DiagnosisTest t : decisionTests) used += std::string(used.empty() ? "" : ", ") + toString(t);
  s += " Decision from the " + used + " test" + (decisionTests.size() > 1 ? "s" : "") +
       "; hypothesis window " + windowText() + ".";
  for (std::size_t i = 0; i < tests.size() && i < outcomes.size(); ++i) {
    const auto& o = outcomes[i];
    s += std::string(" ") + toString(tests[i].test) + ": ";
    if (o.verdict)
      s += faults[*o.verdict] + " at " + seconds2(*o.verdictTime);
    else if (o.detectionTime)
      s += "detection at " + seconds2(*o.detectionTime) + ", not isolated";
    else
      s += "no alarm";
    int events = 0;
    for (int e : o.alarmEvents) events += e;
    s += " (" + std::to_string(events) + " alarm" + (events == 1 ? "" : "s") + ").";
  }
  return s;
}

DiagnosisReference completeReference(const DiagnosisReference& reference,
                                     const DiagnosisSignals& monitored,
                                     const DiagnosisOptions& options) {
  DiagnosisReference ref = reference;
  if (!ref.ok()) return ref;
  const std::size_t n = options.parameters.size();
  if (ref.predictor != monitored.predictor)
    throw std::invalid_argument("diagnosis: the reference was fitted with the " +
                                std::string(toString(ref.predictor)) + " predictor, the log is read with the " +
                                toString(monitored.predictor) + " one");
  if (ref.noiseVariance <= 0.0 && options.estimator.noiseVariance <= 0.0) {
    ref.noiseVariance = quietestMeanSquare(outputErrors(*ref.nominal, monitored));
  }
  if (ref.p0.size() != n || ref.p0Single.size() != n) {
    if (!formInitialCovariances(ref, monitored, options, "the monitored log")) return ref;
  }
  ref.sigma0.resize(n, 0.0);
  return ref;
}

DiagnosisResult diagnoseSignals(const DiagnosisReference& reference, const DiagnosisSignals& data,
                                const DiagnosisOptions& options, const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("diagnosis: " + why);
  if (!reference.ok()) throw std::invalid_argument("diagnosis: the reference is not usable: " + reference.message);
  const auto begin = std::chrono::steady_clock::now();
  DiagnosisResult r;
  r.options = options;
  r.window = options.window;
  r.windowS = options.window == HypothesisWindow::Sliding ? options.windowS : 0.0;
  r.referenceSource = reference.source;
  for (DiagnosisTest t : options.decision)
    if (options.uses(t)) r.decisionTests.push_back(t);
  const DiagnosisReference ref = completeReference(reference, data, options);
  auto finish = [&](Termination t, std::string message) {
    r.termination = t;
    r.message = std::move(message);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    return r;
  };
  if (!ref.ok()) return finish(Termination::Failed, ref.message);

  DiagnosisMonitor monitor(ref, data, options);
  r.parameters = monitor.estimator().parameters();
  r.faults.clear();
  for (const auto& p : r.parameters) {
    r.faults.push_back(p.modelName);
    r.theta0.push_back(p.nominal);
  }
  r.sigma0 = ref.sigma0;
  r.noiseVariance = ref.noiseVariance;
  const auto names = monitor.columns();
  const std::size_t n = static_cast<std::size_t>(data.size());
  for (std::size_t k = 0; k < options.tests.size(); ++k) {
    TestTrace t;
    t.test = options.tests[k];
    t.columns = names[k];
    for (auto* v : {&t.statistic, &t.threshold, &t.ratio}) {
      v->assign(t.columns.size(), {});
      for (auto& c : *v) c.reserve(n);
    }
    r.tests.push_back(std::move(t));
  }
  const bool robust = options.uses(DiagnosisTest::Robust);
  if (robust) r.smoothed.assign(r.parameters.size(), {});
  r.estimates.reserve(n, r.parameters.size());
  r.time.reserve(n);

  Termination ending = Termination::Converged;
  std::string message;
  for (std::size_t i = 0; i < n; ++i) {
    const auto idx = static_cast<Eigen::Index>(i);
    const RecursiveStep& step = monitor.update(data.input(idx), data.output(idx));
    if (!monitor.ok()) {
      ending = Termination::Diverged;
      message = "a recursive estimator left its bounds at " + seconds2(data.timeAt(idx)) + ": " +
                monitor.estimator().message() + "; the diagnosis stops there";
      break;
    }
    r.time.push_back(step.time);
    r.estimates.append(step);
    const auto& samples = monitor.tests();
    for (std::size_t k = 0; k < samples.size(); ++k)
      for (std::size_t q = 0; q < samples[k].size(); ++q) {
        r.tests[k].statistic[q].push_back(samples[k][q].statistic);
        r.tests[k].threshold[q].push_back(samples[k][q].threshold);
        r.tests[k].ratio[q].push_back(samples[k][q].ratio);
      }
    if (robust) {
      const auto bar = monitor.smoothed();
      for (std::size_t p = 0; p < bar.size(); ++p) r.smoothed[p].push_back(bar[p]);
    }
    if (i % 500 == 0 && reportProgress(progress, static_cast<double>(i) / static_cast<double>(n), "diagnose"))
      return finish(Termination::Cancelled, "cancelled");
  }

  const double from = data.startTime + options.settleS;
  for (const auto& t : r.tests)
    r.outcomes.push_back(evaluateTests({&t}, {{1.0}}, r.time, r.faults, options.confirmS, from));
  std::vector<const TestTrace*> deciding;
  for (DiagnosisTest t : r.decisionTests) deciding.push_back(r.trace(t));
  r.decision = evaluateTests(deciding, std::vector<std::vector<double>>(deciding.size(), {1.0}),
                             r.time, r.faults, options.confirmS, from);
  if (options.checkModel && r.noiseVariance > 0.0 && !r.time.empty())
    r.modelCheck = checkModel(r.time, r.estimates.epsilon, data.input, r.noiseVariance, 1.0,
                              options.windowS, from, options.mismatchRatio, &r.fitRatio);
  if (ending == Termination::Converged) message = r.summary();
  return finish(ending, message);
}

DiagnosisResult diagnose(const DiagnosisReference& reference, const IdData& log,
                         const DiagnosisOptions& options, const ProgressCallback& progress) {
  std::string why;
  auto refuse = [&](const std::string& text) {
    DiagnosisResult r;
    r.options = options;
    r.message = "the log cannot be diagnosed: " + text;
    return r;
  };
  // Read as the reference was: the two predictors settle on different values.
  const auto data = diagnosisSignals(log, reference.predictor, &why);
  if (!data) return refuse(why);
  if (const double span = log.samples() > 1 ? (static_cast<double>(log.samples()) - 1.0) * log.sampleTime : 0.0;
      options.settleS >= span) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "no alarm is raised in the first %g s (the settling time), and the log lasts %g s", options.settleS, span);
    return refuse(buf);
  }
  // f_m compared at the monitored log's temperature.
  const LogTemperature monitored = logTemperature(log);
  if (!monitored.problem.empty() && !options.monitoredTemperatureC) return refuse(monitored.problem);
  DiagnosisReference ref = reference;
  if (options.referenceTemperatureC) ref.temperatureC = options.referenceTemperatureC;
  const TemperatureCorrection temperature = correctForTemperature(
      ref, options.monitoredTemperatureC ? options.monitoredTemperatureC : monitored.celsius, options.friction);
  DiagnosisResult r = diagnoseSignals(ref, *data, options, progress);
  r.temperature = temperature;
  if (r.termination == Termination::Converged) r.message += " Temperature: " + temperature.message + ".";
  return r;
}

}  // namespace flexarm
