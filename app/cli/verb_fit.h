#pragma once
// Shared by `flexarm fit` and `flexarm bode`: parsing a model specification, reading and
// preparing estimation and validation data, and fitting black-box or physical models.
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "core/ident/blackbox.h"
#include "core/ident/closed_loop_pem.h"
#include "core/ident/nonparametric.h"
#include "core/ident/pem.h"

namespace flexarm::cli {

// --- Physical models ----------------------------------------------------------------------
// Maps a physical structure name (two-mass, three-mass, four-mass, rigid) to a model with its
// nominal parameters. This is the one place where core/models is plugged into the verbs;
// it returns nullptr while no physical model is available in this build.
std::unique_ptr<ParametricModel> makePhysicalModel(const std::string& name);
bool isPhysicalModelName(const std::string& name);
// ------------------------------------------------------------------------------------------

// A parsed --model value: a polynomial structure with orders, or a physical structure name.
struct ModelSpec {
  bool physical = false;
  // Non-parametric estimate (bode only): "spa[:M]" or "etfe[:W]" with window width.
  bool nonparametric = false;
  bool spa = true;
  int windowWidth = 0;
  std::string physicalName;
  PolyStructure structure = PolyStructure::Arx;
  PolyOrders orders;
};
// Parses "arx:NA,NB,NK", "armax:NA,NB,NC,NK", "oe:NB,NF,NK", "bj:NB,NC,ND,NF,NK" or a
// physical name (and, when allowNonparametric, "spa[:M]" or "etfe[:W]"); false with a
// sentence on malformed text.
bool parseModelSpec(const std::string& text, ModelSpec& spec, std::string* why,
                    bool allowNonparametric = false);

// Option names and help shared by fit and bode.
std::vector<std::string> fitValuedOptionNames();
std::vector<std::string> fitFlagNames();
const char* fitOptionsHelp();

// Data and fitted model of one run.
struct FitOutcome {
  ModelSpec spec;
  double sampleTime = 1.0;
  Eigen::VectorXd uEst, yEst;  // means of the estimation data removed
  // Validation: the whole log holding the validation data (simulation starts at its first
  // sample, so no start-up transient enters the fit) and the range the fit is taken over.
  Eigen::VectorXd uVal, yVal;
  SampleRange validation;
  bool closedLoop = false;
  // Physical fits: how the closed loop was handled (two-stage when the log has a reference
  // channel, unless --closed-loop direct or --noise-model), and stage 1's fit % of the input.
  std::optional<ClosedLoopMethod> closedLoopMethod;
  std::optional<double> referenceFit;
  NonparametricEstimate nonparametric;  // when spec.nonparametric
  PolyEstimate poly;  // when a polynomial structure
  PemResult grey;     // when spec.physical
  const EstimateSummary& summary() const { return spec.physical ? grey.summary : poly.summary; }
  std::string modelName() const;
  Eigen::VectorXd simulate(const Eigen::VectorXd& u) const;
  // Fit % (5.2) on the validation range, or nullopt when there is none.
  std::optional<double> validationFit() const;
  FrequencyResponse response(const std::vector<double>& omega, double level) const;
};

// Reads LOG and the fit options, prepares the data and fits the model. Returns kExitOk or the
// exit code after printing a message prefixed by "flexarm VERB: ".
int prepareAndFit(ArgParser& args, const std::string& verb, FitOutcome& outcome,
                  std::ostream& err, bool allowNonparametric = false);

}  // namespace flexarm::cli
