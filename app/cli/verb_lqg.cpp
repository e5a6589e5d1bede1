// flexarm lqg [--model two-mass --param NAME=VALUE ...] --q1 ... --q2 x --r1 ... --r2 y[,z]
//             [--accel] [--json]
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "core/common/text.h"
#include "app/cli/cli.h"
#include "core/control/lqg_analysis.h"

namespace flexarm::cli {
namespace {

OptionTable lqgTable() {
  OptionTable t("flexarm lqg [--model two-mass] [--param NAME=VALUE ...] [--q1 a,b,c,d,e] [--q2 x] [--r1 a,b,c,d,e] "
                "[--r2 y[,z]] [--accel] [--json]",
                "Designs the LQG regulator of the seed's chapter 8 for the two-mass arm and analyses it: LQR gain L "
                "minimizing (8.17), Kalman gain K of (8.16), integral action by the state x5, a constant load on the "
                "arm (Section 8.3), closed-loop and regulator poles, the Nyquist curve of F_y G with its "
                "encirclements of -1, max |S|, Bode's integral (8.37) against pi * sum Re(p_i), the disturbance "
                "steps of Figure 8.3 and the describing-function check. Without options it designs the seed's case "
                "(i).");
  const double any = 1e308;
  t.add(textOption("model", "two-mass", "the plant (8.1)-(8.6); the only model of this verb (default)"))
      .add(textOption("param", "NAME=VALUE", "change a parameter of Table 8.1: J_m, J_a (kg m^2), f_m, f_a, d (N m "
                                             "s/rad), k (N m/rad)",
                      true))
      .add(textOption("q1", "LIST", "diagonal state weight of (8.17), one entry per design state (x1..x5; default "
                                    "100,1,0,0,0; the fifth weights the uncontrollable x5 and changes no gain)"))
      .add(numberOption("q2", "X", -any, any, "1", "input weight of (8.17)"))
      .add(textOption("r1", "LIST", "diagonal process noise covariance (default 0,0,0,0,1)"))
      .add(textOption("r2", "Y[,Z]", "measurement noise covariance: Y for phi_m, Z for the arm acceleration with "
                                     "--accel (default 1e-6; 1e-8 is case (ii); with --accel 1e-8,1e-1 as in "
                                     "Section 8.7)"))
      .add(flagOption("accel", "also measure the arm acceleration, (8.40)-(8.42)"))
      .add(flagOption("no-integral", "design on the four-state model without x5 (Q1, R1 take 4 entries)"))
      .add(numberOption("saturation", "U", -any, any, "", "also simulate the steps with |u| <= U, without and with "
                                                          "anti-windup (8.31)-(8.32)"))
      .add(numberOption("bandwidth", "W", -any, any, "50", "bandwidth in rad/s of T_a for the Section 8.4 check"))
      .add(flagOption("json", "print the results as JSON"));
  t.note("JSON fields: L, K, lqr_residual, kalman_residual, closed_loop_poles, regulator_poles (each [re, im]), "
         "rhp_regulator_poles, regulator_stability, encirclements (counter-clockwise, of -1 by F_y G), "
         "expected_encirclements (P - Z), max_sensitivity and its frequency, min_distance_to_minus_one, "
         "bode_integral, bode_prediction, peak_arm_deviation, describing_function_crossings (F_y G and G_0), "
         "saturation, bandwidth_criterion, seconds.");
  return t;
}

bool parseList(const std::string& text, Eigen::VectorXd& out, std::string& why) {
  std::vector<double> v;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const char* b = text.data() + pos;
    const char* e = text.data() + comma;
    if (b != e && *b == '+') ++b;
    double x = 0.0;
    auto res = std::from_chars(b, e, x);
    if (b == e || res.ec != std::errc() || res.ptr != e || !std::isfinite(x)) {
      why = "expects comma-separated numbers, got " + inQuotes(text);
      return false;
    }
    v.push_back(x);
    pos = comma + 1;
  }
  out = Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  return true;
}

nlohmann::json poles(const Eigen::VectorXcd& p) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < p.size(); ++i) j.push_back({p(i).real(), p(i).imag()});
  return j;
}

nlohmann::json matrix(const Eigen::MatrixXd& M) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index k = 0; k < M.cols(); ++k) row.push_back(M(i, k));
    j.push_back(row);
  }
  return j;
}

nlohmann::json crossings(const std::vector<DescribingFunctionCrossing>& xs) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& x : xs)
    j.push_back(
        {{"frequency_rad_s", x.frequency}, {"real_part", x.realPart}, {"amplitude", x.amplitude}});
  return j;
}

nlohmann::json response(const DisturbanceResponse& r) {
  return {{"peak_arm_deviation", r.peakArmDeviation},
          {"diverged", r.diverged},
          {"final_motor_angle", r.motorAngle.empty() ? 0.0 : r.motorAngle.back()}};
}

}  // namespace

int runLqg(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(lqgTable());
  auto usage = [&err](const std::string& why) {
    err << "flexarm lqg: " << why << "\n(flexarm lqg --help explains the options)\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << args.table().help();
    return kExitOk;
  }
  if (!args.positional().empty())
    return usage("unexpected argument '" + args.positional()[0] + "'");
  if (auto m = args.value("model"); m && *m != "two-mass")
    return usage("--model must be two-mass, not " + inQuotes(*m));

  LqgOptions o;
  if (args.flag("accel")) o = LqgOptions::seedAccelerationFeedback();
  o.integralAction = !args.flag("no-integral");
  if (!o.integralAction) {
    o.q1.conservativeResize(4);
    o.r1 = Eigen::Vector4d(0, 0, 0, 1);  // noise on the arm: the load enters there
  }
  for (const std::string& p : args.values("param")) {
    const auto eq = p.find('=');
    if (eq == std::string::npos) return usage("--param expects NAME=VALUE, got " + inQuotes(p));
    const std::string name = p.substr(0, eq), text = p.substr(eq + 1);
    double value = 0.0;
    const auto res = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || res.ec != std::errc() || res.ptr != text.data() + text.size())
      return usage("--param " + name + " expects a number, got " + inQuotes(text));
    try {
      o.parameters.set(name, value);
    } catch (const std::invalid_argument& e) {
      return usage(e.what());
    }
  }
  std::string why;
  for (auto [name, target] :
       {std::pair<const char*, Eigen::VectorXd*>{"q1", &o.q1}, {"r1", &o.r1}, {"r2", &o.r2}}) {
    if (auto v = args.value(name); v && !parseList(*v, *target, why))
      return usage(std::string("--") + name + " " + why);
  }
  LqgAnalysisOptions ao;
  if (!args.number("q2", o.q2) || !args.number("saturation", ao.saturationLimit) ||
      !args.number("bandwidth", ao.taBandwidth))
    return usage(args.error());
  if (!o.isValid(&why)) return usage(why);
  if (!ao.isValid(&why)) return usage(why);

  const LqgAnalysis a = analyzeLqg(o, ao);
  if (!a.ok()) {
    err << "flexarm lqg: the design failed: " << a.message << "\n";
    return kExitNumerical;
  }
  const LqgDesign& d = a.design;
  if (args.flag("json")) {
    nlohmann::json j = {
        {"model", "two-mass"},
        {"measurement", toString(o.measurement)},
        {"integral_action", o.integralAction},
        {"L", matrix(d.L)},
        {"K", matrix(d.K)},
        {"lqr_residual", d.lqrResidual},
        {"kalman_residual", d.kalmanResidual},
        {"closed_loop_poles", poles(d.closedLoopPoles)},
        {"regulator_poles", poles(d.regulatorPoles)},
        {"rhp_regulator_poles", d.rhpRegulatorPoles},
        {"regulator_stability", d.regulatorStability()},
        {"closed_loop_stable", d.rhpClosedLoopPoles == 0},
        {"encirclements", a.loop.encirclements},
        {"expected_encirclements", a.expectedEncirclements},
        {"max_sensitivity", a.maxSensitivity},
        {"max_sensitivity_frequency_rad_s", a.maxSensitivityFrequency},
        {"min_distance_to_minus_one", a.minDistanceToMinusOne},
        {"bode_integral", a.bodeIntegral},
        {"bode_prediction", a.bodePrediction},
        {"peak_arm_deviation", a.steps.peakArmDeviation},
        {"describing_function_crossings",
         {{"loop_gain", crossings(a.loopCrossings)}, {"g0", crossings(a.g0Crossings)}}},
        {"seconds", a.seconds}};
    if (ao.saturationLimit > 0.0)
      j["saturation"] = {{"limit", ao.saturationLimit},
                         {"without_anti_windup", response(a.saturated)},
                         {"with_anti_windup", response(a.saturatedAntiWindup)}};
    if (ao.taBandwidth > 0.0)
      j["bandwidth_criterion"] = {
          {"bandwidth_rad_s", a.bandwidth.bandwidth},
          {"encirclements_of_plus_one", a.bandwidth.curve.encirclements},
          {"rhp_zeros", a.bandwidth.rhpZeros},
          {"unstable_regulator_needed", a.bandwidth.unstableRegulatorNeeded()}};
    out << j.dump(2) << "\n";
    return kExitOk;
  }
  out << "LQG design (" << toString(o.measurement)
      << (o.integralAction ? ", integral action by x5" : "") << ")\n";
  out << "  L = " << d.L << "\n  K' = " << d.K.transpose() << "\n";
  out << "  Riccati residuals: LQR " << d.lqrResidual << ", Kalman " << d.kalmanResidual << "\n";
  out << "  " << d.regulatorStability() << "; closed loop "
      << (d.rhpClosedLoopPoles == 0 ? "stable" : "UNSTABLE") << "\n";
  out << "  F_y G encircles -1 " << a.loop.encirclements
      << " times counter-clockwise (poles predict " << a.expectedEncirclements << ")\n";
  out << "  max |S| = " << a.maxSensitivity << " at " << a.maxSensitivityFrequency
      << " rad/s (min distance to -1: " << a.minDistanceToMinusOne << ")\n";
  out << "  Bode integral (8.37): " << a.bodeIntegral << ", pi * sum Re(p_i) = " << a.bodePrediction
      << "\n";
  out << "  peak arm deviation for unit steps in w (0 s) and v (1 s): " << a.steps.peakArmDeviation
      << " rad\n";
  out << "  crossings of -1/Y_f (8.30): F_y G " << a.loopCrossings.size() << ", G_0 (8.35) "
      << a.g0Crossings.size() << "\n";
  if (ao.saturationLimit > 0.0)
    out << "  with |u| <= " << ao.saturationLimit << ": peak arm deviation "
        << a.saturated.peakArmDeviation << (a.saturated.diverged ? " (diverged)" : "")
        << " without anti-windup, " << a.saturatedAntiWindup.peakArmDeviation
        << (a.saturatedAntiWindup.diverged ? " (diverged)" : "") << " with\n";
  if (ao.taBandwidth > 0.0)
    out << "  T_a of bandwidth " << a.bandwidth.bandwidth << " rad/s: "
        << (a.bandwidth.unstableRegulatorNeeded() ? "needs an unstable regulator"
                                                  : "a stable regulator can reach it")
        << " (1 - T_m has " << a.bandwidth.rhpZeros << " RHP zeros)\n";
  return kExitOk;
}

}  // namespace flexarm::cli
