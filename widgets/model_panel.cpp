#include "widgets/model_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QSplitter>
#include <QTableWidget>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <qcustomplot.h>

#include "core/ident/evaluation.h"
#include "core/ident/pole_zero_regions.h"
#include "core/models/analysis.h"
#include "core/models/nonlinear_plant.h"
#include "core/signal/preprocess.h"
#include "core/sim/log_simulation.h"
#include "widgets/ident_data.h"
#include "widgets/plots/bode_plot.h"
#include "widgets/plots/envelope_graph.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"
#include "widgets/plots/pole_zero_plot.h"

namespace flexarm {
namespace {

QString frequenciesText(const std::vector<double>& w) {
  QStringList parts;
  for (double x : w) parts << QString::number(x, 'f', 1);
  return parts.isEmpty() ? QString("-") : parts.join(", ");
}

// FlexArm's one definition of notches and peaks (core/models/analysis.h), said where they show.
const char* const kNotchPeakDefinition =
    "Notches and peaks: the frequencies of the minima and maxima of |G(i w)| (the motor velocity "
    "per torque), what a click on the Bode plot reads; the same numbers as flexarm model, "
    "flexarm fit and the reports. For a lightly damped pair they lie near the imaginary part of "
    "the zero or pole, (5.4).";

}  // namespace

ModelPanel::ModelPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), list_(new QComboBox(this)),
      structure_(new QComboBox(this)), params_(new QTableWidget(0, 4, this)),
      effects_(new QTableWidget(0, 4, this)), bode_(new BodePlot(this)),
      poleZero_(new PoleZeroPlot(this)), frequencies_(new QLabel(this)),
      description_(new QLabel(this)), simulate_(new QPushButton(tr("Simulate against log"), this)),
      compare_(new QCustomPlot(this)), fit_(new QLabel(this)),
      cursor_(new PlayheadCursor(compare_, this)) {
  setObjectName("modelPanel");
  list_->setObjectName("modelList");
  structure_->setObjectName("structureCombo");
  list_->setToolTip(tr("The model of the shared list shown and edited here"));
  structure_->setToolTip(tr("Structure of a new model: rigid, two-mass (5.3) or three-mass (5.1), "
                            "with the seed's Table 5.2 values"));
  for (const auto& s : modelStructureNames()) structure_->addItem(QString::fromStdString(s));
  structure_->setCurrentText("three-mass");
  auto* add = new QPushButton(tr("New model"), this);
  add->setObjectName("newModelButton");
  add->setToolTip(tr("Add a model of the chosen structure to the shared list (undoable)"));
  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Model"), this));
  top->addWidget(list_, 1);
  top->addWidget(structure_);
  top->addWidget(add);

  params_->setObjectName("parameterTable");
  params_->setHorizontalHeaderLabels({tr("Parameter"), tr("Value"), tr("Unit"), tr("Free")});
  params_->verticalHeader()->hide();
  // Columns as wide as their text (a narrow dock scrolls; no value is cut to "0....").
  params_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  params_->horizontalHeader()->setStretchLastSection(true);
  params_->setTextElideMode(Qt::ElideNone);
  params_->verticalHeader()->setDefaultSectionSize(22);
  effects_->setObjectName("effectTable");
  effects_->setHorizontalHeaderLabels({tr("Effect"), tr("On"), tr("Value 1"), tr("Value 2")});
  effects_->verticalHeader()->hide();
  effects_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  effects_->horizontalHeader()->setStretchLastSection(true);
  effects_->setTextElideMode(Qt::ElideNone);
  effects_->verticalHeader()->setDefaultSectionSize(22);
  effects_->setRowCount(static_cast<int>(allEffectKinds().size()));
  for (int r = 0; r < effects_->rowCount(); ++r) {
    const EffectKind k = allEffectKinds()[static_cast<std::size_t>(r)];
    auto* name = new QTableWidgetItem(toString(k));
    name->setFlags(Qt::ItemIsEnabled);
    QStringList tip;
    for (const auto& p : effectParameters(k))
      tip << QString("%1 [%2]: %3").arg(QString::fromStdString(p.name), QString::fromStdString(p.unit),
                                        QString::fromStdString(p.meaning));
    name->setToolTip(tip.join("\n"));
    effects_->setItem(r, 0, name);
  }
  description_->setWordWrap(true);
  frequencies_->setObjectName("frequencyLabel");
  frequencies_->setWordWrap(true);
  frequencies_->setToolTip(tr(kNotchPeakDefinition));
  fit_->setObjectName("fitLabel");
  simulate_->setObjectName("simulateButton");
  simulate_->setToolTip(tr("Simulate the model (ZOH, 5.3) on the open log's input and compare "
                           "with its measured motor velocity (fit 5.2)"));
  compare_->setObjectName("comparePlot");
  compare_->setMinimumHeight(160);
  compare_->xAxis->setLabel(tr("time [s]"));
  compare_->yAxis->setLabel(tr("motor velocity [rad/s]"));
  compare_->legend->setVisible(true);
  compare_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(compare_)->limitAxisToData(compare_->xAxis);
  compare_->axisRect()->setRangeZoom(Qt::Horizontal);
  compare_->axisRect()->setRangeDrag(Qt::Horizontal);
  auto* measured = compare_->addGraph();
  measured->setName(tr("measured"));
  measured->setPen(QPen(QColor(60, 60, 60), 1));
  auto* simulated = compare_->addGraph();
  simulated->setName(tr("simulated"));
  simulated->setPen(QPen(QColor(214, 39, 40), 1.2));

  auto* left = new QWidget(this);
  auto* leftLayout = new QVBoxLayout(left);
  leftLayout->setContentsMargins(0, 0, 0, 0);
  leftLayout->addWidget(description_);
  leftLayout->addWidget(params_, 3);
  leftLayout->addWidget(new QLabel(tr("Effects the linear model lacks:"), this));
  leftLayout->addWidget(effects_, 2);
  auto* right = new QWidget(this);
  auto* rightLayout = new QVBoxLayout(right);
  rightLayout->setContentsMargins(0, 0, 0, 0);
  rightLayout->addWidget(bode_, 3);
  rightLayout->addWidget(frequencies_);
  rightLayout->addWidget(poleZero_, 2);
  auto* split = new QSplitter(Qt::Horizontal, this);
  split->addWidget(left);
  split->addWidget(right);
  split->setStretchFactor(0, 1);
  split->setStretchFactor(1, 1);
  auto* simRow = new QHBoxLayout;
  simRow->addWidget(simulate_);
  simRow->addWidget(fit_, 1);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(top);
  layout->addWidget(split, 3);
  layout->addLayout(simRow);
  layout->addWidget(compare_, 1);

  connect(add, &QPushButton::clicked, this, [this] { newModel(structure_->currentText()); });
  connect(list_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this](int i) {
    if (!filling_) selectModel(i);
  });
  connect(params_, &QTableWidget::cellChanged, this, &ModelPanel::onParameterEdited);
  connect(effects_, &QTableWidget::cellChanged, this, &ModelPanel::onEffectEdited);
  connect(simulate_, &QPushButton::clicked, this, &ModelPanel::simulateAgainstLog);
  connect(&simulation_, &QFutureWatcher<SimOutcome>::finished, this, &ModelPanel::onSimulated);
  connect(workspace_, &Workspace::modelsChanged, this, [this](int index) {
    if (index < 0) refreshList();
    else if (index == current_) refreshModel();
  });
  refreshList();
}

void ModelPanel::refreshList() {
  filling_ = true;
  list_->clear();
  for (const auto& m : workspace_->models()) list_->addItem(nameOf(m));
  filling_ = false;
  const int n = static_cast<int>(workspace_->models().size());
  if (n == 0) {
    current_ = -1;
    refreshModel();
    return;
  }
  selectModel(std::clamp(current_, 0, n - 1));
}

void ModelPanel::selectModel(int index) {
  if (index < 0 || index >= static_cast<int>(workspace_->models().size())) return;
  current_ = index;
  filling_ = true;
  list_->setCurrentIndex(index);
  filling_ = false;
  refreshModel();
}

int ModelPanel::newModel(const QString& structure) {
  ModelEntry e;
  e.model = std::shared_ptr<PhysicalModel>(makeModel(structure.toStdString()));
  int same = 1;
  for (const auto& m : workspace_->models())
    if (nameOf(m).startsWith(structure)) ++same;
  e.name = (same == 1 ? structure : QString("%1 (%2)").arg(structure).arg(same)).toStdString();
  current_ = static_cast<int>(workspace_->models().size());
  const int index = workspace_->addModel(std::move(e));
  selectModel(index);
  return index;
}

void ModelPanel::refreshModel() {
  filling_ = true;
  params_->setRowCount(0);
  bode_->clear();
  poleZero_->clear();
  const bool has = current_ >= 0 && current_ < static_cast<int>(workspace_->models().size());
  simulate_->setEnabled(has);
  if (!has) {
    description_->setText(tr("No model yet: pick a structure and press New model."));
    frequencies_->clear();
    filling_ = false;
    return;
  }
  const ModelEntry& entry = workspace_->models()[static_cast<std::size_t>(current_)];
  if (!entry.model) {  // a black-box estimate: nothing physical to edit here
    simulate_->setEnabled(false);
    description_->setText(tr("%1 is a black-box estimate: the Bode, Compare and Residuals "
                             "panels show it.").arg(nameOf(entry)));
    frequencies_->clear();
    filling_ = false;
    return;
  }
  const PhysicalModel& m = *entry.model;
  description_->setText(QString::fromStdString(m.description()));
  const auto& ps = m.parameters();
  params_->setRowCount(static_cast<int>(ps.size()));
  for (int r = 0; r < static_cast<int>(ps.size()); ++r) {
    const auto& p = ps[static_cast<std::size_t>(r)];
    auto* name = new QTableWidgetItem(QString::fromStdString(p.name));
    name->setFlags(Qt::ItemIsEnabled);
    name->setToolTip(tr("bounds %1 .. %2").arg(p.lower).arg(p.upper));
    auto* value = new QTableWidgetItem(QString::number(p.value, 'g', 6));
    auto* unit = new QTableWidgetItem(QString::fromStdString(p.unit));
    unit->setFlags(Qt::ItemIsEnabled);
    auto* free = new QTableWidgetItem;
    free->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    free->setCheckState(p.free ? Qt::Checked : Qt::Unchecked);
    params_->setItem(r, 0, name);
    params_->setItem(r, 1, value);
    params_->setItem(r, 2, unit);
    params_->setItem(r, 3, free);
  }
  for (int r = 0; r < effects_->rowCount(); ++r) {
    const EffectKind k = allEffectKinds()[static_cast<std::size_t>(r)];
    const Effect* on = nullptr;
    for (const auto& e : entry.effects)
      if (e.kind == k) on = &e;
    const Effect shown = on ? *on : Effect::withDefaults(k);
    auto* check = new QTableWidgetItem;
    check->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    check->setCheckState(on ? Qt::Checked : Qt::Unchecked);
    effects_->setItem(r, 1, check);
    const auto& info = effectParameters(k);
    for (int c = 0; c < 2; ++c) {
      auto* v = new QTableWidgetItem(c < static_cast<int>(info.size())
                                         ? QString("%1 %2").arg(shown.value(c), 0, 'g', 4).arg(QString::fromStdString(info[static_cast<std::size_t>(c)].unit))
                                         : QString());
      if (c >= static_cast<int>(info.size())) v->setFlags(Qt::NoItemFlags);
      effects_->setItem(r, 2 + c, v);
    }
  }
  filling_ = false;

  // Linear analysis of the model with the velocity output (structural effects applied).
  try {
    const StateSpace sys = *analysedStateSpace(entry);
    const auto w = logGrid(1.0, 2000.0, 600);
    BodeCurve curve;
    curve.name = nameOf(entry);
    curve.color = QColor(31, 119, 180);
    curve.frequency = w;
    curve.response = frequencyResponse(sys, w);
    const NotchesPeaks np = notchesAndPeaks(sys);
    curve.extrema = curveExtrema(np, [&](double x) { return std::abs(frequencyResponse(sys, {x}).front()); });
    curve.extremaKnown = true;
    bode_->addCurve(curve);
    poleZero_->addSet(nameOf(entry), QColor(31, 119, 180), poles(sys), zeros(sys));
    // An estimate's 99 % regions, from the covariance of its free parameters (a model with
    // structural effects is analysed through them, so it shows none).
    if (entry.covariance.size() > 0 && entry.effects.empty()) {
      std::shared_ptr<PhysicalModel> linear = clonePhysical(*entry.model);
      linear->setOptions(ModelOptions{});
      std::vector<std::vector<std::complex<double>>> shapes;
      for (const auto& r : poleZeroRegions(linear.get(), entry.covariance, entry.covarianceIndices, nullptr, 0.99))
        shapes.push_back(r.boundary());
      if (!shapes.empty()) poleZero_->addRegions(tr("99 % regions"), QColor(31, 119, 180), shapes);
    }
    frequencies_->setText(tr("Notches %1 rad/s; peaks %2 rad/s")
                              .arg(frequenciesText(np.notches))
                              .arg(frequenciesText(np.peaks)));
  } catch (const std::exception& e) {
    frequencies_->setText(tr("Cannot analyse the model: %1").arg(e.what()));
  }
}

QString ModelPanel::frequencyText() const { return frequencies_->text(); }

bool ModelPanel::setParameter(const QString& name, double value, QString* why) {
  if (current_ < 0) return false;
  ModelEntry entry = workspace_->models()[static_cast<std::size_t>(current_)];
  if (!entry.model) return false;
  auto copy = clonePhysical(*entry.model);
  try {
    copy->setParameter(name.toStdString(), value);
  } catch (const std::exception& e) {
    if (why) *why = QString::fromStdString(e.what());
    refreshModel();  // show the old value again
    return false;
  }
  entry.model = copy;
  entry.covariance.resize(0, 0);  // the estimate's covariance no longer describes it
  entry.covarianceIndices.clear();
  workspace_->replaceModel(current_, entry, tr("set %1 = %2").arg(name).arg(value));
  return true;
}

bool ModelPanel::setEffect(EffectKind kind, bool on, double firstValue) {
  if (current_ < 0) return false;
  ModelEntry entry = workspace_->models()[static_cast<std::size_t>(current_)];
  if (!entry.model) return false;
  std::vector<Effect> effects;
  for (const auto& e : entry.effects)
    if (e.kind != kind) effects.push_back(e);
  if (on) {
    Effect e = Effect::withDefaults(kind);
    for (const auto& old : entry.effects)
      if (old.kind == kind) e = old;
    if (std::isfinite(firstValue)) e.values[0] = firstValue;
    std::string why;
    if (!e.isValid(&why)) {
      refreshModel();
      return false;
    }
    effects.push_back(e);
  }
  entry.effects = effects;
  workspace_->replaceModel(current_, entry,
                           tr("%1 %2").arg(on ? tr("switch on") : tr("switch off")).arg(toString(kind)));
  return true;
}

void ModelPanel::onParameterEdited(int row, int column) {
  if (filling_ || current_ < 0 || !workspace_->models()[static_cast<std::size_t>(current_)].model)
    return;
  const auto& ps = workspace_->models()[static_cast<std::size_t>(current_)].model->parameters();
  const QString name = QString::fromStdString(ps[static_cast<std::size_t>(row)].name);
  if (column == 1) {
    bool ok = false;
    const double v = params_->item(row, 1)->text().toDouble(&ok);
    QString why;
    if (!ok || !std::isfinite(v)) {
      refreshModel();
      params_->setToolTip(tr("'%1' is not a number").arg(params_->item(row, 1)->text()));
    } else if (!setParameter(name, v, &why)) {
      params_->setToolTip(why);
    }
  } else if (column == 3) {
    ModelEntry entry = workspace_->models()[static_cast<std::size_t>(current_)];
    auto copy = clonePhysical(*entry.model);
    const bool free = params_->item(row, 3)->checkState() == Qt::Checked;
    copy->setFree(name.toStdString(), free);
    entry.model = copy;
    workspace_->replaceModel(current_, entry, tr("%1 %2").arg(free ? tr("free") : tr("fix")).arg(name));
  }
}

void ModelPanel::onEffectEdited(int row, int column) {
  if (filling_ || current_ < 0) return;
  const EffectKind kind = allEffectKinds()[static_cast<std::size_t>(row)];
  const bool on = effects_->item(row, 1)->checkState() == Qt::Checked;
  double first = std::nan("");
  if (column == 2) {
    bool ok = false;
    first = effects_->item(row, 2)->text().split(' ').value(0).toDouble(&ok);
    if (!ok) first = std::nan("");
  }
  setEffect(kind, on, first);
}

void ModelPanel::setPlayhead(Playhead* playhead) { cursor_->setPlayhead(playhead); }

void ModelPanel::simulateAgainstLog() {
  const IdData* data = workspace_->current();
  if (current_ < 0 || !data || isSimulating()) return;
  if (!workspace_->models()[static_cast<std::size_t>(current_)].model) return;
  const ModelEntry entry = workspace_->models()[static_cast<std::size_t>(current_)];
  auto log = workspace_->currentShared();  // shared, not copied on the GUI thread
  simulate_->setEnabled(false);
  fit_->setText(tr("Simulating..."));
  simulation_.setFuture(QtConcurrent::run([entry, log]() {
    SimOutcome out;
    try {
      LogSimulationResult r = flexarm::simulateAgainstLog(*entry.model, entry.effects, *log);
      if (!r.ok()) {
        std::string text = r.message + ".";
        text[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
        out.error = QString::fromStdString(text);
        return out;
      }
      out.startTime = r.time.empty() ? log->startTime : r.time.front();
      out.sampleTime = log->sampleTime;
      if (!r.measured.empty()) {
        const auto [lo, hi] = std::minmax_element(r.measured.begin(), r.measured.end());
        const auto [slo, shi] = std::minmax_element(r.simulated.begin(), r.simulated.end());
        out.lo = std::min(*lo, *slo);
        out.hi = std::max(*hi, *shi);
      }
      out.measured = std::make_shared<const EnvelopePyramid>(r.measured);
      out.simulated = std::make_shared<const EnvelopePyramid>(r.simulated);
      out.fit = r.fitPercent;
    } catch (const std::exception& e) {
      out.error = QObject::tr("Simulation failed: %1").arg(QString::fromStdString(e.what()));
    }
    return out;
  }));
}

void ModelPanel::onSimulated() {
  simulate_->setEnabled(true);
  SimOutcome out = simulation_.result();
  if (!out.error.isEmpty()) {
    fit_->setText(out.error);
    return;
  }
  const std::size_t n = out.measured->size();
  if (n > 1) compare_->xAxis->setRange(out.startTime, out.startTime + static_cast<double>(n - 1) * out.sampleTime);
  const double pad = std::max(1e-12, 0.05 * (out.hi - out.lo));
  compare_->yAxis->setRange(out.lo - pad, out.hi + pad);
  // Each graph is fed from its envelope for the visible time range (the previous feed goes).
  int g = 0;
  for (const auto& envelope : {out.measured, out.simulated}) {
    QCPGraph* graph = compare_->graph(g++);
    qDeleteAll(graph->findChildren<EnvelopeGraph*>(Qt::FindDirectChildrenOnly));
    new EnvelopeGraph(graph, envelope, out.startTime, out.sampleTime);
  }
  compare_->replot();
  lastFit_ = out.fit;
  fit_->setText(tr("Fit %1 % (5.2), simulated from the log's torque reference")
                    .arg(out.fit, 0, 'f', 1));
  emit simulationFinished(out.fit);
}

}  // namespace flexarm
