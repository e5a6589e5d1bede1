#pragma once
// Monte-Carlo calibration of the diagnosis thresholds on the simulator. The recursive
// estimates are strongly autocorrelated (the estimator forgets with lambda = 0.995, a memory of
// 200 samples), so thresholds from formulas for independent samples ("3 sigma") do not say how
// often a healthy axis raises an alarm. Here the arm (the reference's plant) is simulated many
// times under the monitored log's conditions (its controller, rate, length and reference, and
// the fault-free log's noise level, simulate_like.h): fault-free runs give each test's false
// alarms per hour as a function of its threshold, runs with a fault stepping in give the
// detection delay (the time from the step to the correct isolation). Each run goes through the
// whole pipeline: theta_0 is fitted on a fault-free simulated run as on the real log, so that
// closed-loop bias is reproduced as well.
//
// A test's threshold is scaled by c (the classical and robust 3 sigma by c, the CUSUM's h by c,
// the hypothesis threshold 1 by c); the calibrated threshold is the smallest c on the grid
// whose false-alarm rate on the fault-free runs does not exceed the stated rate, chosen for
// each parameter of a test on its own (TestCalibration). The rate is estimated from a few
// hours of simulated time, so its 95 % upper bound is given beside it.
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/reference.h"
#include "core/diagnosis/simulate_like.h"

namespace flexarm {

struct CalibrationOptions {
  static constexpr int kMaxRuns = 100000;
  // The memory all runs of a calibration may hold together (their conditions and statistics):
  // a request for more runs than fit is refused before any run is set up.
  static constexpr double kMaxCalibrationBytes = 4.0e9;
  int healthyRuns = 40;      // fault-free runs
  int faultyRuns = 8;        // runs per monitored parameter with a fault stepping in
  double faultSize = 0.2;    // the monitored quantity (theta's form: J_a^-1) rises by this part
  double faultTimeS = 0.0;   // when the fault steps in; 0: the middle of the run
  double durationS = 0.0;    // length of a run; 0: the log's
  double horizonS = 5.0;     // a fault isolated later than this after its step counts as missed
  double targetFalseAlarmsPerHour = 1.0;
  // Threshold scales c tried for every test (empty: 64 values from 0.1 to 10, log-spaced).
  std::vector<double> scales;
  int threads = 2;
  std::uint64_t seed = 1;
  bool isValid(std::string* why) const;
};

// One threshold of one test.
struct CalibrationPoint {
  double scale = 1.0;      // c
  double threshold = 0.0;  // c times the test's design value (k, alpha_2, or the level 1)
  int falseAlarms = 0;     // detections on the fault-free runs
  double falseAlarmsPerHour = 0.0;
  double falseAlarmsPerHourUpper = 0.0;  // 95 % upper bound (Poisson)
  double isolatedFraction = 0.0;  // faulty runs isolated correctly within the horizon
  double wrongFraction = 0.0;     // faulty runs whose verdict names another parameter
  double medianDelayS = 0.0;      // of the correct isolations within the horizon (NaN: none)
  double p95DelayS = 0.0;
};

struct TestCalibration {
  DiagnosisTest test = DiagnosisTest::Classical;
  std::vector<CalibrationPoint> curve;  // one scale c for every column, c increasing
  // The calibrated thresholds: the false-alarm budget of the test (the stated rate shared
  // evenly by the tests of the decision) is shared evenly by its columns (the parameters;
  // the hypothesis tests have one threshold), and each column gets the smallest c on the grid
  // that keeps within its share. met: every column found one (else the largest c is kept).
  bool met = false;
  std::vector<double> columnScales;  // per column (one value for the hypothesis tests)
  std::vector<double> thresholds;    // the same in the test's units: k, alpha_2, or the level
  CalibrationPoint point;            // the test at those thresholds
  // Per fault (monitored parameter) at those thresholds: isolated fraction and median delay.
  std::vector<double> isolatedFraction, medianDelayS;
};

struct CalibrationResult {
  Termination termination = Termination::Failed;
  std::string message;
  // Failed because the request asks for more than the budget (too many runs for the log's
  // length), not because a run failed.
  bool badRequest = false;
  double seconds = 0.0;
  int healthyRuns = 0, faultyRuns = 0;  // completed
  double healthyHours = 0.0;            // simulated fault-free time after settling
  // Runs the model check (model_check.h) called a mismatch: none should be, the simulated arm
  // is the model's own structure.
  int healthyMismatches = 0, faultyMismatches = 0;
  double noiseScale = 1.0;
  std::string conditions;               // what was simulated, in words
  std::vector<std::string> faults;      // the monitored parameters' model names
  std::vector<TestCalibration> tests;   // in options.tests order
  // The options with every test's calibrated threshold (tests without one keep theirs), and
  // the decision over options.decision at those thresholds.
  DiagnosisOptions calibrated;
  CalibrationPoint decision;
  std::vector<double> decisionIsolatedFraction, decisionMedianDelayS;  // per fault
  // The decision at the options' own thresholds (as given, before calibrating): how the
  // thresholds in use fare on these runs.
  CalibrationPoint given;
  std::vector<double> givenIsolatedFraction, givenMedianDelayS;  // per fault
};

// The 95 % upper confidence bound of a Poisson mean after `events` events (the bound beside
// every false-alarm rate); throws std::invalid_argument for a negative count.
double poissonUpper95(int events);

// The design value a scale multiplies (k of the classical or robust test, alpha_2, the
// hypothesis threshold) and the options with a test's threshold set to scale times it.
double designThreshold(DiagnosisTest test, const DiagnosisOptions& options);
DiagnosisOptions withThresholdScale(const DiagnosisOptions& options, DiagnosisTest test, double scale);
// The options with a test's thresholds multiplied per column (parameter tests: one factor per
// monitored parameter; hypothesis tests: one factor).
DiagnosisOptions withColumnScales(const DiagnosisOptions& options, DiagnosisTest test,
                                  const std::vector<double>& scales);

// Runs the calibration for the reference's plant under the conditions of `log`. Data failures
// (a log that cannot be simulated again, a simulated run the pipeline cannot fit) end as Failed
// with a sentence; invalid options throw std::invalid_argument; Abort gives Cancelled.
CalibrationResult calibrate(const DiagnosisReference& reference, const IdData& log,
                            const DiagnosisOptions& options, const CalibrationOptions& calibration,
                            const ProgressCallback& progress = {});

// The same for given conditions and noise scale.
CalibrationResult calibrateUnder(const DiagnosisReference& reference, const LogConditions& conditions,
                                 double noiseScale, const DiagnosisOptions& options,
                                 const CalibrationOptions& calibration,
                                 const ProgressCallback& progress = {});

// One simulated run of a Monte-Carlo study: an arm, its conditions and noise, a seed, and the
// fault that steps in (none: fault < 0). Without a reference, theta_0 is fitted on a fault-free
// run of the same arm under the same conditions (seed referenceSeed), as on a real axis.
struct MonteCarloRun {
  std::shared_ptr<const PhysicalModel> plant;
  LogConditions conditions;
  double noiseScale = 1.0;
  std::uint64_t seed = 1, referenceSeed = 0;
  int fault = -1;         // index into DiagnosisOptions::parameters
  double faultSize = 0.2; // the monitored quantity (theta's form) rises by this part
  double faultTimeS = 0.0;
  double durationS = 0.0; // 0: the conditions'
  std::shared_ptr<const DiagnosisReference> reference;
};

// Runs every run through the whole pipeline and evaluates the tests over the threshold scales
// of `calibration` (its run counts, fault size and times are not used: the runs say them).
// Conditions, noise scale and counts in the result describe the runs only in general terms.
CalibrationResult monteCarlo(const std::vector<MonteCarloRun>& runs, const DiagnosisOptions& options,
                             const CalibrationOptions& calibration,
                             const ProgressCallback& progress = {});

}  // namespace flexarm
