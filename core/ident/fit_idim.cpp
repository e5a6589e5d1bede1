// The inverse-dynamics steps of the fit pipeline (core/ident/idim.h): the estimate of method
// idim / idim-iv, and the start values it gives a prediction-error fit of a flexible model.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/ident/fit_internal.h"
#include "core/models/analysis.h"

namespace flexarm {

const char* toString(FitMethod m) {
  switch (m) {
    case FitMethod::PredictionError: return "pem";
    case FitMethod::Idim: return "idim";
    case FitMethod::IdimIv: return "idim-iv";
  }
  return "pem";
}

std::optional<FitMethod> fitMethodFromString(std::string_view s) {
  for (auto m : {FitMethod::PredictionError, FitMethod::Idim, FitMethod::IdimIv})
    if (s == toString(m)) return m;
  return std::nullopt;
}

const char* describe(FitMethod m) {
  switch (m) {
    case FitMethod::PredictionError: return "prediction error (5.7)";
    case FitMethod::Idim:
      return "the rigid part by inverse dynamics in closed form (IDIM-LS): tau = J q'' + F_v q' + F_c sign(q') + "
             "offset by least squares on the low-passed, differentiated position";
    case FitMethod::IdimIv: return "the same with instruments from the position reference (IDIM-IV, closed loop)";
  }
  return "";
}

namespace fit_detail {
namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// The estimation range of the position (the logged angle, or an output that is a position)
// and of the torque, their means kept. False when the data hold no position.
bool positionAndTorque(const PreparedData& d, Eigen::VectorXd& q, Eigen::VectorXd& tau, Eigen::VectorXd& ref) {
  const auto b = static_cast<Eigen::Index>(d.estimation.begin), n = static_cast<Eigen::Index>(d.estimation.size());
  // An output named for a speed or an acceleration (motor_velocity_rad_s, arm_accel_rad_s2, a
  // prismatic axis's motor_velocity_m_s) is no position to differentiate.
  const bool position = !d.differentiated && d.outputName.find("velocity") == std::string::npos &&
                        d.outputName.find("accel") == std::string::npos;
  if (d.angle.size() == d.u.size()) q = d.angle.segment(b, n);
  else if (position) q = d.y.segment(b, n).array() + d.outputMean;
  else return false;
  tau = d.u.segment(b, n).array() + d.inputMean;
  if (d.r.size() == d.u.size()) ref = d.r.segment(b, n).array() + d.referenceMean;
  return true;
}

// A log of a prismatic axis: metadata axis = prismatic, or an output in metres.
bool prismatic(const FitOptions& o) {
  const IdData& data = *o.estimation.front().data;
  if (data.meta("axis") == "prismatic") return true;
  const Channel* out = o.output.empty() ? data.output() : data.channel(o.output);
  return out && out->unit == "m";
}

}  // namespace

bool fitIdim(const FitOptions& o, FitResult& r) {
  auto fail = [&r](const std::string& text) {
    r.termination = Termination::Failed;
    r.message = text;
    r.status = FitStatus::BadData;
    return false;
  };
  Eigen::VectorXd q, tau, ref;
  if (!positionAndTorque(r.data, q, tau, ref))
    return fail("inverse dynamics needs a position: the log's output " + r.data.outputName + " is not one and it has no " +
                std::string(columns::kMotorAngle) + " channel");
  IdimOptions io = o.idim;
  io.instrumentalVariables = o.method == FitMethod::IdimIv;
  io.prismatic = io.prismatic || prismatic(o);
  if (io.instrumentalVariables && ref.size() != q.size())
    return fail("IDIM-IV takes its instruments from the position reference, and the log has none");
  IdimResult e = idim(q, tau, r.data.sampleTime, io, ref);
  if (!e.ok()) return fail(e.message);
  r.summary.termination = Termination::Converged;
  r.summary.message = e.message;
  r.summary.iterations = 0;
  r.summary.loss = (e.torque - e.predicted).squaredNorm() / std::max<Eigen::Index>(1, e.torque.size());
  for (const auto& p : e.parameters) r.parameters.push_back({p.name, p.unit, p.value, p.std, p.lower, p.upper, true, "", true, {}});
  // The rigid model (3.10) of the estimate, for its response: J_m the whole inertia, J_a at
  // its least, f_m the viscous friction (torque reference per unit of speed).
  auto rigid = makeModel("rigid", ModelOptions{ModelOutput::MotorVelocity, false});
  const double r2 = std::pow(rigid->value("r"), 2), JaLeast = rigid->parameters()[1].lower;
  const double J = e.parameters[0].value, fv = e.parameters[1].value;
  if (J - r2 * JaLeast > rigid->parameters()[0].lower && fv >= 0.0 && o.idim.friction == IdimFriction::Symmetric) {
    rigid->setParameter("J_a", JaLeast);
    rigid->setParameter("J_m", J - r2 * JaLeast);
    rigid->setParameter("f_m", fv);
    r.physical = std::shared_ptr<const PhysicalModel>(std::move(rigid));
    r.covariance = e.covariance.topLeftCorner(2, 2);
    r.freeIndices = {0, 2};
  }
  r.idim = std::move(e);
  return true;
}

void idimStart(FitOptions& o, FitResult& r) {
  if (!o.idimStart || o.method != FitMethod::PredictionError || o.model.kind != FitModelKind::Physical) return;
  const PhysicalModel& model = *o.model.start;
  for (const auto& v : o.startValues)
    if (v.name.rfind("J_", 0) == 0 || v.name.rfind("k_", 0) == 0 || v.name.rfind("d_", 0) == 0 || v.name == "f_m" ||
        v.name.rfind("theta", 0) == 0)
      return;  // the user chose start values of the dynamics
  if (model.structureName() == "two-mass-theta") return;
  Eigen::VectorXd q, tau, ref;
  if (!positionAndTorque(r.data, q, tau, ref)) return;
  std::shared_ptr<PhysicalModel> start;
  try {
    start = fitStartModel(o);
  } catch (const std::invalid_argument&) {
    return;  // the options' own problem is reported by the fit
  }
  // Below the start model's first notch the axis moves as one rigid body.
  const double nyquist = 0.5 / r.data.sampleTime;
  double cutoff = nyquist / 10.0;
  ModelOptions velocity;
  auto v = std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(start->clone().release()));
  v->setOptions(velocity);
  const auto notches = notchFrequencies(v->stateSpace());
  if (!notches.empty()) cutoff = std::min(cutoff, 0.3 * notches.front().frequency / (2.0 * M_PI));
  const double seconds = static_cast<double>(q.size()) * r.data.sampleTime;
  if (cutoff * seconds < 20.0) return;  // too short to see the rigid body below the notch
  IdimOptions io;
  io.cutoffHz = cutoff;
  const IdimResult e = idim(q, tau, r.data.sampleTime, io);
  if (!e.ok()) return;
  r.idim = e;
  // Only a rigid body that explains the low-passed torque, with a well-determined inertia,
  // moves the start (data without motion below the notch say nothing of the rigid body).
  if (e.torqueFitPercent < 90.0 || !(e.parameters[0].std < 0.05 * e.parameters[0].value)) {
    r.idimNote = "inverse dynamics below " + number(cutoff) + " Hz (IDIM-LS) explains only " +
                 number(e.torqueFitPercent) + " % of the torque there (the data move too little below the start "
                 "model's first notch), so the start was kept";
    return;
  }
  // The start's inertia seen from the motor, in units of the torque reference: (3.10) with
  // every mass behind the gear.
  double Jb = 0.0;
  for (const auto& p : start->parameters())
    if (p.name.rfind("J_", 0) == 0 && p.name != "J_m") Jb += p.value;
  const double rr = start->value("r"), kT = start->value("k_T");
  const double Jmodel = (start->value("J_m") + rr * rr * Jb) / kT;
  const double s = e.parameters[0].value / Jmodel;
  if (s > 0.5 && s < 2.0) {
    r.idimNote = "inverse dynamics below " + number(cutoff) + " Hz (IDIM-LS) finds the start's inertia within " +
                 number(std::abs(s - 1.0) * 100.0) + " % (J = " + number(e.parameters[0].value) +
                 "), so the start was kept";
    return;
  }
  for (const auto& p : start->parameters()) {
    const bool dynamic = p.name.rfind("J_", 0) == 0 || p.name.rfind("k_", 0) == 0 || p.name.rfind("d_", 0) == 0 ||
                         p.name == "f_m";
    if (!dynamic || p.name == "k_T") continue;
    const double scaled = p.value * s;
    if (scaled < p.lower || scaled > p.upper) continue;
    o.startValues.push_back({p.name, scaled});
  }
  r.idimNote = "inverse dynamics below " + number(cutoff) + " Hz (IDIM-LS) puts the axis's inertia at " +
               number(e.parameters[0].value) + " (torque reference per unit of acceleration), " + number(s) +
               " times the start model's: its inertias, stiffnesses, dampings and f_m started scaled by " +
               number(s) + " (the same resonances)";
}

}  // namespace fit_detail
}  // namespace flexarm
