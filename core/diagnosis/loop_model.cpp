#include "core/diagnosis/loop_model.h"

#include <stdexcept>

namespace flexarm {

namespace {

std::unique_ptr<PhysicalModel> physicalClone(const ParametricModel& m) {
  auto copy = m.clone();
  auto* p = dynamic_cast<PhysicalModel*>(copy.get());
  if (!p) throw std::invalid_argument("LoopModel: the plant must be a physical model");
  copy.release();
  return std::unique_ptr<PhysicalModel>(p);
}

}  // namespace

LoopModel::LoopModel(const PhysicalModel& plant, const ControllerOptions& controller)
    : plant_(physicalClone(plant)), originalOutput_(plant.options().output), controller_(controller) {
  std::string why;
  if (!controller.isValid(&why)) throw std::invalid_argument("LoopModel: " + why);
  ModelOptions o = plant_->options();
  o.output = ModelOutput::MotorAngle;
  o.armAcceleration = false;
  plant_->setOptions(o);
  const StateSpace ss = plant_->stateSpace();
  const Eigen::Index n = ss.A.rows();
  ca_ = ss.C.row(0);
  cv_ = Eigen::RowVectorXd::Zero(n);
  cv_(plant_->topology().motorVelocityState) = 1.0;
}

LoopModel::LoopModel(const LoopModel& other)
    : plant_(physicalClone(*other.plant_)),
      originalOutput_(other.originalOutput_),
      controller_(other.controller_),
      ca_(other.ca_),
      cv_(other.cv_) {}

std::string LoopModel::structureName() const { return plant_->structureName() + " in the loop"; }

std::unique_ptr<ParametricModel> LoopModel::clone() const { return std::make_unique<LoopModel>(*this); }

namespace {

// With the first-order hold the reference becomes the loop's last state and the input is its
// slope, held over each sample: exact for a reference that is linear between samples.
void foh(StateSpace& s) {
  const Eigen::Index m = s.A.rows();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m + 1, m + 1);
  A.topLeftCorner(m, m) = s.A;
  A.block(0, m, m, 1) = s.B;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(m + 1, 1);
  B(m, 0) = 1.0;
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(1, m + 1);
  C.leftCols(m) = s.C;
  s.A = A;
  s.B = B;
  s.C = C;
}

// The loop's matrices are affine in the plant's (A, B): A_cl = E A E^T + E B H + const,
// B_cl = E B h + const (E embeds the plant's states), so their derivatives are
// E dA E^T + E dB H and E dB h. u = H X + h phi_ref.
struct LoopLayout {
  Eigen::Index n = 0, m = 0, iState = -1;
  Eigen::RowVectorXd H;
  double h = 0.0;
  Eigen::MatrixXd constA;
  Eigen::VectorXd constB;
};

LoopLayout layout(Eigen::Index n, const Eigen::RowVectorXd& ca, const Eigen::RowVectorXd& cv,
                  const ControllerOptions& c) {
  LoopLayout L;
  L.n = n;
  L.m = n;
  if (c.ti > 0.0) L.iState = L.m++;
  const Eigen::RowVectorXd F = c.kp * ca + cv;  // e_v = k_p phi_ref - F x
  L.H = Eigen::RowVectorXd::Zero(L.m);
  L.H.head(n) = -c.kv * F;
  if (L.iState >= 0) L.H(L.iState) = c.kv / c.ti;
  L.h = c.kv * c.kp;
  L.constA = Eigen::MatrixXd::Zero(L.m, L.m);
  L.constB = Eigen::VectorXd::Zero(L.m);
  if (L.iState >= 0) {
    L.constA.block(L.iState, 0, 1, n) = -F;
    L.constB(L.iState) = c.kp;
  }
  return L;
}

}  // namespace

StateSpace LoopModel::stateSpace() const {
  const StateSpace p = plant_->stateSpace();
  const LoopLayout L = layout(p.A.rows(), ca_, cv_, controller_);
  StateSpace s;
  s.A = L.constA;
  s.A.topLeftCorner(L.n, L.n) += p.A;
  s.A.topRows(L.n) += p.B.col(0) * L.H;
  s.B = L.constB;
  s.B.topRows(L.n) += L.h * p.B.col(0);
  s.C = Eigen::MatrixXd::Zero(1, L.m);
  s.C.leftCols(L.n) = ca_;
  s.D = Eigen::MatrixXd::Zero(1, 1);
  foh(s);
  return s;
}

StateSpaceDerivative LoopModel::derivative(int index) const {
  const StateSpaceDerivative p = plant_->derivative(index);
  const Eigen::Index n = ca_.size();
  const LoopLayout L = layout(n, ca_, cv_, controller_);
  const Eigen::MatrixXd dA = p.dA.size() ? p.dA : Eigen::MatrixXd::Zero(n, n);
  const Eigen::VectorXd dB = p.dB.size() ? Eigen::VectorXd(p.dB.col(0)) : Eigen::VectorXd::Zero(n);
  StateSpaceDerivative d;
  d.dA = Eigen::MatrixXd::Zero(L.m, L.m);
  d.dA.topLeftCorner(n, n) = dA;
  d.dA.topRows(n) += dB * L.H;
  d.dB = Eigen::MatrixXd::Zero(L.m, 1);
  d.dB.topRows(n) = L.h * dB;
  d.dC = Eigen::MatrixXd::Zero(1, L.m);
  d.dD = Eigen::MatrixXd::Zero(1, 1);
  StateSpace t{d.dA, d.dB, d.dC, d.dD, 0.0};
  foh(t);
  t.B.setZero();  // the slope's input column is constant
  d.dA = t.A;
  d.dB = t.B;
  d.dC = t.C;
  return d;
}

Eigen::VectorXd LoopModel::referenceSlopes(const Eigen::VectorXd& reference, double sampleTime) {
  Eigen::VectorXd s = Eigen::VectorXd::Zero(reference.size());
  for (Eigen::Index k = 0; k + 1 < reference.size(); ++k)
    s(k) = (reference(k + 1) - reference(k)) / sampleTime;
  return s;
}

std::unique_ptr<PhysicalModel> LoopModel::plant() const {
  auto p = physicalClone(*plant_);
  ModelOptions o = p->options();
  o.output = originalOutput_;
  p->setOptions(o);
  return p;
}

}  // namespace flexarm
