#pragma once
// The fault-free reference a diagnosis compares with (the seed's Sections 6.5 and 7.5: "the
// nominal parameters are estimated using the off-line identification procedure", on another
// data set than the one diagnosed).
//
// theta_0 is the output-error fit (FlexArm's prediction-error fit, pem) of the physical model
// inside the diagnosis' predictor (diagnosis_data.h) on a fault-free log: the criterion the
// recursive estimator minimises sample by sample, so that on a healthy axis its estimates
// scatter around theta_0 even where the predictor is biased. With the direct predictor of the
// seed, closed-loop data bias both alike ((4.43); on the sample logs the direct fit puts f_m
// near 0.075 for a true 0.0355); the loop predictor is free of that bias. The Monte-Carlo
// calibration needs the arm itself, so the two-stage closed-loop fit (when the log has a
// reference) is kept beside theta_0 as the plant to simulate.
//
// From a model instead of a log (a model of the list, typed values): the model is the plant,
// and theta_0 is fitted as above on a fault-free run of it simulated under the monitored log's
// controller and reference (diagnosis/simulate_like.h); without those, theta_0 is the model
// itself and a sentence says that closed-loop bias then shows as a deviation.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/diagnosis/diagnosis_data.h"
#include "core/diagnosis/diagnosis_options.h"
#include "core/models/physical_models.h"

namespace flexarm {

struct DiagnosisReference {
  Termination termination = Termination::Failed;
  std::string message;  // how it was made, or why it could not be
  double seconds = 0.0;

  // theta_0: the plant the estimators run with (inside the predictor); its monitored values
  // are the tests' centre.
  std::shared_ptr<const PhysicalModel> nominal;
  // The predictor theta_0 was fitted with (Loop or Direct): the monitored log is read the same
  // way, since the two settle on different values.
  DiagnosisPredictor predictor = DiagnosisPredictor::Direct;
  // The arm the calibration simulates.
  std::shared_ptr<const PhysicalModel> plant;
  // Standard deviation of theta_0,i per monitored parameter in the estimator's form (J_a^-1),
  // from the fit's covariance (7.4); 0 where the fit held the parameter (k_T).
  std::vector<double> sigma0;
  // lambda_0: mean squared output error of theta_0 on the fault-free data (0: not known); the
  // calibration simulates the plant at the noise level that gives the same.
  double noiseVariance = 0.0;
  // diag P(0) of the estimator of every monitored parameter and of each one alone (the bank of
  // Section 7.5.2), from the seed's pre-run (Section 6.6.2) on the fault-free data; empty: to be
  // formed on the monitored log.
  std::vector<double> p0;
  std::vector<double> p0Single;
  std::string source;  // one sentence: where theta_0 came from
  // The fault-free log's temperature (its temperature_c channel or metadata; none when it
  // says nothing, or the reference is a model), degC: what theta_0's f_m refers to.
  std::optional<double> temperatureC;

  bool ok() const { return termination == Termination::Converged && nominal != nullptr; }
};

struct ReferenceOptions {
  int maxIterations = 60;  // of each fit
  bool fitPlant = true;    // also the closed-loop fit of the plant (for the calibration)
  bool isValid(std::string* why) const;
};

// The fit of the physical model `start` (its free flags say what is fitted) as the diagnosis
// uses it: output error of the predictor (input to output) for theta_0, or two-stage on
// (u, velocity, r) for the plant. This is the one place the diagnosis calls FlexArm's fit.
// Data failures end as Failed with a sentence.
struct NominalFit {
  Termination termination = Termination::Failed;
  std::string message;
  std::shared_ptr<const PhysicalModel> model;
  std::vector<std::string> freeNames;
  Eigen::MatrixXd covariance;  // of the free parameters, freeNames order
  double loss = 0.0;           // mean squared output error on the data
};
NominalFit fitNominalModel(const PhysicalModel& start, const DiagnosisSignals& data, bool closedLoop,
                           int maxIterations, const ProgressCallback& progress = {});

// The reference from fault-free signals (a log's, or a simulated run's).
DiagnosisReference referenceFromSignals(const PhysicalModel& start, const DiagnosisSignals& healthy,
                                        const DiagnosisOptions& options,
                                        const ReferenceOptions& referenceOptions = {},
                                        const ProgressCallback& progress = {});
// The reference from a fault-free log; a log the diagnosis cannot use is a Failed reference
// with a sentence.
DiagnosisReference referenceFromLog(const PhysicalModel& start, const IdData& healthy,
                                    const DiagnosisOptions& options,
                                    const ReferenceOptions& referenceOptions = {},
                                    const ProgressCallback& progress = {});
// The reference from a model believed fault-free, with the monitored log's controller and
// reference signal to simulate it (see above).
DiagnosisReference referenceFromModel(const PhysicalModel& model, const IdData& monitored,
                                      const DiagnosisOptions& options,
                                      const ReferenceOptions& referenceOptions = {},
                                      const ProgressCallback& progress = {});

// The seed's way of making a fault out of fault-free data (Section 7.5: "to simulate a fault the
// initial value of the faulty parameter is changed"): theta_0 of one monitored parameter, in
// the estimator's form (J_a^-1), multiplied by `factor` (1.2 for the seed's 20 %), so that the
// estimates on the data settle 1/factor off it. Throws std::invalid_argument for a name that is
// not monitored or a value the model refuses.
DiagnosisReference withSeedFault(const DiagnosisReference& reference, const DiagnosisOptions& options,
                                 const std::string& name, double factor);

// P(0) as the seed forms it (Section 6.6.2) on `data`, into ref.p0 (every monitored parameter
// together) and ref.p0Single (each one alone). False, with ref.termination Failed and a
// message naming `where`, when a covariance cannot be formed.
bool formInitialCovariances(DiagnosisReference& ref, const DiagnosisSignals& data,
                            const DiagnosisOptions& options, const std::string& where);

// Output error of the plant inside the signals' predictor (simulated from the input).
Eigen::VectorXd outputErrors(const PhysicalModel& model, const DiagnosisSignals& data);
// The mean square of e over its quietest quarter: the noise level of a log in which a fault
// may raise the error over part of the time.
double quietestMeanSquare(const Eigen::VectorXd& e);

}  // namespace flexarm
