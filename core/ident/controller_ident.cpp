#include "core/ident/controller_ident.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/ident/evaluation.h"

namespace flexarm {

bool ControllerIdentOptions::isValid(std::string* why) const {
  if (!(minimumFitPercent <= 100.0) || !std::isfinite(minimumFitPercent)) {
    if (why) *why = "the minimum fit % of the torque must be a number up to 100";
    return false;
  }
  return true;
}

namespace {

// Columns x1..x4 of the model in the header.
struct Regressors {
  Eigen::VectorXd x1, x2, x3, x4;
};

Regressors regressors(const Eigen::VectorXd& r, const Eigen::VectorXd& a, double T) {
  const Eigen::Index n = r.size();
  Regressors x{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  double s1 = 0.0, s2 = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    x.x1[k] = r[k] - a[k];
    x.x2[k] = k == 0 ? 0.0 : (a[k] - a[k - 1]) / T;
    s1 += T * x.x1[k];
    s2 += T * x.x2[k];
    x.x3[k] = s1;
    x.x4[k] = s2;
  }
  return x;
}

// u = kv (kp x1 - x2) + kv g (kp x3 - x4) + c with g = 1 / T_i.
Eigen::VectorXd torqueOf(const Regressors& x, double kp, double kv, double g, double c) {
  return (kv * (kp * x.x1 - x.x2 + g * (kp * x.x3 - x.x4))).array() + c;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

Eigen::VectorXd controllerTorque(const ControllerOptions& c, const Eigen::VectorXd& r,
                                 const Eigen::VectorXd& a, double T, double offset) {
  if (r.size() != a.size()) throw std::invalid_argument("controllerTorque: reference and angle differ in length");
  if (!(T > 0.0)) throw std::invalid_argument("controllerTorque: the sample time must be positive");
  return torqueOf(regressors(r, a, T), c.kp, c.kv, c.ti > 0.0 ? 1.0 / c.ti : 0.0, offset);
}

double controllerFitPercent(const ControllerOptions& c, const Eigen::VectorXd& r,
                            const Eigen::VectorXd& a, const Eigen::VectorXd& u, double T) {
  if (r.size() != a.size() || r.size() != u.size() || r.size() < 2 || !(T > 0.0))
    return std::numeric_limits<double>::quiet_NaN();
  const Eigen::VectorXd uhat = controllerTorque(c, r, a, T);
  const double offset = (u - uhat).mean();
  return fitPercent(u, (uhat.array() + offset).matrix());
}

ControllerIdentResult identifyController(const Eigen::VectorXd& r, const Eigen::VectorXd& a,
                                         const Eigen::VectorXd& u, double T,
                                         const ControllerIdentOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("identifyController: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  ControllerIdentResult out;
  auto finish = [&](Termination t, std::string text) {
    out.termination = t;
    out.message = std::move(text);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  const std::string head = "the cascade controller of Figure 5.1";
  if (r.size() != a.size() || r.size() != u.size())
    return finish(Termination::Failed, head + " needs reference, angle and torque of equal length");
  if (!(T > 0.0)) throw std::invalid_argument("identifyController: the sample time must be positive");
  const Eigen::Index n = r.size();
  if (n < 50) return finish(Termination::Failed, head + " cannot be identified from " + std::to_string(n) + " samples");
  if (!r.allFinite() || !a.allFinite() || !u.allFinite())
    return finish(Termination::Failed, head + " cannot be identified: the log holds non-finite values");
  // The first sample's velocity estimate needs the angle before the log: the regression
  // starts at the second sample (its sum then differs from the controller's by a constant,
  // which c takes up).
  const Regressors full = regressors(r, a, T);
  const Eigen::Index m = n - 1;
  const Regressors x{full.x1.tail(m), full.x2.tail(m), full.x3.tail(m), full.x4.tail(m)};
  const Eigen::VectorXd ut = u.tail(m);

  // Least squares of u on (x1, x2, x3, x4, 1), columns scaled to unit norm.
  Eigen::MatrixXd X(m, 5);
  X << x.x1, x.x2, x.x3, x.x4, Eigen::VectorXd::Ones(m);
  Eigen::VectorXd scale(5);
  for (int j = 0; j < 5; ++j) {
    scale[j] = X.col(j).norm();
    if (!(scale[j] > 0.0))
      return finish(Termination::Failed,
                    head + " cannot be identified: the angle or the reference does not move");
    X.col(j) /= scale[j];
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  if (qr.rank() < 5)
    return finish(Termination::Failed, head + " cannot be identified: the log does not excite the loop");
  const Eigen::VectorXd b = qr.solve(ut).cwiseQuotient(scale);
  double kv = -b[1];
  if (!(kv > 0.0) || !(b[0] > 0.0))
    return finish(Termination::Failed, head + " does not explain the torque: its gains come out "
                                              "k_p k_v = " + number(b[0]) + ", k_v = " + number(kv) +
                                              ", not positive");
  double kp = b[0] / kv, g = std::max(0.0, -b[3] / kv), c = b[4];

  // Gauss-Newton on (k_p, k_v, g, c): the four coefficients as products of one controller.
  bool integral = g > 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int it = 0; it < 50; ++it) {
      const Eigen::VectorXd e = ut - torqueOf(x, kp, kv, g, c);
      const int q = integral ? 4 : 3;
      Eigen::MatrixXd J(m, q);
      J.col(0) = kv * (x.x1 + g * x.x3);                          // d/dkp
      J.col(1) = kp * x.x1 - x.x2 + g * (kp * x.x3 - x.x4);      // d/dkv
      J.col(2) = Eigen::VectorXd::Ones(m);                         // d/dc
      if (integral) J.col(3) = kv * (kp * x.x3 - x.x4);            // d/dg
      Eigen::VectorXd s(q);
      for (int j = 0; j < q; ++j) {
        s[j] = J.col(j).norm();
        if (s[j] > 0.0) J.col(j) /= s[j];
        else s[j] = 1.0;
      }
      const Eigen::VectorXd step = J.colPivHouseholderQr().solve(e).cwiseQuotient(s);
      kp += step[0];
      kv += step[1];
      c += step[2];
      if (integral) g += step[3];
      const double rel = std::abs(step[0] / kp) + std::abs(step[1] / kv) +
                         (integral ? std::abs(step[3]) / std::max(g, 1e-12) : 0.0);
      if (!(rel > 1e-13)) break;
    }
    if (!integral || g > 0.0) break;
    integral = false;  // a negative integral gain: the loop has no integral action
    g = 0.0;
  }
  if (!(kp > 0.0) || !(kv > 0.0) || !std::isfinite(c))
    return finish(Termination::Failed, head + " does not explain the torque: its gains come out k_p = " +
                                           number(kp) + ", k_v = " + number(kv) + ", not positive");
  out.controller.rateHz = 1.0 / T;
  out.controller.kp = kp;
  out.controller.kv = kv;
  out.controller.ti = g > 0.0 ? 1.0 / g : 0.0;
  out.offset = c;
  out.fitPercent = fitPercent(ut, torqueOf(x, kp, kv, g, c));
  const std::string gains = "k_p = " + number(kp) + " 1/s, k_v = " + number(kv) + " N m s/rad, T_i = " +
                            (g > 0.0 ? number(1.0 / g) + " s" : std::string("none (no integral action)")) +
                            " at " + number(1.0 / T) + " Hz";
  char fit[64];
  std::snprintf(fit, sizeof fit, "%.3f %%", out.fitPercent);
  if (!(out.fitPercent >= options.minimumFitPercent)) {
    char need[32];
    std::snprintf(need, sizeof need, "%.4g %%", options.minimumFitPercent);
    return finish(Termination::Failed,
                  head + " identified from the log (" + gains + ") explains only " + fit +
                      " of the torque (5.2), less than the " + need +
                      " needed: the log's controller has another structure or rate");
  }
  return finish(Termination::Converged, head + " identified from the log: " + gains +
                                            "; it explains " + fit + " of the torque (5.2)");
}

}  // namespace flexarm
