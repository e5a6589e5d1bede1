// Locating the disagreement: where a model's prediction error lives on the estimation data
// (over time, against the motor speed and its sign, in frequency against the model's
// resonances), and the data-dependent bounds of the candidates' values that follow from it.
#include <algorithm>
#include <cmath>

#include "core/discovery/discovery_internal.h"
#include "core/models/analysis.h"
#include "core/models/nonlinear_plant.h"
#include "core/signal/preprocess.h"

namespace flexarm {

namespace discovery_detail {

namespace {

// The lightly damped modes of the model's linear part (an extra mass included).
std::vector<double> resonances(const PhysicalModel& model, const std::vector<Effect>& effects) {
  std::vector<double> w;
  try {
    auto merged = mergedModel(model, effects);
    merged.first->setOptions(ModelOptions{});
    for (const auto& m : peakFrequencies(merged.first->stateSpace())) w.push_back(m.frequency);
  } catch (const std::invalid_argument&) {
  }
  return w;
}

}  // namespace

DisagreementMap mapDisagreement(const NonlinearSeries& est, const std::vector<double>& yhat,
                                const std::vector<double>& deflection, const PhysicalModel& model,
                                const std::vector<Effect>& effects, const DiscoveryScore& score, bool hasValidation) {
  DisagreementMap D;
  const std::size_t N = est.y.size();
  if (yhat.size() != N || N < 8) {
    D.summary = "the model could not be simulated on the data";
    return D;
  }
  D.time.resize(N);
  D.residual.resize(N);
  for (std::size_t k = 0; k < N; ++k) {
    D.time[k] = est.startTime + static_cast<double>(k) * est.Ts;
    D.residual[k] = est.y[k] - yhat[k];
  }
  D.motorVelocity = est.y;
  D.gearDeflection = deflection;
  D.motorAngle = est.phi;
  D.rms = score.rmsEstimation;
  D.fitPercent = score.fitPercent;
  const auto spec = amplitudeSpectrum(D.residual, est.Ts, static_cast<int>(std::min<std::size_t>(4096, N / 2)));
  D.spectrumHz = spec.frequencyHz;
  D.spectrum = spec.amplitude;
  double peak = 0.0;
  for (std::size_t i = 0; i < spec.frequencyHz.size(); ++i)
    if (2.0 * M_PI * spec.frequencyHz[i] > 5.0 && spec.amplitude[i] > peak) {
      peak = spec.amplitude[i];
      D.spectrumPeakRadS = 2.0 * M_PI * spec.frequencyHz[i];
    }
  D.resonancesRadS = resonances(model, effects);
  {
    const Eigen::Map<const Eigen::VectorXd> e(D.residual.data(), static_cast<Eigen::Index>(N));
    const Eigen::Map<const Eigen::VectorXd> u(est.u.data(), static_cast<Eigen::Index>(N));
    D.tests = residualAnalysis(e, u);
  }
  std::vector<double> speed(N), sgn(N);
  for (std::size_t k = 0; k < N; ++k) {
    speed[k] = std::abs(est.y[k]);
    sgn[k] = (est.y[k] > 0) - (est.y[k] < 0);
  }
  std::vector<double> sorted = speed;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(N / 2), sorted.end());
  const double median = sorted[N / 2];
  double lo = 0, hi = 0;
  std::size_t nl = 0, nh = 0;
  for (std::size_t k = 0; k < N; ++k) {
    const double e2 = D.residual[k] * D.residual[k];
    if (speed[k] < median) lo += e2, ++nl;
    else hi += e2, ++nh;
  }
  D.rmsLowSpeed = nl ? std::sqrt(lo / static_cast<double>(nl)) : 0.0;
  D.rmsHighSpeed = nh ? std::sqrt(hi / static_cast<double>(nh)) : 0.0;
  D.correlationSignVelocity = correlation(D.residual, sgn);
  std::string s = std::string(effects.empty() ? "Base model" : "Model") + ": fit " + number(score.fitPercent) +
                  " %, residual RMS " + number(score.rmsEstimation) + " rad/s on the estimation data";
  if (hasValidation) s += " and " + number(score.rmsValidation) + " rad/s on the held-out data";
  s += ". Residual RMS " + number(D.rmsLowSpeed) + " rad/s at low motor speed, " + number(D.rmsHighSpeed) +
       " at high speed; correlation with the sign of the velocity " + number(D.correlationSignVelocity, 2) +
       ". Largest residual line at " + number(D.spectrumPeakRadS) + " rad/s (model resonances:";
  for (double w : D.resonancesRadS) s += " " + number(w);
  s += " rad/s). " + D.tests.verdict;
  D.summary = s;
  return D;
}

// How wide a backlash gap the data can show: the gear travel, r times the motor's swing about
// its 0.5 s moving mean (a gap the motor never crosses is invisible), or the model's gear
// deflections if larger; 99th percentiles of the absolute values. The model's highest
// resonance places an added mass.
EffectBounds effectBounds(const NonlinearSeries& est, const std::vector<double>& deflection,
                          const PhysicalModel& model, const std::vector<Effect>& effects) {
  EffectBounds b;
  const std::size_t N = est.phi.size();
  double gap = percentile99(deflection);
  if (N > 0) {
    const std::size_t half = std::max<std::size_t>(1, static_cast<std::size_t>(0.25 / est.Ts));
    std::vector<double> swing(N);
    double sum = 0.0;
    std::size_t lo = 0, hi = 0;  // the window [lo, hi)
    for (std::size_t k = 0; k < N; ++k) {
      for (; hi < std::min(N, k + half + 1); ++hi) sum += est.phi[hi];
      for (; lo + half < k; ++lo) sum -= est.phi[lo];
      swing[k] = est.phi[k] - sum / static_cast<double>(hi - lo);
    }
    gap = std::max(gap, model.value("r") * percentile99(swing));
  }
  if (gap > 0.0) b.gapRange = gap;
  double w = 0.0;
  for (double x : resonances(model, effects)) w = std::max(w, x);
  b.resonanceRadS = w > 0.0 ? w : 100.0;
  return b;
}

}  // namespace discovery_detail

DisagreementMap locateDisagreement(const PhysicalModel& model, const std::vector<Effect>& effects, const IdData& data,
                                   const DiscoveryOptions& options) {
  using namespace discovery_detail;
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("locateDisagreement: " + why);
  DisagreementMap D;
  auto s = makeSeries(data, options.maxRateHz, &why);
  if (!s) {
    D.summary = why;
    return D;
  }
  std::unique_ptr<PhysicalModel> m(static_cast<PhysicalModel*>(model.clone().release()));
  m->setOptions(ModelOptions{});
  std::vector<double> yhat, deflection;
  try {
    const NonlinearPlant plant(*m, effects);
    const LoadObserver observer = loadObserver(*m, options.observerBandwidthHz);
    const int substeps = options.substeps > 0 ? options.substeps : defaultSubsteps(s->Ts);
    if (!predictOutput(plant, *s, substeps, observer, PredictedOutput::DifferentiatedAngle, yhat, &deflection)) {
      D.summary = "the model's simulation blows up on the data";
      return D;
    }
  } catch (const std::invalid_argument& e) {
    D.summary = std::string("the model cannot be simulated: ") + e.what();
    return D;
  }
  DiscoveryScore score;
  setFit(score, false, s->y, yhat);
  return mapDisagreement(*s, yhat, deflection, *m, effects, score, false);
}

}  // namespace flexarm
