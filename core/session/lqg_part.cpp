#include "core/session/lqg_part.h"

#include <cmath>

#include "core/common/text.h"
#include "core/session/report.h"

namespace flexarm {

using nlohmann::json;

namespace {

json vectorToJson(const Eigen::VectorXd& v) {
  json j = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) j.push_back(v(i));
  return j;
}

bool vectorFromJson(const json& j, const char* key, Eigen::VectorXd& out, std::string* why) {
  if (!j.contains(key)) return true;  // the default
  const json& v = j[key];
  if (!v.is_array() || v.empty()) {
    if (why) *why = std::string(key) + " must be a list of numbers";
    return false;
  }
  out.resize(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number()) {
      if (why) *why = std::string(key) + " must be a list of numbers";
      return false;
    }
    out(static_cast<Eigen::Index>(i)) = v[i].get<double>();
  }
  return true;
}

bool numberFromJson(const json& j, const char* key, double& out, std::string* why) {
  if (!j.contains(key)) return true;
  if (!j[key].is_number()) {
    if (why) *why = std::string(key) + " must be a number";
    return false;
  }
  out = j[key].get<double>();
  return true;
}

std::string listText(const Eigen::VectorXd& v) {
  std::string t;
  for (Eigen::Index i = 0; i < v.size(); ++i) t += (i ? ", " : "") + formatSignificant(v(i), 4);
  return t;
}

std::string polesText(const Eigen::VectorXcd& p) {
  std::string t;
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    if (p(i).imag() < 0.0) continue;  // conjugates are implied by "+-"
    t += (t.empty() ? "" : ", ") + formatSignificant(p(i).real(), 4);
    if (p(i).imag() > 0.0) t += " +- " + formatSignificant(p(i).imag(), 4) + "i";
  }
  return t;
}

class LqgPart : public SessionPart {
 public:
  std::string key() const override { return "lqg"; }

  bool validate(const json& section, std::string* why) const override {
    return lqgRequestFromJson(section, why).has_value();
  }

  void replay(const json& section, const ReplayContext&, Report& report) const override {
    std::string why;
    auto request = lqgRequestFromJson(section, &why);
    if (!request) return;  // validated on load
    const LqgOptions& o = request->design;
    ReportSection s;
    s.title = "LQG design (chapter 8)";
    s.paragraphs.push_back(
        "The regulator (8.15)-(8.16) for the two-mass arm of Figure 8.1 (parameters: " + request->source +
        "): the LQR gain minimizing (8.17) with the weights Q1, Q2 and the Kalman gain of (8.16) with "
        "the noise intensities R1, R2" +
        (o.integralAction ? ", with integral action by the arm-load state x5 (Section 8.3)." : "."));
    ReportTable opts{"Design options", {"Option", "Value"}, {}};
    opts.rows.push_back({"parameters from", request->source});
    for (const auto& name : TwoMassLqgParameters::names())
      opts.rows.push_back({name + " (" + TwoMassLqgParameters::unit(name) + ")",
                           formatSignificant(o.parameters.get(name), 5)});
    opts.rows.push_back({"measurement", toString(o.measurement)});
    opts.rows.push_back({"integral action (x5)", o.integralAction ? "yes" : "no"});
    opts.rows.push_back({"Q1 (diagonal)", listText(o.q1)});
    opts.rows.push_back({"Q2", formatSignificant(o.q2, 4)});
    opts.rows.push_back({"R1 (diagonal)", listText(o.r1)});
    opts.rows.push_back({"R2 (diagonal)", listText(o.r2)});
    opts.rows.push_back({"input saturation |u| <=",
                         request->saturationLimit > 0.0 ? formatSignificant(request->saturationLimit, 4) + " N m"
                                                        : "none"});
    s.tables.push_back(opts);
    s.values = {{"q1", vectorToJson(o.q1)}, {"q2", o.q2}, {"r1", vectorToJson(o.r1)}, {"r2", vectorToJson(o.r2)},
                {"measurement", toString(o.measurement)}};

    const LqgAnalysis a = analyzeLqg(o, request->analysisOptions());
    if (!a.ok()) {
      s.paragraphs.push_back("The design failed: " + a.message + ".");
      s.values["regulator_stability"] = nullptr;
      s.values["message"] = a.message;
      report.sections.push_back(s);
      return;
    }
    const LqgDesign& d = a.design;
    const bool closedStable = d.rhpClosedLoopPoles == 0;
    std::string verdict = "Regulator: " + d.regulatorStability() + ". Closed loop: ";
    verdict += closedStable ? "stable (every pole in the left half plane)."
                            : "unstable, " + std::to_string(d.rhpClosedLoopPoles) + " poles in the right half plane.";
    s.paragraphs.push_back(verdict);
    s.paragraphs.push_back(
        "Nyquist (Section 8.6): F_y G encircles -1 " + std::to_string(a.loop.encirclements) +
        " times counter-clockwise; the poles predict P - Z = " + std::to_string(a.expectedEncirclements) +
        (a.loop.encirclements == a.expectedEncirclements ? ", in agreement." : ", which disagrees.") +
        " The curve passes -1 at a distance of " + formatSignificant(a.minDistanceToMinusOne, 4) +
        ", so max |S| = " + formatSignificant(a.maxSensitivity, 4) + " (8.38).");
    ReportTable margins{"Stability and margins", {"Quantity", "Value"}, {}};
    margins.rows.push_back({"regulator poles in the RHP", std::to_string(d.rhpRegulatorPoles)});
    margins.rows.push_back({"closed-loop poles in the RHP", std::to_string(d.rhpClosedLoopPoles)});
    margins.rows.push_back({"encirclements of -1 (counter-clockwise)", std::to_string(a.loop.encirclements)});
    margins.rows.push_back({"max |S| (8.36)", formatSignificant(a.maxSensitivity, 4)});
    margins.rows.push_back({"at frequency (rad/s)", formatSignificant(a.maxSensitivityFrequency, 4)});
    margins.rows.push_back({"min |1 + F_y G| (8.38)", formatSignificant(a.minDistanceToMinusOne, 4)});
    margins.rows.push_back({"Bode integral of log|S| (8.37)", formatSignificant(a.bodeIntegral, 4)});
    margins.rows.push_back({"pi * sum Re(p_i), RHP poles of F_y G", formatSignificant(a.bodePrediction, 4)});
    margins.rows.push_back({"peak arm deviation, unit steps of Figure 8.3 (rad)",
                            formatSignificant(a.steps.peakArmDeviation, 4)});
    if (request->saturationLimit > 0.0) {
      margins.rows.push_back({"peak arm deviation with saturation (rad)",
                              a.saturated.diverged ? "diverged" : formatSignificant(a.saturated.peakArmDeviation, 4)});
      margins.rows.push_back({"... with anti-windup (8.32) (rad)",
                              a.saturatedAntiWindup.diverged ? "diverged"
                                                             : formatSignificant(a.saturatedAntiWindup.peakArmDeviation, 4)});
    }
    s.tables.push_back(margins);
    ReportTable poles{"Poles (rad/s)", {"Poles", "Values"}, {}};
    poles.rows.push_back({"closed loop", polesText(d.closedLoopPoles)});
    poles.rows.push_back({"regulator F_y", polesText(d.regulatorPoles)});
    s.tables.push_back(poles);
    s.values["regulator_stability"] = d.regulatorStability();
    s.values["regulator_stable"] = d.rhpRegulatorPoles == 0;
    s.values["rhp_regulator_poles"] = d.rhpRegulatorPoles;
    s.values["closed_loop_stable"] = closedStable;
    s.values["rhp_closed_loop_poles"] = d.rhpClosedLoopPoles;
    s.values["encirclements"] = a.loop.encirclements;
    s.values["expected_encirclements"] = a.expectedEncirclements;
    s.values["max_sensitivity"] = a.maxSensitivity;
    s.values["max_sensitivity_frequency_rad_s"] = a.maxSensitivityFrequency;
    s.values["min_distance_to_minus_one"] = a.minDistanceToMinusOne;
    s.values["bode_integral"] = a.bodeIntegral;
    s.values["bode_prediction"] = a.bodePrediction;
    s.values["peak_arm_deviation"] = a.steps.peakArmDeviation;

    // Nyquist curve of F_y G near -1 (positive frequencies solid, negative mirrored, dashed).
    ReportSeries pos{"F_y G, w > 0", {}, {}, false, 0}, neg{"F_y G, w < 0", {}, {}, true, 0};
    for (const auto& v : a.loop.values) {
      pos.x.push_back(v.real());
      pos.y.push_back(v.imag());
      neg.x.push_back(v.real());
      neg.y.push_back(-v.imag());
    }
    ReportSeries minusOne{"-1", {-1.0}, {0.0}, false, 1};
    ReportPlot ny{"Nyquist curve of F_y G near -1", "Re", "Im", false, false, {pos, neg, minusOne}};
    ny.parametric = true;
    ny.xRange = {{-4.0, 2.0}};
    ny.yRange = {{-3.0, 3.0}};
    s.plots.push_back(ny);
    ReportSeries S{"|S|", a.loop.frequencies, a.sensitivity, false, 0};
    ReportSeries T{"|T|", a.loop.frequencies, a.complementary, true, 1};
    thinSeries(S.x, S.y, 3000);
    thinSeries(T.x, T.y, 3000);
    s.plots.push_back(ReportPlot{"Sensitivity |S| (8.36) and complementary sensitivity |T|",
                                 "frequency (rad/s)", "magnitude", true, true, {S, T}});
    report.sections.push_back(s);
  }
};

}  // namespace

LqgAnalysisOptions LqgRequest::analysisOptions() const {
  LqgAnalysisOptions ao;
  ao.saturationLimit = saturationLimit;
  ao.taBandwidth = taBandwidth;
  return ao;
}

bool LqgRequest::isValid(std::string* why) const {
  if (!(saturationLimit >= 0.0) || !std::isfinite(saturationLimit)) {
    if (why) *why = "the saturation limit must be 0 (none) or positive";
    return false;
  }
  if (!(taBandwidth >= 0.0) || !std::isfinite(taBandwidth)) {
    if (why) *why = "the T_a bandwidth must be 0 (none) or positive";
    return false;
  }
  return design.isValid(why) && analysisOptions().isValid(why);
}

json lqgRequestToJson(const LqgRequest& r) {
  json params = json::object();
  for (const auto& name : TwoMassLqgParameters::names()) params[name] = r.design.parameters.get(name);
  return {{"source", r.source},
          {"parameters", params},
          {"measurement", toString(r.design.measurement)},
          {"integral_action", r.design.integralAction},
          {"q1", vectorToJson(r.design.q1)},
          {"q2", r.design.q2},
          {"r1", vectorToJson(r.design.r1)},
          {"r2", vectorToJson(r.design.r2)},
          {"saturation_limit", r.saturationLimit},
          {"ta_bandwidth", r.taBandwidth}};
}

std::optional<LqgRequest> lqgRequestFromJson(const json& j, std::string* why) {
  auto fail = [&](const std::string& text) -> std::optional<LqgRequest> {
    if (why) *why = "the LQG design: " + text;
    return std::nullopt;
  };
  if (!j.is_object()) return fail("must be an object");
  LqgRequest r;
  std::string reason;
  if (j.contains("source")) {
    if (!j["source"].is_string()) return fail("source must be text");
    r.source = j["source"].get<std::string>();
  }
  if (j.contains("parameters")) {
    if (!j["parameters"].is_object()) return fail("parameters must be an object of J_m, J_a, f_m, f_a, k, d");
    for (const auto& [name, value] : j["parameters"].items()) {
      bool known = false;
      for (const auto& n : TwoMassLqgParameters::names()) known = known || n == name;
      if (!known) return fail("unknown parameter " + inQuotes(name));
      if (!value.is_number()) return fail("parameter " + name + " must be a number");
      r.design.parameters.set(name, value.get<double>());
    }
  }
  if (j.contains("measurement")) {
    auto m = j["measurement"].is_string() ? lqgMeasurementFromString(j["measurement"].get<std::string>())
                                          : std::nullopt;
    if (!m) return fail("measurement must be motor-angle or motor-angle+arm-acceleration");
    r.design.measurement = *m;
  }
  if (j.contains("integral_action")) {
    if (!j["integral_action"].is_boolean()) return fail("integral_action must be true or false");
    r.design.integralAction = j["integral_action"].get<bool>();
  }
  if (!vectorFromJson(j, "q1", r.design.q1, &reason) || !numberFromJson(j, "q2", r.design.q2, &reason) ||
      !vectorFromJson(j, "r1", r.design.r1, &reason) || !vectorFromJson(j, "r2", r.design.r2, &reason) ||
      !numberFromJson(j, "saturation_limit", r.saturationLimit, &reason) ||
      !numberFromJson(j, "ta_bandwidth", r.taBandwidth, &reason))
    return fail(reason);
  if (!r.isValid(&reason)) return fail(reason);
  return r;
}

std::shared_ptr<const SessionPart> makeLqgPart() { return std::make_shared<LqgPart>(); }

}  // namespace flexarm
