#include "widgets/ident_data.h"

#include <QFileInfo>
#include <QHash>
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

bool ofOpenData(const ModelEntry& entry, const Workspace& workspace) {
  const auto data = entry.dataProvenance();
  return !data || (workspace.hasLog() && sameData(*data, workspace.dataProvenance()));
}

void fillModelChecklist(QListWidget* list, const std::vector<ModelEntry>& models, const Workspace& workspace) {
  constexpr int kOtherData = Qt::UserRole + 1;  // the item was of other data when filled
  struct Was {
    bool checked, other;
  };
  QHash<QString, Was> before;
  for (int i = 0; i < list->count(); ++i)
    before.insert(list->item(i)->text(),
                  {list->item(i)->checkState() == Qt::Checked, list->item(i)->data(kOtherData).toBool()});
  const QSignalBlocker block(list);
  list->clear();
  for (const auto& m : models) {
    const QString name = nameOf(m);
    const bool own = ofOpenData(m, workspace);
    auto* item = new QListWidgetItem(name, list);
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    item->setData(kOtherData, !own);
    const auto was = before.constFind(name);
    // A choice the user made stands while the model's data stay what they were.
    const bool keep = was != before.constEnd() && was->other == !own;
    item->setCheckState((keep ? was->checked : own) ? Qt::Checked : Qt::Unchecked);
    item->setToolTip(QString::fromStdString(m.provenanceText()));
    if (!own) {
      item->setForeground(QColor(130, 130, 130));
      item->setToolTip(QObject::tr("Of other data than the open log: %1").arg(QString::fromStdString(m.provenanceText())));
    }
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
  return {workspace.currentShared(), workspace.range(RangeKind::Estimation), workspace.range(RangeKind::Validation),
          QFileInfo(workspace.logPath()).fileName().toStdString()};
}

EvaluationData evaluationDataOf(const WorkspaceSnapshot& snapshot) {
  return {snapshot.data, snapshot.estimation, snapshot.validation, snapshot.name};
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
