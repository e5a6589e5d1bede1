#pragma once
// The sensitivity study of the seed's Section 5.3.3: how far each parameter's initial value
// may move before prediction-error fitting fails (the domain of attraction of Table 5.8, by
// interval halving), and Monte-Carlo fits from random initial values with their success rate
// (the seed: 649 of 1000). A fit succeeds when its loss is less than 5 % above the loss of the
// original identification. Fits run in parallel on std::threads.
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/pem.h"

namespace flexarm {

struct AttractionOptions {
  double successTolerance = 0.05;  // success: loss < (1 + tol) * reference loss
  double maxFactor = 200.0;        // largest upper factor tried (20000 %)
  double minFactor = 0.01;         // smallest lower factor tried for positive parameters
  int halvings = 8;                // interval-halving steps per limit
  int threads = 0;                 // 0: std::thread::hardware_concurrency()
  PemOptions pem;                  // one start per fit; noise model, iterations
  bool isValid(std::string* why) const;
};

// Limits of the initial value of one parameter as factors of its estimate (1.0 = 100 %).
struct ParameterAttraction {
  std::string name;
  double lowerFactor = 1.0, upperFactor = 1.0;
  bool lowerOpen = false, upperOpen = false;  // the search bound itself still succeeded
  int fits = 0;
};

struct AttractionResult {
  double referenceLoss = 0.0;
  std::vector<ParameterAttraction> parameters;  // free parameters, in model order
  Termination termination = Termination::Failed;
  std::string message;
  int fits = 0;
  double seconds = 0.0;
};

// Domain of attraction per free parameter of `estimated` (the original identification, whose
// values are the reference) by interval halving between a success and a failure (Table 5.8).
// Parameters whose lower bound is negative are searched linearly down to -maxFactor; others
// geometrically down to minFactor. Progress may be reported from worker threads.
AttractionResult domainOfAttraction(const ParametricModel& estimated, const Eigen::VectorXd& u,
                                    const Eigen::VectorXd& y, double sampleTime,
                                    const AttractionOptions& options = {},
                                    const ProgressCallback& progress = {});

struct MonteCarloOptions {
  int runs = 1000;
  double regionFraction = 0.2;  // initial factors drawn in [1 + f (lower - 1), 1 + f (upper - 1)]
  double successTolerance = 0.05;
  unsigned seed = 1;
  int threads = 0;
  PemOptions pem;
  bool isValid(std::string* why) const;
};

struct MonteCarloResult {
  int runs = 0, completed = 0, successes = 0;
  double referenceLoss = 0.0;
  std::vector<double> losses;  // per run (NaN when not run or failed)
  std::vector<bool> success;
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  double successRate() const { return completed ? static_cast<double>(successes) / completed : 0.0; }
};

// Monte-Carlo fits from random initial values of all free parameters at once, drawn from the
// region given by `region` (Table 5.8 limits, shrunk by regionFraction), as in Section 5.3.3.
MonteCarloResult monteCarloStarts(const ParametricModel& estimated, const Eigen::VectorXd& u,
                                  const Eigen::VectorXd& y, double sampleTime,
                                  const AttractionResult& region,
                                  const MonteCarloOptions& options = {},
                                  const ProgressCallback& progress = {});

}  // namespace flexarm
