#pragma once
// Flexible-arm logs with a known state-space order and resonances, for the subspace tests and
// bench_subspace: a two-mass (order 3) or three-mass (order 5) axis, torque in, motor velocity
// out, sampled at 5 ms with white measurement noise, in open loop or under a P velocity
// controller whose measurement noise is fed back.
#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/pem.h"

namespace flexarm::testing {

// A two-mass (order 3: motor and arm speed, twist) or three-mass (order 5) axis, torque in,
// motor velocity out, continuous time.
inline StateSpace massChain(int masses) {
  const std::vector<double> J = masses == 2 ? std::vector<double>{5e-3, 2e-2} : std::vector<double>{5e-3, 4e-3, 2e-2};
  const std::vector<double> k = masses == 2 ? std::vector<double>{8.0} : std::vector<double>{30.0, 8.0};
  const double d = 0.004, fm = 0.01;
  const int m = masses, n = 2 * masses - 1;  // speeds, then twists
  StateSpace s;
  s.A = Eigen::MatrixXd::Zero(n, n);
  s.B = Eigen::MatrixXd::Zero(n, 1);
  s.C = Eigen::MatrixXd::Zero(1, n);
  s.D = Eigen::MatrixXd::Zero(1, 1);
  for (int i = 0; i + 1 < m; ++i) {
    const int tw = m + i;  // twist phi_i - phi_{i+1}
    s.A(tw, i) = 1.0;
    s.A(tw, i + 1) = -1.0;
    // The spring and damper act on both masses.
    s.A(i, tw) -= k[i] / J[i];
    s.A(i + 1, tw) += k[i] / J[i + 1];
    s.A(i, i) -= d / J[i];
    s.A(i, i + 1) += d / J[i];
    s.A(i + 1, i + 1) -= d / J[i + 1];
    s.A(i + 1, i) += d / J[i + 1];
  }
  s.A(0, 0) -= fm / J[0];
  s.B(0, 0) = 1.0 / J[0];
  s.C(0, 0) = 1.0;
  return s;
}

// The resonance frequencies (rad/s) of the complex poles, ascending.
inline std::vector<double> resonances(const Eigen::MatrixXd& A, double T, bool discrete) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(A, false);
  std::vector<double> w;
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) {
    const std::complex<double> z = es.eigenvalues()[i];
    if (z.imag() <= 1e-9) continue;
    w.push_back(std::abs(discrete ? std::log(z) / T : z));
  }
  std::sort(w.begin(), w.end());
  return w;
}

struct ArmLog {
  Eigen::VectorXd u, y;
  std::vector<double> truth;  // resonances, rad/s
  int order = 0;
};

// T = 5 ms; open loop: a random multisine-like torque; closed loop: a P velocity controller
// u = Kp (r - y_measured) whose measurement noise is fed back.
inline ArmLog armLog(int masses, bool closedLoop, unsigned seed, Eigen::Index n = 6000) {
  const double T = 0.005, noise = 0.02;
  const StateSpace c = massChain(masses);
  const StateSpace d = discretizeZoh(c, T);
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  ArmLog log;
  log.order = c.states();
  log.truth = resonances(c.A, T, false);
  log.u.resize(n);
  log.y.resize(n);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(c.states());
  double r = 0.0, drive = 0.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    const double y = (d.C * x)(0, 0) + noise * nd(rng);
    drive = 0.7 * drive + 0.3 * nd(rng);
    if (t % 40 == 0) r = 5.0 * nd(rng);
    const double u = closedLoop ? 0.05 * (r - y) + 0.2 * drive : 0.3 * drive;
    log.u[t] = u;
    log.y[t] = y;
    x = d.A * x + d.B * u;
  }
  return log;
}

}  // namespace flexarm::testing
