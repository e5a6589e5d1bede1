#include "widgets/discovery_panel.h"

#include <QComboBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPointer>
#include <QProgressBar>
#include <QPushButton>
#include <QSplitter>
#include <QTableWidget>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <algorithm>
#include <cmath>
#include <qcustomplot.h>

#include "core/signal/preprocess.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {

namespace {

const char* kStructures[] = {"two-mass", "three-mass", "four-mass"};

QVector<double> toQ(const std::vector<double>& v) { return QVector<double>(v.begin(), v.end()); }

std::vector<double> difference(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> d(std::min(a.size(), b.size()));
  for (std::size_t k = 0; k < d.size(); ++k) d[k] = a[k] - b[k];
  return d;
}

void setupPlot(QCustomPlot* p, const QString& x, const QString& y) {
  p->xAxis->setLabel(x);
  p->yAxis->setLabel(y);
  p->legend->setVisible(true);
  p->legend->setFont(QFont(p->font().family(), 8));
  placeLegendAbove(p);  // never over the residuals
  p->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(p);
  p->setMinimumHeight(200);  // the legend row above leaves the axis its label's length
}

QCPGraph* addCurve(QCustomPlot* p, const QString& name, const QColor& c) {
  QCPGraph* g = p->addGraph();
  g->setName(name);
  g->setPen(QPen(c, 1.2));
  return g;
}

QString num(double v, int digits = 3) { return QString::number(v, 'g', digits); }

// Amplitude spectrum of a residual against frequency in rad/s (positive values only, for the
// logarithmic axes).
void setSpectrum(QCPGraph* g, const std::vector<double>& x, double sampleTime) {
  const auto s = amplitudeSpectrum(x, sampleTime, static_cast<int>(std::min<std::size_t>(2048, x.size() / 2)));
  QVector<double> w, a;
  for (std::size_t i = 1; i < s.frequencyHz.size(); ++i)
    if (s.amplitude[i] > 0.0) {
      w << 2.0 * M_PI * s.frequencyHz[i];
      a << s.amplitude[i];
    }
  g->setData(w, a, true);
}

}  // namespace

DiscoveryPanel::DiscoveryPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent),
      workspace_(workspace),
      base_(new QComboBox(this)),
      find_(new QPushButton(tr("Find missing effect"), this)),
      cancel_(new QPushButton(tr("Cancel"), this)),
      add_(new QPushButton(tr("Add to model"), this)),
      progress_(new QProgressBar(this)),
      stage_(new QLabel(this)),
      verdict_(new QLabel(this)),
      evidence_(new QLabel(this)),
      where_(new QLabel(this)),
      comparison_(new QLabel(this)),
      table_(new QTableWidget(0, 7, this)),
      residualTime_(new QCustomPlot(this)),
      residualSpectrum_(new QCustomPlot(this)),
      overlay_(new QCustomPlot(this)),
      residualCursor_(new PlayheadCursor(residualTime_, this)),
      overlayCursor_(new PlayheadCursor(overlay_, this)) {
  find_->setObjectName("findMissingEffect");
  add_->setObjectName("addToModel");
  base_->setToolTip(tr("The model to extend: the effect missing from it is looked for"));
  cancel_->setToolTip(tr("Stop the search; no effect is named from a part of it"));
  find_->setToolTip(tr("Fit the base model, map where it disagrees with the log, fit each "
                       "candidate effect and name the one that is significant"));
  add_->setToolTip(tr("Add the base model with the found effect to the model list (undoable)"));
  progress_->setRange(0, 1000);
  progress_->setVisible(false);
  cancel_->setVisible(false);
  add_->setEnabled(false);
  QFont bold = verdict_->font();
  bold.setBold(true);
  bold.setPointSizeF(bold.pointSizeF() * 1.2);
  verdict_->setFont(bold);
  verdict_->setText(tr("Choose a base model and press \"Find missing effect\"."));
  for (QLabel* l : {evidence_, where_, comparison_, stage_}) {
    l->setWordWrap(true);
    l->setTextInteractionFlags(Qt::TextSelectableByMouse);
  }
  table_->setHorizontalHeaderLabels({tr("Effect"), tr("Loss est."), tr("RMS val."), tr("ΔAIC"),
                                     tr("F / threshold"), tr("Significant"), tr("Why")});
  table_->horizontalHeader()->setStretchLastSection(true);
  table_->setWordWrap(true);
  table_->setToolTip(tr("Each candidate effect fitted on the estimation range: its loss, the RMS "
                        "error on the validation range, the AIC change against the base model "
                        "and the F test; hover a cell for its whole text"));
  table_->verticalHeader()->setVisible(false);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setMinimumHeight(150);

  setupPlot(residualTime_, tr("time (s)"), tr("residual (rad/s)"));
  addCurve(residualTime_, tr("base"), QColor(200, 40, 40));
  addCurve(residualTime_, tr("augmented"), QColor(30, 90, 200));
  setupPlot(residualSpectrum_, tr("frequency (rad/s)"), tr("residual amplitude (rad/s)"));
  residualSpectrum_->xAxis->setScaleType(QCPAxis::stLogarithmic);
  residualSpectrum_->yAxis->setScaleType(QCPAxis::stLogarithmic);
  residualSpectrum_->xAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
  residualSpectrum_->yAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
  addCurve(residualSpectrum_, tr("base"), QColor(200, 40, 40));
  addCurve(residualSpectrum_, tr("augmented"), QColor(30, 90, 200));
  setupPlot(overlay_, tr("time (s)"), tr("motor velocity (rad/s)"));
  addCurve(overlay_, tr("measured"), Qt::black);
  addCurve(overlay_, tr("base"), QColor(200, 40, 40));
  addCurve(overlay_, tr("augmented"), QColor(30, 90, 200));

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Base model:"), this));
  top->addWidget(base_, 1);
  top->addWidget(find_);
  top->addWidget(cancel_);
  top->addWidget(add_);
  auto* status = new QHBoxLayout;
  status->addWidget(progress_, 1);
  status->addWidget(stage_, 2);

  auto* plots = new QSplitter(Qt::Vertical, this);
  plots->addWidget(table_);
  plots->addWidget(residualTime_);
  plots->addWidget(residualSpectrum_);
  plots->addWidget(overlay_);
  table_->setMaximumHeight(240);
  plots->setStretchFactor(0, 1);
  for (int i = 1; i < 4; ++i) plots->setStretchFactor(i, 2);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(top);
  layout->addLayout(status);
  layout->addWidget(verdict_);
  layout->addWidget(evidence_);
  layout->addWidget(comparison_);
  layout->addWidget(plots, 1);
  layout->addWidget(where_);

  connect(find_, &QPushButton::clicked, this, &DiscoveryPanel::findMissingEffect);
  connect(cancel_, &QPushButton::clicked, this, &DiscoveryPanel::cancel);
  connect(add_, &QPushButton::clicked, this, &DiscoveryPanel::addToModel);
  connect(&watcher_, &QFutureWatcher<Outcome>::finished, this, &DiscoveryPanel::onFinished);
  connect(workspace_, &Workspace::modelsChanged, this, &DiscoveryPanel::refillModels);
  connect(workspace_, &Workspace::resultWithdrawn, this, [this](const QString& key) {
    if (key == "discovery") clearResult();
  });
  refillModels();
}

DiscoveryPanel::~DiscoveryPanel() {
  if (cancelFlag_) *cancelFlag_ = true;
  watcher_.waitForFinished();
}

void DiscoveryPanel::refillModels() {
  const QString keep = base_->currentText();
  base_->clear();
  const auto& models = workspace_->models();
  for (std::size_t i = 0; i < models.size(); ++i) {
    const auto& m = models[i];
    if (!m.model || m.model->topology().gearStiffness.empty() ||
        m.model->structureName() == "two-mass-theta")
      continue;
    base_->addItem(m.name, static_cast<int>(i));
  }
  for (const char* s : kStructures)
    base_->addItem(tr("%1 (nominal)").arg(s), QString(s));
  const int k = base_->findText(keep);
  if (k >= 0) base_->setCurrentIndex(k);
}

std::unique_ptr<PhysicalModel> DiscoveryPanel::chosenBase(std::vector<Effect>* effects) const {
  const QVariant v = base_->currentData();
  if (v.typeId() == QMetaType::Int) {
    const auto& models = workspace_->models();
    const int i = v.toInt();
    if (i < 0 || i >= static_cast<int>(models.size()) || !models[static_cast<std::size_t>(i)].model)
      return nullptr;
    if (effects) *effects = models[static_cast<std::size_t>(i)].effects;
    return std::unique_ptr<PhysicalModel>(static_cast<PhysicalModel*>(
        models[static_cast<std::size_t>(i)].model->clone().release()));
  }
  if (effects) effects->clear();
  return makeModel(v.toString().toStdString());
}

void DiscoveryPanel::clearResult() {
  if (watcher_.isRunning()) cancel();
  ++run_;
  workspace_->forgetResult("discovery");
  request_.reset();
  result_.reset();
  added_ = false;
  find_->setEnabled(true);
  add_->setEnabled(false);
  cancel_->setVisible(false);
  progress_->setVisible(false);
  verdict_->setText(tr("Choose a base model and press \"Find missing effect\"."));
  for (QLabel* l : {evidence_, where_, comparison_, stage_}) l->clear();
  table_->setRowCount(0);
  clearPlots();
}

void DiscoveryPanel::clearPlots() {
  for (QCustomPlot* p : {residualTime_, residualSpectrum_, overlay_}) {
    for (int g = 0; g < p->graphCount(); ++g) p->graph(g)->data()->clear();
    p->clearItems();
    p->replot();
  }
  residualCursor_->attach();
  overlayCursor_->attach();
}

void DiscoveryPanel::setPlayhead(Playhead* playhead) {
  residualCursor_->setPlayhead(playhead);
  overlayCursor_->setPlayhead(playhead);
}

QString DiscoveryPanel::verdictText() const { return verdict_->text(); }
QString DiscoveryPanel::evidenceText() const { return evidence_->text(); }
QString DiscoveryPanel::comparisonText() const { return comparison_->text(); }

void DiscoveryPanel::findMissingEffect() {
  if (watcher_.isRunning()) return;
  if (!workspace_->current()) {
    verdict_->setText(workspace_->needsResampling()
                          ? tr("Resample the log in the Preprocess panel first: its time stamps are irregular.")
                          : tr("Open a log first."));
    return;
  }
  std::vector<Effect> existing;
  auto base = chosenBase(&existing);
  if (!base) {
    verdict_->setText(tr("Choose a base model."));
    return;
  }
  if (!existing.empty()) {
    verdict_->setText(tr("The chosen model already has effects; choose a model without effects "
                         "as the base."));
    return;
  }
  // Estimation and validation data from the workspace ranges (whole log if none is set).
  const IdData all = workspace_->currentWithRanges();
  pendingData_ = workspace_->dataProvenance();
  auto est = std::make_shared<IdData>(all.estimationRange && !all.estimationRange->empty()
                                          ? all.select(*all.estimationRange)
                                          : all);
  std::shared_ptr<IdData> val;
  if (all.validationRange && !all.validationRange->empty())
    val = std::make_shared<IdData>(all.select(*all.validationRange));
  baseName_ = base_->currentText();
  // The request as a session stores it: the workspace's log as preprocessed, its ranges.
  DiscoveryRequest request;
  if (base_->currentData().typeId() == QMetaType::Int) request.baseModel = base_->currentText().toStdString();
  else request.baseStructure = base_->currentData().toString().toStdString();
  auto seconds = [this](RangeKind k) -> std::optional<SecondsRange> {
    const auto r = workspace_->range(k);
    if (!r || !(r->start < r->end)) return std::nullopt;
    return SecondsRange{r->start, r->end};
  };
  if (all.estimationRange && !all.estimationRange->empty()) request.estimation.range = seconds(RangeKind::Estimation);
  if (val) request.validation = DiscoveryDataRef{"", seconds(RangeKind::Validation)};
  request.options = options_;
  pendingRequest_ = request;
  const int run = ++run_;
  std::shared_ptr<const PhysicalModel> baseModel(std::move(base));
  cancelFlag_ = std::make_shared<std::atomic<bool>>(false);
  auto flag = cancelFlag_;
  const DiscoveryOptions o = options_;
  QPointer<DiscoveryPanel> self(this);
  find_->setEnabled(false);
  add_->setEnabled(false);
  cancel_->setVisible(true);
  progress_->setVisible(true);
  progress_->setValue(0);
  stage_->setText(tr("Fitting the base model..."));
  verdict_->setText(tr("Searching..."));
  evidence_->clear();
  comparison_->clear();
  added_ = false;
  watcher_.setFuture(QtConcurrent::run([est, val, baseModel, o, flag, self, run]() {
    Outcome out;
    out.run = run;
    try {
      auto progress = [flag, self](double f, const std::string& stage) {
        const QString text = QString::fromStdString(stage);
        QMetaObject::invokeMethod(
            qApp,
            [self, f, text] {
              if (!self) return;
              self->progress_->setValue(static_cast<int>(1000 * f));
              self->stage_->setText(text);
            },
            Qt::QueuedConnection);
        return flag->load() ? ProgressAction::Abort : ProgressAction::Continue;
      };
      out.result = std::make_shared<DiscoveryResult>(
          discoverMissingEffect(*baseModel, *est, val.get(), o, progress));
    } catch (const std::exception& e) {
      out.error = QString::fromStdString(e.what());
    }
    return out;
  }));
}

void DiscoveryPanel::cancel() {
  if (cancelFlag_) *cancelFlag_ = true;
  stage_->setText(tr("Cancelling..."));
}

void DiscoveryPanel::onFinished() {
  Outcome out = watcher_.result();
  find_->setEnabled(true);
  cancel_->setVisible(false);
  progress_->setVisible(false);
  if (out.run != run_) {  // a stored result replaced this run while it ran
    emit finished();
    return;
  }
  if (!out.error.isEmpty() || !out.result) {
    verdict_->setText(tr("Discovery failed: %1").arg(out.error));
    emit finished();
    return;
  }
  if (out.result->termination == Termination::Cancelled) {
    verdict_->setText(tr("Cancelled."));
    stage_->clear();
    emit finished();
    return;
  }
  if (out.result->termination == Termination::Failed) {
    verdict_->setText(tr("Discovery failed: %1").arg(QString::fromStdString(out.result->message)));
    emit finished();
    return;
  }
  if (!workspace_->recordResult("discovery", pendingData_)) {  // the data changed meanwhile
    clearResult();
    verdict_->setText(tr("The data changed while discovery ran: press \"Find missing effect\" again."));
    emit finished();
    return;
  }
  result_ = out.result;
  request_ = pendingRequest_;
  showResult();
  emit finished();
}

void DiscoveryPanel::showStored(const DiscoveryRequest& request, const DiscoveryResult& summary) {
  if (watcher_.isRunning()) cancel();
  ++run_;
  request_ = request;
  result_ = std::make_shared<DiscoveryResult>(summary);
  const int k = base_->findText(request.baseModel.empty()
                                    ? tr("%1 (nominal)").arg(QString::fromStdString(request.baseStructure))
                                    : QString::fromStdString(request.baseModel));
  if (k >= 0) base_->setCurrentIndex(k);
  baseName_ = base_->currentText();
  added_ = false;
  find_->setEnabled(true);
  cancel_->setVisible(false);
  progress_->setVisible(false);
  showResult();
  // The summary has no augmented model to add; a new run gives one.
  add_->setEnabled(false);
  stage_->setText(tr("Stored result of the session; \"Find missing effect\" recomputes it with its plots."));
}

void DiscoveryPanel::showResult() {
  const DiscoveryResult& r = *result_;
  QString verdict = r.effect ? tr("Missing effect: %1").arg(toString(*r.effect))
                             : tr("Missing effect: none");
  if (!r.tied.empty()) {
    QStringList t;
    for (EffectKind k : r.tied) t << toString(k);
    verdict += tr("  (tie with %1)").arg(t.join(", "));
  }
  verdict_->setText(verdict);
  evidence_->setText(QString::fromStdString(r.evidence));
  where_->setText(QString::fromStdString(r.disagreement.summary));
  stage_->setText(tr("%1 candidates in %2 s").arg(r.candidates.size()).arg(r.seconds, 0, 'f', 1));
  add_->setEnabled(r.effect.has_value());

  table_->setRowCount(static_cast<int>(r.candidates.size()));
  for (std::size_t i = 0; i < r.candidates.size(); ++i) {
    const CandidateFit& c = r.candidates[i];
    const int row = static_cast<int>(i);
    const QStringList cells = {
        toString(c.kind),
        num(c.lossEst, 4),
        r.hasValidation ? num(c.score.rmsValidation, 4) : tr("no validation range"),
        std::isfinite(c.aic) ? QString::number(c.aic - r.baseAic, 'f', 1) : tr("-"),
        num(c.fStatistic, 3) + " / " + num(c.fThreshold, 3),
        c.significant ? tr("yes") : tr("no"),
        QString::fromStdString(c.reason)};
    for (int col = 0; col < cells.size(); ++col) {
      auto* item = new QTableWidgetItem(cells[col]);
      item->setToolTip(cells[col]);  // the whole text, also when the column wraps it
      if (static_cast<int>(i) == r.best) {
        QFont f = item->font();
        f.setBold(true);
        item->setFont(f);
        item->setBackground(QColor(220, 235, 255));
      }
      table_->setItem(row, col, item);
    }
  }
  // Every column as wide as its text except "Why", which wraps within what is left, so the
  // reason reads whole in the row (and in its tooltip).
  table_->resizeColumnsToContents();
  const int why = table_->columnCount() - 1;
  int others = 0;
  for (int col = 0; col < why; ++col) others += table_->columnWidth(col);
  table_->setColumnWidth(why, std::max(220, table_->viewport()->width() - others));
  table_->resizeRowsToContents();

  // Base residual in time and frequency, the model's resonances marked (a stored summary
  // has no traces).
  const auto& e = r.estimation;
  if (e.time.size() < 8) {
    clearPlots();
    showComparison();
    return;
  }
  const auto baseRes = difference(e.measured, e.base);
  residualTime_->graph(0)->setData(toQ(e.time), toQ(baseRes), true);
  residualTime_->graph(1)->data()->clear();
  residualTime_->rescaleAxes();
  residualTime_->replot();
  residualSpectrum_->clearItems();
  setSpectrum(residualSpectrum_->graph(0), baseRes, r.sampleTime);
  residualSpectrum_->graph(1)->data()->clear();
  residualSpectrum_->rescaleAxes();
  for (double w : r.disagreement.resonancesRadS) {
    auto* line = new QCPItemStraightLine(residualSpectrum_);
    line->point1->setCoords(w, 1e-9);
    line->point2->setCoords(w, 1.0);
    line->setPen(QPen(Qt::darkGreen, 1, Qt::DashLine));
  }
  residualSpectrum_->replot();
  showOverlay();
}

void DiscoveryPanel::showOverlay() {
  const DiscoveryResult& r = *result_;
  const DiscoveryTrace& t = r.hasValidation ? r.validation : r.estimation;
  overlay_->graph(0)->setData(toQ(t.time), toQ(t.measured), true);
  overlay_->graph(1)->setData(toQ(t.time), toQ(t.base), true);
  if (added_) {
    overlay_->graph(2)->setData(toQ(t.time), toQ(t.augmented), true);
    const auto& e = r.estimation;
    const auto augRes = difference(e.measured, e.augmented);
    residualTime_->graph(1)->setData(toQ(e.time), toQ(augRes), true);
    setSpectrum(residualSpectrum_->graph(1), augRes, r.sampleTime);
    residualTime_->replot();
    residualSpectrum_->replot();
  } else {
    overlay_->graph(2)->data()->clear();
  }
  overlay_->xAxis->setLabel(r.hasValidation ? tr("time (s), validation data")
                                            : tr("time (s), estimation data"));
  overlay_->rescaleAxes();
  overlay_->replot();
  showComparison();
}

void DiscoveryPanel::showComparison() {
  const DiscoveryResult& r = *result_;
  // A stored summary shows the augmented scores at once: its model is not in the list.
  const bool after = added_ || (r.effect && r.estimation.time.empty());
  QString text = tr("Base: fit (5.2) %1 % (estimation)").arg(r.base.fitPercent, 0, 'f', 1);
  if (r.hasValidation)
    text += tr(", %1 % (validation), residual RMS %2 rad/s")
                .arg(r.base.fitPercentValidation, 0, 'f', 1)
                .arg(num(r.base.rmsValidation));
  if (after) {
    text += tr(".   Augmented: fit (5.2) %1 % (estimation)").arg(r.augmented.fitPercent, 0, 'f', 1);
    if (r.hasValidation)
      text += tr(", %1 % (validation), residual RMS %2 rad/s (%3 % lower)")
                  .arg(r.augmented.fitPercentValidation, 0, 'f', 1)
                  .arg(num(r.augmented.rmsValidation))
                  .arg(100.0 * (1.0 - r.augmented.rmsValidation / r.base.rmsValidation), 0, 'f', 0);
  }
  comparison_->setText(text + ".");
}

void DiscoveryPanel::addToModel() {
  if (!result_ || !result_->effect || !result_->augmentedModel) return;
  ModelEntry entry;
  QString baseLabel = baseName_;
  baseLabel.remove(tr(" (nominal)"));
  entry.name = tr("%1 + %2").arg(baseLabel, toString(*result_->effect));
  entry.model = result_->augmentedModel;
  entry.effects = result_->augmentedEffects;
  const int index = workspace_->addModel(entry);
  added_ = true;
  add_->setEnabled(false);
  showOverlay();
  emit modelAdded(index);
}

}  // namespace flexarm
