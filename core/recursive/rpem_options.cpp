// Names, option checks and the trajectory container of the recursive estimator.
#include <cmath>
#include <limits>

#include "core/recursive/rpem.h"
#include "core/recursive/theta.h"

namespace flexarm {

const char* toString(RecursiveAlgorithm a) {
  return a == RecursiveAlgorithm::Kalman ? "kalman" : "forgetting";
}
std::optional<RecursiveAlgorithm> recursiveAlgorithmFromString(std::string_view s) {
  for (auto a : {RecursiveAlgorithm::ForgettingFactor, RecursiveAlgorithm::Kalman})
    if (s == toString(a)) return a;
  return std::nullopt;
}

const char* toString(RecursiveGradient g) {
  return g == RecursiveGradient::Difference ? "difference" : "sensitivity";
}
std::optional<RecursiveGradient> recursiveGradientFromString(std::string_view s) {
  for (auto g : {RecursiveGradient::Sensitivity, RecursiveGradient::Difference})
    if (s == toString(g)) return g;
  return std::nullopt;
}

const char* toString(RecursiveTracking t) {
  switch (t) {
    case RecursiveTracking::Variable: return "variable";
    case RecursiveTracking::Bank: return "bank";
    default: return "fixed";
  }
}
std::optional<RecursiveTracking> recursiveTrackingFromString(std::string_view s) {
  for (auto t : {RecursiveTracking::Fixed, RecursiveTracking::Variable, RecursiveTracking::Bank})
    if (s == toString(t)) return t;
  return std::nullopt;
}

bool RecursiveOptions::isValid(std::string* why) const {
  auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (why) why->clear();
  for (std::size_t i = 0; i < estimate.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (estimate[i] == estimate[j]) return fail("'" + estimate[i] + "' is listed twice");
  if (!(lambda > 0.0 && lambda <= 1.0)) return fail("the forgetting factor must lie in (0, 1]");
  if (!(r2 > 0.0) || !std::isfinite(r2)) return fail("R2 must be a positive number");
  for (double v : r1)
    if (!(v >= 0.0) || !std::isfinite(v)) return fail("R1's diagonal must not be negative");
  if (!r1.empty() && r1.size() != estimate.size())
    return fail("R1 needs one value per estimated parameter");
  if (!(designSampleTime >= 0.0) || !std::isfinite(designSampleTime))
    return fail("the design sample time must not be negative (0: per sample)");
  if (!(lambdaMin > 0.0 && lambdaMin <= lambda))
    return fail("the lowest forgetting factor must lie in (0, lambda]");
  if (tracking == RecursiveTracking::Variable && algorithm != RecursiveAlgorithm::ForgettingFactor)
    return fail("variable forgetting needs the forgetting-factor algorithm");
  if (!(bankSpacingS > 0.0) || !std::isfinite(bankSpacingS))
    return fail("the spacing of the hypothesised change times must be positive");
  if (bankSize < 1 || bankSize > 64) return fail("the bank holds 1 to 64 estimators");
  if (!(bankMinAgeS >= 0.0) || !std::isfinite(bankMinAgeS) ||
      bankMinAgeS >= bankSpacingS * static_cast<double>(bankSize))
    return fail("the bank's hypotheses must ripen (bankMinAgeS) before they drop out of the bank");
  if (!(bankThreshold > 0.0) || !std::isfinite(bankThreshold))
    return fail("the bank's threshold must be positive");
  if (!(bankCovarianceScale >= 1.0) || !std::isfinite(bankCovarianceScale))
    return fail("the bank's P(0) scale must be at least 1");
  if (!(mu >= 0.0) || !std::isfinite(mu)) return fail("the regularisation mu must not be negative");
  if (!(differenceStep > 0.0) || !std::isfinite(differenceStep))
    return fail("the difference step must be positive");
  if (!(startScale > 0.0) || !std::isfinite(startScale))
    return fail("the start scale must be a positive number");
  if (!thetaStart.empty() && thetaStart.size() != estimate.size())
    return fail("theta(0) needs one value per estimated parameter");
  for (double v : thetaStart)
    if (!std::isfinite(v)) return fail("theta(0) must be finite");
  if (!p0.empty() && p0.size() != estimate.size())
    return fail("P(0) needs one value per estimated parameter");
  for (double v : p0)
    if (!(v > 0.0) || !std::isfinite(v)) return fail("P(0)'s diagonal must be positive");
  if (!(noiseVariance >= 0.0) || !std::isfinite(noiseVariance))
    return fail("the noise variance must not be negative");
  if (!(covarianceLimit > 1.0)) return fail("the covariance limit must exceed 1");
  if (!(maxHeldSeconds >= 0.0)) return fail("the time held at the bounds must not be negative");
  return true;
}

RecursiveOptions perSample(const RecursiveOptions& options, double sampleTime,
                           const std::vector<RecursiveParameter>& params) {
  RecursiveOptions o = options;
  if (o.algorithm == RecursiveAlgorithm::Kalman) {
    const Eigen::VectorXd r1 = kalmanR1(params, options);
    o.r1.assign(r1.data(), r1.data() + r1.size());
  }
  if (options.designSampleTime > 0.0 && sampleTime > 0.0 && sampleTime != options.designSampleTime) {
    const double ratio = sampleTime / options.designSampleTime;
    o.lambda = std::pow(options.lambda, ratio);
    o.lambdaMin = std::pow(options.lambdaMin, ratio);
    for (double& v : o.r1) v *= ratio;
  }
  o.designSampleTime = 0.0;
  return o;
}

std::string sampleTimeProblem(const RecursiveOptions& options, double sampleTime) {
  if (!(options.designSampleTime > 0.0) || !(sampleTime > options.designSampleTime)) return {};
  const std::string at = "The sample time of " + formatNumber(sampleTime) + " s";
  if (options.algorithm == RecursiveAlgorithm::ForgettingFactor && options.lambda < 1.0) {
    const double memory = options.designSampleTime / (1.0 - options.lambda);  // s, of (6.13)
    if (sampleTime > memory * (1.0 + 1e-9))  // 1 - lambda is not exact in binary
      return at + " is longer than the recursive estimator's memory of " + formatNumber(memory) +
             " s (lambda " + formatNumber(options.lambda) + " " + designRateText(options) +
             "): each sample would forget every sample before it; the log needs a sample at least every " +
             formatNumber(memory) + " s";
  }
  const double ratio = sampleTime / options.designSampleTime;
  for (double lambda : {options.lambda, options.lambdaMin})
    if (!(std::pow(lambda, ratio) >= std::numeric_limits<double>::min()))
      return at + " makes the forgetting factor " + formatNumber(lambda) + " " + designRateText(options) +
             " vanish (" + formatNumber(lambda) + "^" + formatNumber(ratio) + " is zero in double precision)";
  return {};
}

std::string designRateText(const RecursiveOptions& options) {
  if (!(options.designSampleTime > 0.0)) return "per sample";
  return "per " + formatNumber(1.0 / options.designSampleTime) + " Hz sample";
}

void RecursiveTrajectory::reserve(std::size_t samples, std::size_t parameters) {
  for (auto* v : {&time, &y, &yhat, &epsilon, &noiseVariance, &lambda}) v->reserve(samples);
  for (auto* m : {&theta, &pDiagonal, &sigma}) {
    m->resize(parameters);
    for (auto& v : *m) v.reserve(samples);
  }
}

void RecursiveTrajectory::append(const RecursiveStep& s) {
  const auto p = static_cast<std::size_t>(s.theta.size());
  for (auto* m : {&theta, &pDiagonal, &sigma})
    if (m->size() != p) m->resize(p);
  time.push_back(s.time);
  y.push_back(s.y);
  yhat.push_back(s.yhat);
  epsilon.push_back(s.epsilon);
  noiseVariance.push_back(s.noiseVariance);
  lambda.push_back(s.lambda);
  if (s.change) {
    changeDetected.push_back(s.time);
    changeTime.push_back(s.changeTime);
  }
  for (std::size_t i = 0; i < p; ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    theta[i].push_back(s.theta[k]);
    pDiagonal[i].push_back(s.pDiagonal[k]);
    sigma[i].push_back(s.sigma[k]);
  }
}

void RecursiveTrajectory::clear() {
  for (auto* v : {&time, &y, &yhat, &epsilon, &noiseVariance, &lambda, &changeDetected, &changeTime})
    v->clear();
  for (auto* m : {&theta, &pDiagonal, &sigma}) m->clear();
}

}  // namespace flexarm
