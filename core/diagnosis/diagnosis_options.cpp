#include "core/diagnosis/diagnosis_options.h"

#include <algorithm>
#include <cmath>

namespace flexarm {

namespace {

bool failWith(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

bool contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

}  // namespace

const char* toString(DiagnosisTest t) {
  switch (t) {
    case DiagnosisTest::Classical: return "classical";
    case DiagnosisTest::Robust: return "robust";
    case DiagnosisTest::Cusum: return "cusum";
    case DiagnosisTest::Hypothesis: return "hypothesis";
    case DiagnosisTest::Joint: return "joint";
  }
  return "classical";
}

std::optional<DiagnosisTest> diagnosisTestFromString(std::string_view s) {
  for (DiagnosisTest t : allDiagnosisTests())
    if (s == toString(t)) return t;
  return std::nullopt;
}

const std::vector<DiagnosisTest>& allDiagnosisTests() {
  static const std::vector<DiagnosisTest> kAll = {DiagnosisTest::Classical, DiagnosisTest::Robust,
                                                  DiagnosisTest::Cusum, DiagnosisTest::Hypothesis,
                                                  DiagnosisTest::Joint};
  return kAll;
}

std::optional<std::vector<DiagnosisTest>> diagnosisTestsFromList(std::string_view list,
                                                                 std::string* why) {
  std::vector<DiagnosisTest> tests;
  std::size_t pos = 0;
  while (pos <= list.size()) {
    const std::size_t comma = std::min(list.find(',', pos), list.size());
    const std::string_view word = list.substr(pos, comma - pos);
    const auto t = diagnosisTestFromString(word);
    if (!t) {
      if (why)
        *why = "'" + std::string(word) + "' is not a test (classical, robust, cusum, hypothesis, joint)";
      return std::nullopt;
    }
    if (std::find(tests.begin(), tests.end(), *t) == tests.end()) tests.push_back(*t);
    pos = comma + 1;
  }
  return tests;
}

const char* toString(DiagnosisPredictor p) {
  switch (p) {
    case DiagnosisPredictor::Auto: return "auto";
    case DiagnosisPredictor::Loop: return "loop";
    case DiagnosisPredictor::Direct: return "direct";
  }
  return "auto";
}

std::optional<DiagnosisPredictor> diagnosisPredictorFromString(std::string_view s) {
  for (auto p : {DiagnosisPredictor::Auto, DiagnosisPredictor::Loop, DiagnosisPredictor::Direct})
    if (s == toString(p)) return p;
  return std::nullopt;
}

const char* toString(HypothesisWindow w) {
  return w == HypothesisWindow::Cumulative ? "cumulative" : "sliding";
}

std::optional<HypothesisWindow> hypothesisWindowFromString(std::string_view s) {
  for (HypothesisWindow w : {HypothesisWindow::Cumulative, HypothesisWindow::Sliding})
    if (s == toString(w)) return w;
  return std::nullopt;
}

DiagnosisOptions DiagnosisOptions::seed() {
  DiagnosisOptions o;
  o.predictor = DiagnosisPredictor::Direct;
  o.classicalK = o.robustK = 3.0;
  o.robustLambda = 0.995;
  o.cusumAlpha1 = 3.0;
  o.cusumAlpha2 = 20.0;
  o.hypothesisThreshold = 1.0;
  o.window = HypothesisWindow::Cumulative;
  o.classicalScales.clear();
  o.robustScales.clear();
  o.cusumScales.clear();
  o.confirmS = 0.0;
  o.settleS = 2.0;
  return o;
}

std::vector<double>* DiagnosisOptions::scales(DiagnosisTest t) {
  switch (t) {
    case DiagnosisTest::Classical: return &classicalScales;
    case DiagnosisTest::Robust: return &robustScales;
    case DiagnosisTest::Cusum: return &cusumScales;
    case DiagnosisTest::Hypothesis:
    case DiagnosisTest::Joint: return nullptr;
  }
  return nullptr;
}

double DiagnosisOptions::thresholdScale(DiagnosisTest t, std::size_t i) const {
  const auto* v = const_cast<DiagnosisOptions*>(this)->scales(t);
  return v && i < v->size() ? (*v)[i] : 1.0;
}

bool DiagnosisOptions::uses(DiagnosisTest t) const {
  return std::find(tests.begin(), tests.end(), t) != tests.end();
}

bool DiagnosisOptions::decides(DiagnosisTest t) const {
  return uses(t) && std::find(decision.begin(), decision.end(), t) != decision.end();
}

bool DiagnosisOptions::isValid(std::string* why) const {
  if (parameters.empty() || parameters.size() > 8)
    return failWith(why, "monitor 1 to 8 parameters");
  for (std::size_t i = 0; i < parameters.size(); ++i)
    for (std::size_t j = i + 1; j < parameters.size(); ++j)
      if (parameters[i] == parameters[j])
        return failWith(why, "the parameter " + parameters[i] + " is monitored twice");
  for (const auto& name : inverted)
    if (!contains(parameters, name))
      return failWith(why, "the inverted parameter " + name + " is not monitored");
  if (tests.empty()) return failWith(why, "choose at least one test");
  for (DiagnosisTest t : decision)
    if (!uses(t))
      return failWith(why, std::string("the decision uses the ") + toString(t) +
                               " test, which is not run");
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(classicalK) || !positive(robustK))
    return failWith(why, "the thresholds of the classical and robust tests must be > 0");
  if (!(robustLambda > 0.0 && robustLambda < 1.0))
    return failWith(why, "the robust test's forgetting factor must lie in (0, 1)");
  if (!(cusumAlpha1 >= 0.0) || !std::isfinite(cusumAlpha1) || !positive(cusumAlpha2))
    return failWith(why, "CUSUM: alpha_1 >= 0 and alpha_2 > 0");
  if (!positive(hypothesisThreshold))
    return failWith(why, "the hypothesis tests' threshold must be > 0");
  if (!positive(jointK) || !positive(jointScale))
    return failWith(why, "the joint test's k and scale must be > 0");
  if (!(mismatchRatio > 1.0) || !std::isfinite(mismatchRatio))
    return failWith(why, "the model mismatch ratio must be a number > 1");
  if (friction && !friction->isValid(why)) return false;
  for (const auto& t : {monitoredTemperatureC, referenceTemperatureC})
    if (t && !(std::isfinite(*t) && *t >= -50.0 && *t <= 250.0))
      return failWith(why, "a temperature must lie between -50 and 250 degC");
  if (window == HypothesisWindow::Sliding && !positive(windowS))
    return failWith(why, "the sliding window must be longer than 0 s");
  for (const auto* v : {&classicalScales, &robustScales, &cusumScales}) {
    if (!v->empty() && v->size() != parameters.size())
      return failWith(why, "threshold factors need one value per monitored parameter");
    for (double x : *v)
      if (!positive(x)) return failWith(why, "threshold factors must be > 0");
  }
  if (!(confirmS >= 0.0) || !std::isfinite(confirmS) || !(settleS >= 0.0) || !std::isfinite(settleS))
    return failWith(why, "the confirmation and settling times must be >= 0 s");
  RecursiveOptions e = estimatorOptions(*this, parameters);
  std::string bad;
  if (!e.isValid(&bad)) return failWith(why, "recursive estimator: " + bad);
  if (why) why->clear();
  return true;
}

RecursiveOptions estimatorOptions(const DiagnosisOptions& options,
                                  const std::vector<std::string>& parameters) {
  RecursiveOptions e = options.estimator;
  e.estimate = parameters;
  e.inverted.clear();
  for (const auto& name : parameters)
    if (contains(options.inverted, name)) e.inverted.push_back(name);
  // R1 of (6.54) follows the parameters when given for all of them.
  if (e.r1.size() == options.parameters.size() && parameters.size() != options.parameters.size()) {
    std::vector<double> r1;
    for (const auto& name : parameters)
      r1.push_back(e.r1[static_cast<std::size_t>(
          std::find(options.parameters.begin(), options.parameters.end(), name) -
          options.parameters.begin())]);
    e.r1 = r1;
  }
  e.startScale = 1.0;
  e.thetaStart.clear();
  e.p0.clear();
  e.updateParameters = true;
  return e;
}

}  // namespace flexarm
