#pragma once
// Data generators shared by the identification tests: known polynomial systems (4.8) driven by
// white noise, in open loop or under a proportional controller u = r - K y (4.29).
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/polynomial.h"
#include "core/signal/id_data.h"

namespace flexarm::testing {

struct SimData {
  Eigen::VectorXd u, y, r, e;
};

inline Eigen::VectorXd whiteNoise(Eigen::Index n, double sigma, std::mt19937& rng) {
  std::normal_distribution<double> nd(0.0, sigma);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = nd(rng);
  return x;
}

// y = B/(A F) u + C/(A D) e, with u = r - gain * y when gain != 0 (B must have a delay);
// r is white with standard deviation referenceStd.
inline SimData simulateSystem(const Poly& a, const Poly& b, const Poly& c, const Poly& d,
                              const Poly& f, Eigen::Index n, double noiseStd, unsigned seed,
                              double gain = 0.0, double referenceStd = 1.0) {
  std::mt19937 rng(seed);
  SimData s;
  s.r = whiteNoise(n, referenceStd, rng);
  s.e = whiteNoise(n, noiseStd, rng);
  const Poly af = polyMultiply(a, f), ad = polyMultiply(a, d);
  s.u = Eigen::VectorXd::Zero(n);
  s.y = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    double xs = 0.0, vs = 0.0;
    for (std::size_t k = 1; k < b.size(); ++k)
      if (t >= static_cast<Eigen::Index>(k)) xs += b[k] * s.u[t - k];
    for (std::size_t k = 1; k < af.size(); ++k)
      if (t >= static_cast<Eigen::Index>(k)) xs -= af[k] * x[t - k];
    for (std::size_t k = 0; k < c.size(); ++k)
      if (t >= static_cast<Eigen::Index>(k)) vs += c[k] * s.e[t - k];
    for (std::size_t k = 1; k < ad.size(); ++k)
      if (t >= static_cast<Eigen::Index>(k)) vs -= ad[k] * v[t - k];
    x[t] = xs;
    v[t] = vs;
    s.y[t] = xs + vs;
    s.u[t] = s.r[t] - gain * s.y[t];
  }
  return s;
}

// u as the torque and y as the motor velocity of a log sampled every T seconds.
inline std::shared_ptr<const IdData> torqueVelocityLog(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double T) {
  auto d = std::make_shared<IdData>();
  d->sampleTime = T;
  d->setChannel({columns::kTorqueRef, "N m", ChannelRole::Input, std::vector<double>(u.data(), u.data() + u.size())});
  d->setChannel(
      {columns::kMotorVelocity, "rad/s", ChannelRole::Output, std::vector<double>(y.data(), y.data() + y.size())});
  return d;
}

}  // namespace flexarm::testing
