#pragma once
// Fault detection and isolation from recursive estimates of physical parameters (the seed's
// chapter 7): the recursive estimator of chapter 6 follows the monitored parameters (k_T,
// J_a^-1, f_m) of a log, the tests of Sections 7.4-7.5 compare them with the fault-free
// reference theta_0, and the decision structure of Section 7.5.2 turns the tests' alarms into
// a diagnosis statement S and a verdict: the parameter that changed, and when that was known.
//
// One implementation, several users: DiagnosisMonitor is fed one sample at a time (on-line
// use); diagnose() runs it over a whole log and keeps every statistic for plots, the command
// line, the panel (which shows the result up to its playhead), sessions and the calibration,
// which re-evaluates the same traces at other thresholds (evaluateTest).
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/diagnosis/decision.h"
#include "core/diagnosis/diagnosis_data.h"
#include "core/diagnosis/diagnosis_options.h"
#include "core/diagnosis/diagnosis_temperature.h"
#include "core/diagnosis/model_check.h"
#include "core/diagnosis/parameter_tests.h"
#include "core/diagnosis/reference.h"
#include "core/recursive/rpem.h"

namespace flexarm {

// What one test computed over a run, one column per test quantity: the monitored parameters
// (theta's names: k_T, J_a^-1, f_m) for the classical, robust and CUSUM tests, T_NF and T_i for
// the hypothesis tests. ratio = |statistic| / threshold: the column fires where ratio > 1, and
// at a threshold scaled by c where ratio > c.
struct TestTrace {
  DiagnosisTest test = DiagnosisTest::Classical;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> statistic, threshold, ratio;  // [column][sample]
};

// What a test (or the decision of several) concluded.
struct TestOutcome {
  std::vector<ModeSet> statement;               // S at each sample
  std::vector<std::optional<double>> firstAlarm;  // per column: first time it fired
  std::vector<int> alarmEvents;                 // per column: how often it started to fire
  int detectionEvents = 0;                      // how often NF left S
  std::optional<std::size_t> verdict;           // index into the faults
  std::optional<double> verdictTime, detectionTime;
};

// The decision structure of a test: Section 7.5.2's for the hypothesis tests, one column per
// parameter for the others (decision.h).
DecisionStructure decisionStructure(DiagnosisTest test, const std::vector<std::string>& faults);

// S of each sample from the columns of the traces that fire at their threshold times `scales`
// (per trace one factor per column, or a single one for every column; the intersection of the
// tests' statements when there are several), with no alarm before `from` (s), and the verdict
// reached with confirmS (decision.h).
TestOutcome evaluateTests(const std::vector<const TestTrace*>& traces,
                          const std::vector<std::vector<double>>& scales,
                          const std::vector<double>& time, const std::vector<std::string>& faults,
                          double confirmS, double from);

struct DiagnosisResult {
  Termination termination = Termination::Failed;
  std::string message;  // how it ran, or why it could not
  double seconds = 0.0;

  std::vector<double> time;                     // s, one per sample
  std::vector<RecursiveParameter> parameters;   // the monitored parameters, theta's form
  std::vector<std::string> faults;              // their model names: k_T, J_a, f_m
  std::vector<double> theta0, sigma0;           // theta's form
  double noiseVariance = 0.0;                   // lambda_0 of (7.8)
  RecursiveTrajectory estimates;                // of every monitored parameter
  std::vector<std::vector<double>> smoothed;    // theta_bar (7.12), when the robust test ran
  std::vector<TestTrace> tests;                 // in options.tests order
  std::vector<TestOutcome> outcomes;            // each test on its own, same order
  std::vector<DiagnosisTest> decisionTests;
  TestOutcome decision;                         // the decision structure over decisionTests
  HypothesisWindow window = HypothesisWindow::Cumulative;
  double windowS = 0.0;
  DiagnosisOptions options;                     // as run (thresholds, window)
  std::string referenceSource;
  // Under-modelling: R(t) of the estimator of every parameter (model_check.h) and the check.
  std::vector<double> fitRatio;
  ModelCheck modelCheck;
  // What the temperatures did to theta_0's f_m (diagnose() from a log; empty otherwise).
  TemperatureCorrection temperature;

  // "none", the changed parameter's model name (k_T, J_a, f_m), "detected" when the decision
  // detected a change but isolated no single parameter (a fault of two parameters, or one the
  // tests disagree on: a detection is never reported as none), or "model_mismatch" when the
  // model no longer fits the data (then no parameter is named).
  std::string verdictName() const;
  // When the verdict was reached (the detection's time for detected, the mismatch's for
  // model_mismatch), if it was.
  std::optional<double> verdictTime() const;
  // The parameters the tests name on their own (each test's verdict), in test order, once each:
  // what a detected change points at.
  std::vector<std::string> namedByTests() const;
  // "cumulative (from the first sample, as the seed)" or "sliding, the last 5 s".
  std::string windowText() const;
  // The trace and outcome of a test, or nullptr when it did not run.
  const TestTrace* trace(DiagnosisTest t) const;
  const TestOutcome* outcome(DiagnosisTest t) const;
  // The sample at time t (the last one at or before it; 0 before the first).
  std::size_t sampleAt(double t) const;
  // A few sentences: the verdict and its time, each test's alarms.
  std::string summary() const;
};

// A diagnosis fed one sample at a time.
class DiagnosisMonitor {
 public:
  // The reference must be ok() with P(0) (p0, p0Single) and lambda_0 (or the estimator's own
  // noiseVariance) set; throws std::invalid_argument otherwise or for invalid options. Of the
  // signals only the predictor, its controller, the sample time and the start time are used:
  // update() is then fed their input and output sample by sample.
  DiagnosisMonitor(const DiagnosisReference& reference, const DiagnosisSignals& data,
                   const DiagnosisOptions& options);
  ~DiagnosisMonitor();
  DiagnosisMonitor(const DiagnosisMonitor&) = delete;
  DiagnosisMonitor& operator=(const DiagnosisMonitor&) = delete;

  // Processes one sample: returns the estimate; tests() holds each test's verdict on it.
  const RecursiveStep& update(double u, double y);
  // [test in options.tests order][column] for the last sample.
  const std::vector<std::vector<TestSample>>& tests() const;
  // The columns of each test (TestTrace::columns).
  std::vector<std::vector<std::string>> columns() const;
  const RecursiveEstimator& estimator() const;
  // theta_bar of the robust test for each parameter (empty when it does not run).
  std::vector<double> smoothed() const;
  bool ok() const;  // every estimator still inside its bounds

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Forms what the reference lacks (P(0), lambda_0) on the monitored signals, as the seed does
// when it has no other data: P(0) by the pre-run (6.6.2), lambda_0 the mean squared output
// error of theta_0 on the quietest quarter of the log.
DiagnosisReference completeReference(const DiagnosisReference& reference,
                                     const DiagnosisSignals& monitored,
                                     const DiagnosisOptions& options);

// Runs the diagnosis over a whole log. Data failures (unusable signals, an estimator that
// leaves its bounds) are Failed or Diverged with a sentence (a diverged run keeps what it
// computed until then); invalid options or a reference that is not ok() throw
// std::invalid_argument; Abort gives Cancelled.
DiagnosisResult diagnose(const DiagnosisReference& reference, const IdData& log,
                         const DiagnosisOptions& options, const ProgressCallback& progress = {});
DiagnosisResult diagnoseSignals(const DiagnosisReference& reference, const DiagnosisSignals& data,
                                const DiagnosisOptions& options,
                                const ProgressCallback& progress = {});

}  // namespace flexarm
