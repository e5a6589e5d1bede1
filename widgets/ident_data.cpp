#include "widgets/ident_data.h"

#include <QListWidget>
#include <cmath>

#include "core/ident/nonparametric.h"
#include "core/ident/pem.h"
#include "core/signal/preprocess.h"

namespace flexarm {

std::shared_ptr<PhysicalModel> clonePhysical(const ParametricModel& model) {
  std::unique_ptr<ParametricModel> c = model.clone();
  return std::shared_ptr<PhysicalModel>(static_cast<PhysicalModel*>(c.release()));
}

void fillModelChecklist(QListWidget* list, const std::vector<ModelEntry>& models) {
  QStringList unchecked;
  for (int i = 0; i < list->count(); ++i)
    if (list->item(i)->checkState() != Qt::Checked) unchecked << list->item(i)->text();
  const QSignalBlocker block(list);
  list->clear();
  for (const auto& m : models) {
    auto* item = new QListWidgetItem(m.name, list);
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    item->setCheckState(unchecked.contains(m.name) ? Qt::Unchecked : Qt::Checked);
  }
}

bool isModelChecked(const QListWidget* list, std::size_t index) {
  return static_cast<int>(index) < list->count() &&
         list->item(static_cast<int>(index))->checkState() == Qt::Checked;
}

std::optional<IdentSignals> identSignals(const Workspace& workspace, int decimation,
                                         bool velocityOutput, QString* why) {
  const IdData* current = workspace.current();
  if (!current || !current->input() || !current->output()) {
    if (why) *why = QObject::tr("Open a log with an input and an output channel first.");
    return std::nullopt;
  }
  IdData data = *current;
  QStringList notes;
  if (velocityOutput && data.output()->name == columns::kMotorAngle) {
    data = addDerivative(data);
    notes << QObject::tr("motor velocity from the angle (central differences)");
  }
  if (decimation > 1) {
    DecimateOptions d;
    d.factor = decimation;
    std::string reason;
    if (!d.isValid(&reason)) {
      if (why) *why = QString::fromStdString(reason);
      return std::nullopt;
    }
    data = decimate(data, d);
    notes << QObject::tr("decimated by %1").arg(decimation);
  }
  IdentSignals s;
  s.sampleTime = data.sampleTime;
  s.startTime = data.startTime;
  s.closedLoop = data.isClosedLoop();
  inputOutput(data, s.u, s.y);
  auto rangeOf = [&](RangeKind kind) {
    const auto r = workspace.range(kind);
    return r ? data.rangeForTimes(r->start, r->end) : SampleRange{};
  };
  s.estimation = rangeOf(RangeKind::Estimation);
  if (s.estimation.empty()) s.estimation = {0, data.samples()};
  s.validation = rangeOf(RangeKind::Validation);
  const auto n = static_cast<Eigen::Index>(s.estimation.size());
  if (n < 20) {
    if (why) *why = QObject::tr("The estimation range holds only %1 samples.").arg(n);
    return std::nullopt;
  }
  const auto b = static_cast<Eigen::Index>(s.estimation.begin);
  s.u.array() -= s.u.segment(b, n).mean();
  s.y.array() -= s.y.segment(b, n).mean();
  if (const Channel* ref = data.withRole(ChannelRole::Reference)) {
    s.r = Eigen::Map<const Eigen::VectorXd>(ref->values.data(), static_cast<Eigen::Index>(ref->values.size()));
    s.r.array() -= s.r.segment(b, n).mean();
  }
  notes << QObject::tr("estimation means removed");
  s.note = notes.join(", ");
  return s;
}

int decimationFor(const ModelEntry& entry, double dataSampleTime) {
  if (entry.model || !entry.polynomial || !(dataSampleTime > 0.0)) return 1;
  const double ratio = entry.polynomial->sampleTime / dataSampleTime;
  const long k = std::lround(ratio);
  return k >= 1 && std::abs(ratio - static_cast<double>(k)) < 1e-6 * ratio ? static_cast<int>(k) : 0;
}

bool wantsVelocity(const ModelEntry& entry) {
  return !entry.model || entry.model->options().output == ModelOutput::MotorVelocity;
}

namespace {
bool sameRate(const PolynomialModel& m, double sampleTime, QString* why) {
  if (std::abs(m.sampleTime - sampleTime) <= 1e-9 * sampleTime) return true;
  if (why)
    *why = QObject::tr("estimated at %1 s, the data are sampled at %2 s")
               .arg(m.sampleTime)
               .arg(sampleTime);
  return false;
}
}  // namespace

std::optional<Eigen::VectorXd> simulateEntry(const ModelEntry& entry, const Eigen::VectorXd& u,
                                             double sampleTime, QString* why) {
  if (entry.model) return simulate(*entry.model, u, sampleTime);
  if (!entry.polynomial || !sameRate(*entry.polynomial, sampleTime, why)) return std::nullopt;
  return simulate(*entry.polynomial, u);
}

std::optional<Eigen::VectorXd> residualsOf(const ModelEntry& entry, const Eigen::VectorXd& u,
                                           const Eigen::VectorXd& y, double sampleTime,
                                           QString* why) {
  if (entry.model) return predictionErrors(*entry.model, Eigen::VectorXd(), u, y, sampleTime);
  if (!entry.polynomial || !sameRate(*entry.polynomial, sampleTime, why)) return std::nullopt;
  return predictionErrors(*entry.polynomial, u, y);
}

FrequencyResponse responseOf(const ModelEntry& entry, const std::vector<double>& omega,
                             double level) {
  if (entry.model)
    return frequencyResponse(*entry.model, omega, entry.covariance, entry.covarianceIndices,
                             level);
  std::vector<double> w;
  if (entry.polynomial) {
    const double nyquist = M_PI / entry.polynomial->sampleTime;
    for (double x : omega)
      if (x < nyquist) w.push_back(x);
  }
  if (w.empty()) return FrequencyResponse{};
  return frequencyResponse(*entry.polynomial, w, level);
}

}  // namespace flexarm
