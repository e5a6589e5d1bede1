#pragma once
// What a diagnosis (the seed's chapter 7) is asked to do: which parameters are monitored
// (each one a fault: k_T, J_a^-1, f_m, Section 7.2), how they are estimated (the recursive
// estimator of chapter 6), which tests run and their design variables, and which tests the
// decision structure of Section 7.5.2 combines into a verdict.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnosis/friction_temperature.h"
#include "core/recursive/rpem.h"

namespace flexarm {

// The tests of chapter 7.
//  Classical:  T_i = theta_i - theta_0,i against 3 sqrt(sigma_i^2 + sigma_0,i^2), sigma_i from
//              lambda_0 P_ii ((7.4), (7.7)-(7.9)).
//  Robust:     the smoothed estimate and its spread over a window ((7.12)-(7.14)).
//  Cusum:      two-sided CUSUM (7.1) of theta_i - theta_0,i with drift nu = alpha_1 sigma_i
//              and threshold h = alpha_2 theta_0,i ((7.15)-(7.17)).
//  Hypothesis: a bank of predictors, one per fault hypothesis, and the normalised sums of
//              squared prediction errors ((7.18)-(7.21)).
//  Joint:      the change vector of every monitored parameter at once against its full
//              covariance (chi-square), isolated by its direction (parameter_tests.h).
enum class DiagnosisTest { Classical, Robust, Cusum, Hypothesis, Joint };
const char* toString(DiagnosisTest t);  // "classical", "robust", "cusum", "hypothesis", "joint"
std::optional<DiagnosisTest> diagnosisTestFromString(std::string_view s);
const std::vector<DiagnosisTest>& allDiagnosisTests();
// "classical,robust" -> the tests; nullopt with a sentence naming a word that is not a test.
std::optional<std::vector<DiagnosisTest>> diagnosisTestsFromList(std::string_view list,
                                                                 std::string* why);

// The window of the hypothesis tests' sums: from the first sample on (the seed's (7.18)-(7.21),
// "only for evaluation"), or the last windowS seconds (on-line use, Section 7.5.2).
enum class HypothesisWindow { Cumulative, Sliding };
const char* toString(HypothesisWindow w);  // "cumulative", "sliding"
std::optional<HypothesisWindow> hypothesisWindowFromString(std::string_view s);

// What the recursive estimators predict (see diagnosis_data.h):
//  Direct: the motor velocity from the torque reference, as the seed (Section 6.1);
//  Loop:   the motor angle from the position reference through the log's controller
//          (loop_model.h), free of closed-loop bias;
//  Auto:   Loop when the log has a reference channel and names its controller, else Direct.
enum class DiagnosisPredictor { Auto, Loop, Direct };
const char* toString(DiagnosisPredictor p);  // "auto", "loop", "direct"
std::optional<DiagnosisPredictor> diagnosisPredictorFromString(std::string_view s);

struct DiagnosisOptions {
  // The monitored parameters, by the model's names, each standing for one fault; those in
  // `inverted` are estimated as inverses (the seed's J_a^-1).
  std::vector<std::string> parameters = {"k_T", "J_a", "f_m"};
  std::vector<std::string> inverted = {"J_a"};
  // The recursive estimator (chapter 6). Its `estimate`, `inverted`, `startScale` and
  // `thetaStart` are set by the diagnosis (theta(0) = theta_0); the rest is used as given
  // (seed: forgetting factor, lambda = 0.995; P(0) from the reference's pre-run).
  RecursiveOptions estimator;
  DiagnosisPredictor predictor = DiagnosisPredictor::Auto;

  std::vector<DiagnosisTest> tests = allDiagnosisTests();  // computed and reported
  // The tests whose alarms the decision structure combines into the verdict (a subset of
  // `tests`). The classical test is left out by default: its false alarms (Figure 7.1) are
  // what the robustified tests remove.
  std::vector<DiagnosisTest> decision = {DiagnosisTest::Robust, DiagnosisTest::Cusum,
                                         DiagnosisTest::Hypothesis};

  // The thresholds. The seed's design values (3 sigma, alpha_1 = 3, alpha_2 = 20, level 1 over
  // the cumulative window; seed() gives them) scaled per parameter as bench/montecarlo_diagnosis
  // calibrated them on designed experiments (Section 6.6.2) of randomly drawn arms, with a
  // margin over the largest excursion of the fault-free runs; the classical test keeps the
  // seed's 3 sigma, whose false alarms (Figure 7.1) are what the others remove.
  double classicalK = 3.0;     // the 3 of (7.3)/(7.7)
  double robustLambda = 0.995; // the lambda of (7.12)/(7.13) (seed: that of the estimator)
  double robustK = 3.0;        // the 3 of the robust threshold 3 sigma (Figure 7.2)
  double cusumAlpha1 = 3.0;    // (7.15) (seed: 3)
  double cusumAlpha2 = 20.0;   // (7.17) (seed: 20)
  double hypothesisThreshold = 1.12;  // the seed's 1, "a natural choice after normalisation"
  // The joint test's k: its chi-square is compared with the quantile of p degrees of freedom
  // at the probability of k sigma (JointTest), times jointScale, which bench/
  // montecarlo_diagnosis calibrated for one false alarm per hour (1.86: the chi-square of the
  // smoothed change is autocorrelated as the estimates are).
  double jointK = 3.0;
  double jointScale = 1.86;
  HypothesisWindow window = HypothesisWindow::Sliding;  // on-line use (seed: cumulative)
  double windowS = 5.0;        // length of the sliding window, s
  // Per-parameter factors on the thresholds of the classical, robust and CUSUM tests, one per
  // monitored parameter (empty: 1 for each), as the calibration chooses them: the seed's
  // h = alpha_2 theta_0 (7.17) is in the parameter's own units, so one alpha_2 does not give
  // every parameter the same false-alarm rate. The defaults are for k_T, J_a (as J_a^-1), f_m.
  std::vector<double> classicalScales;
  std::vector<double> robustScales = {2.0, 1.0, 1.8};
  std::vector<double> cusumScales = {0.2, 0.27, 1.25};
  // A diagnosis statement must hold this long before it becomes the verdict (0: at once).
  double confirmS = 0.0;
  // No alarm is raised before this time: the start-up transient of the estimators and of the
  // hypothesis sums (the seed: "in the first few seconds there is a transient behavior"), s.
  double settleS = 2.0;

  // Under-modelling (model_check.h): the verdict is model_mismatch, not a parameter, when the
  // mean square over a second of the errors of the estimator of every monitored parameter
  // stays above mismatchRatio times lambda_0 for windowS seconds.
  bool checkModel = true;
  double mismatchRatio = 2.0;

  // Temperature (diagnosis_temperature.h): the friction model that carries theta_0's f_m to
  // the monitored log's temperature (none: f_m is compared as fitted), and the temperatures
  // of the monitored and the reference log when the logs do not state them.
  std::optional<FrictionTemperatureModel> friction;
  std::optional<double> monitoredTemperatureC, referenceTemperatureC;

  // The seed's design: the direct predictor, 3 sigma, the robust test's lambda 0.995, alpha_1 = 3,
  // alpha_2 = 20, the hypothesis level 1 over the cumulative window, every test in the decision
  // but the classical one, a two-second settling time.
  static DiagnosisOptions seed();
  // The factor on test t's threshold for monitored parameter i (1 for the hypothesis tests).
  double thresholdScale(DiagnosisTest t, std::size_t i) const;
  std::vector<double>* scales(DiagnosisTest t);
  bool uses(DiagnosisTest t) const;
  bool decides(DiagnosisTest t) const;
  bool isValid(std::string* why) const;
};

// The recursive estimator's options for a subset of the monitored parameters (all of them for
// the classical tests, one for a hypothesis F_i, none for NF): options.estimator with that
// `estimate`, the matching `inverted`, theta(0) at the nominal values and P(0) left to the
// caller.
RecursiveOptions estimatorOptions(const DiagnosisOptions& options,
                                  const std::vector<std::string>& parameters);

}  // namespace flexarm
