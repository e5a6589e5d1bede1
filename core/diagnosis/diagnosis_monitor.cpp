// DiagnosisMonitor: the recursive estimators of the bank and the tests, one sample at a time.
#include <algorithm>
#include <stdexcept>

#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/hypothesis_statistics.h"

namespace flexarm {

struct DiagnosisMonitor::Impl {
  DiagnosisOptions options;
  double sampleTime = 0.0;
  std::unique_ptr<RecursiveEstimator> full;
  // The bank of Section 7.5.2: NF (theta_0 fixed) and each parameter alone.
  std::unique_ptr<RecursiveEstimator> nominal;
  std::vector<RecursiveEstimator> single;
  std::vector<ClassicalTest> classical;
  std::vector<RobustTest> robust;
  std::vector<CusumTest> cusum;
  std::unique_ptr<HypothesisStatistics> hypothesis;
  std::unique_ptr<JointTest> joint;
  std::vector<std::vector<TestSample>> samples;
  std::vector<double> errors;
};

DiagnosisMonitor::DiagnosisMonitor(const DiagnosisReference& reference,
                                   const DiagnosisSignals& signals, const DiagnosisOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const double sampleTime = signals.sampleTime, startTime = signals.startTime;
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("diagnosis: " + why);
  if (!reference.ok()) throw std::invalid_argument("diagnosis: the reference is not usable: " + reference.message);
  const std::size_t n = options.parameters.size();
  if (reference.p0.size() != n || reference.p0Single.size() != n)
    throw std::invalid_argument("diagnosis: the reference lacks P(0) for the monitored parameters");
  if (!(sampleTime > 0.0)) throw std::invalid_argument("diagnosis: the sample time must be > 0");
  Impl& m = *impl_;
  m.options = options;
  m.sampleTime = sampleTime;
  const auto predictor = predictorModel(*reference.nominal, signals);
  auto estimator = [&](const std::vector<std::string>& names, std::vector<double> p0) {
    RecursiveOptions e = estimatorOptions(options, names);
    e.p0 = std::move(p0);
    if (e.noiseVariance == 0.0) e.noiseVariance = reference.noiseVariance;
    return RecursiveEstimator(*predictor, sampleTime, e, startTime);
  };
  m.full = std::make_unique<RecursiveEstimator>(estimator(options.parameters, reference.p0));
  const auto& params = m.full->parameters();
  std::vector<double> sigma0 = reference.sigma0;
  sigma0.resize(n, 0.0);
  for (DiagnosisTest t : options.tests) {
    switch (t) {
      case DiagnosisTest::Classical:
        for (std::size_t i = 0; i < n; ++i)
          m.classical.emplace_back(params[i].nominal, sigma0[i],
                                   options.classicalK * options.thresholdScale(t, i));
        break;
      case DiagnosisTest::Robust:
        for (std::size_t i = 0; i < n; ++i)
          m.robust.emplace_back(params[i].nominal, sigma0[i], options.robustK * options.thresholdScale(t, i),
                                options.robustLambda);
        break;
      case DiagnosisTest::Cusum:
        for (std::size_t i = 0; i < n; ++i)
          m.cusum.emplace_back(params[i].nominal, options.cusumAlpha1,
                               options.cusumAlpha2 * options.thresholdScale(t, i));
        break;
      case DiagnosisTest::Joint: {
        std::vector<double> theta0;
        for (const auto& q : params) theta0.push_back(q.nominal);
        m.joint = std::make_unique<JointTest>(theta0, sigma0, options.jointK, options.robustLambda);
        break;
      }
      case DiagnosisTest::Hypothesis: {
        m.nominal = std::make_unique<RecursiveEstimator>(estimator({}, {}));
        for (std::size_t i = 0; i < n; ++i)
          m.single.push_back(estimator({options.parameters[i]}, {reference.p0Single[i]}));
        const std::size_t window =
            options.window == HypothesisWindow::Sliding
                ? std::max<std::size_t>(1, static_cast<std::size_t>(options.windowS / sampleTime + 0.5))
                : 0;
        m.hypothesis = std::make_unique<HypothesisStatistics>(n + 1, window);
        m.errors.assign(n + 1, 0.0);
        break;
      }
    }
    m.samples.emplace_back(t == DiagnosisTest::Hypothesis || t == DiagnosisTest::Joint ? n + 1 : n);
  }
}

DiagnosisMonitor::~DiagnosisMonitor() = default;

const RecursiveStep& DiagnosisMonitor::update(double u, double y) {
  Impl& m = *impl_;
  const RecursiveStep& step = m.full->update(u, y);
  for (std::size_t k = 0; k < m.options.tests.size(); ++k) {
    auto& out = m.samples[k];
    switch (m.options.tests[k]) {
      case DiagnosisTest::Classical:
        for (std::size_t i = 0; i < out.size(); ++i)
          out[i] = m.classical[i].update(step.theta(static_cast<Eigen::Index>(i)),
                                         step.sigma(static_cast<Eigen::Index>(i)));
        break;
      case DiagnosisTest::Robust:
        for (std::size_t i = 0; i < out.size(); ++i)
          out[i] = m.robust[i].update(step.theta(static_cast<Eigen::Index>(i)),
                                      step.sigma(static_cast<Eigen::Index>(i)));
        break;
      case DiagnosisTest::Cusum:
        for (std::size_t i = 0; i < out.size(); ++i)
          out[i] = m.cusum[i].update(step.theta(static_cast<Eigen::Index>(i)),
                                     step.sigma(static_cast<Eigen::Index>(i)));
        break;
      case DiagnosisTest::Joint: {
        const auto& t = m.joint->update(step.theta, step.sigma, m.full->covariance());
        for (std::size_t h = 0; h < out.size(); ++h) {
          out[h] = t[h];
          out[h].ratio /= m.options.jointScale;
          out[h].threshold *= m.options.jointScale;
          out[h].alarm = out[h].ratio > 1.0;
        }
        break;
      }
      case DiagnosisTest::Hypothesis: {
        m.errors[0] = m.nominal->update(u, y).epsilon;  // (7.18)
        for (std::size_t i = 0; i < m.single.size(); ++i)
          m.errors[i + 1] = m.single[i].update(u, y).epsilon;  // (7.19)
        const auto& t = m.hypothesis->update(m.errors, step.epsilon);  // (7.20), (7.21)
        for (std::size_t h = 0; h < out.size(); ++h) {
          out[h].statistic = t[h];
          out[h].threshold = m.options.hypothesisThreshold;
          out[h].ratio = t[h] / m.options.hypothesisThreshold;
          out[h].alarm = out[h].ratio > 1.0;
        }
        break;
      }
    }
  }
  return step;
}

const std::vector<std::vector<TestSample>>& DiagnosisMonitor::tests() const { return impl_->samples; }

std::vector<std::vector<std::string>> DiagnosisMonitor::columns() const {
  std::vector<std::string> names;
  for (const auto& p : impl_->full->parameters()) names.push_back(p.name);
  std::vector<std::vector<std::string>> out;
  for (DiagnosisTest t : impl_->options.tests) {
    if (t != DiagnosisTest::Hypothesis && t != DiagnosisTest::Joint) {
      out.push_back(names);
      continue;
    }
    std::vector<std::string> h{"T_NF"};
    for (const auto& n : names) h.push_back("T_" + n);
    out.push_back(h);
  }
  return out;
}

const RecursiveEstimator& DiagnosisMonitor::estimator() const { return *impl_->full; }

std::vector<double> DiagnosisMonitor::smoothed() const {
  std::vector<double> out;
  for (const auto& r : impl_->robust) out.push_back(r.smoothed());
  return out;
}

bool DiagnosisMonitor::ok() const {
  const Impl& m = *impl_;
  if (!m.full->ok() || (m.nominal && !m.nominal->ok())) return false;
  return std::all_of(m.single.begin(), m.single.end(), [](const RecursiveEstimator& e) { return e.ok(); });
}

}  // namespace flexarm
