#include "widgets/ident_data.h"

#include <QListWidget>
#include <cmath>

#include "core/ident/nonparametric.h"
#include "core/ident/pem.h"
#include "core/models/nonlinear_plant.h"

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

void useWorkspaceData(const Workspace& workspace, FitOptions& options) {
  options.estimation.clear();
  options.validation.clear();
  auto data = workspace.currentShared();  // shared, not copied on the GUI thread
  if (!data) return;
  auto seconds = [&workspace](RangeKind kind) -> std::optional<SecondsRange> {
    const auto r = workspace.range(kind);
    if (!r) return std::nullopt;
    return SecondsRange{r->start, r->end};
  };
  options.estimation.push_back({data, seconds(RangeKind::Estimation)});
  if (auto v = seconds(RangeKind::Validation)) options.validation.push_back({data, v});
}

QString outputAxisLabel(const Workspace& workspace, bool velocityOutput) {
  const IdData* d = workspace.current();
  const Channel* y = d ? d->output() : nullptr;
  if (!y) return velocityOutput ? QObject::tr("motor velocity [rad/s]") : QObject::tr("output");
  const QString name = QString::fromStdString(y->name);
  const QString unit = QString::fromStdString(y->unit);
  if (velocityOutput)
    return QObject::tr("d/dt %1 [%2/s]").arg(name, unit.isEmpty() ? QString("1") : unit);
  return unit.isEmpty() ? name : QString("%1 [%2]").arg(name, unit);
}

WorkspaceSnapshot snapshotOf(const Workspace& workspace) {
  return {workspace.currentShared(), workspace.range(RangeKind::Estimation),
          workspace.range(RangeKind::Validation)};
}

std::optional<PreparedData> workspaceData(const Workspace& workspace, int decimation, bool velocityOutput,
                                          QString* why) {
  return workspaceData(snapshotOf(workspace), decimation, velocityOutput, why);
}

std::optional<PreparedData> workspaceData(const WorkspaceSnapshot& snapshot, int decimation,
                                          bool velocityOutput, QString* why) {
  const IdData* current = snapshot.data.get();
  if (!current || !current->input() || !current->output()) {
    if (why) *why = QObject::tr("Open a log with an input and an output channel first.");
    return std::nullopt;
  }
  FitDataOptions o;
  o.decimation = decimation;
  o.velocityOutput = velocityOutput;
  if (const auto& r = snapshot.estimation) o.estimation = SecondsRange{r->start, r->end};
  if (const auto& r = snapshot.validation) o.validation = SecondsRange{r->start, r->end};
  std::string reason;
  if (!o.isValid(&reason)) {
    if (why) *why = QString::fromStdString(reason);
    return std::nullopt;
  }
  PreparedData d = prepareFitData(*current, o);
  if (!d.ok()) {
    if (why) *why = QString::fromStdString(d.message);
    return std::nullopt;
  }
  return d;
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
  return estimateResponse(entry.model.get(), entry.covariance, entry.covarianceIndices, entry.polynomial.get(),
                          omega, level);
}

std::optional<StateSpace> analysedStateSpace(const ModelEntry& entry) {
  if (!entry.model) return std::nullopt;
  std::shared_ptr<PhysicalModel> linear = clonePhysical(*entry.model);
  linear->setOptions(ModelOptions{});  // motor velocity, the seed's (5.3) output
  StateSpace sys = linear->stateSpace();
  for (const auto& e : entry.effects)
    if (e.kind == EffectKind::ExtraMass) sys = NonlinearPlant(*linear, {e}).model().stateSpace();
  return sys;
}

}  // namespace flexarm
