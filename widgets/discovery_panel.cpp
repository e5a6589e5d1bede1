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
#include <vector>
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
      findAll_(new QPushButton(tr("Find all"), this)),
      cancel_(new QPushButton(tr("Cancel"), this)),
      add_(new QPushButton(tr("Add to model"), this)),
      progress_(new QProgressBar(this)),
      stage_(new QLabel(this)),
      verdict_(new QLabel(this)),
      evidence_(new QLabel(this)),
      where_(new QLabel(this)),
      comparison_(new QLabel(this)),
      table_(new QTableWidget(0, 8, this)),
      step_(new QComboBox(this)),
      ladder_(new QCustomPlot(this)),
      residualTime_(new QCustomPlot(this)),
      residualSpectrum_(new QCustomPlot(this)),
      overlay_(new QCustomPlot(this)),
      residualCursor_(new PlayheadCursor(residualTime_, this)),
      overlayCursor_(new PlayheadCursor(overlay_, this)) {
  find_->setObjectName("findMissingEffect");
  findAll_->setObjectName("findAllEffects");
  findAll_->setToolTip(tr("Find, add, refit the base and every effect found so far, and look again, until no "
                          "effect is missing (at most four)"));
  step_->setToolTip(tr("The step whose candidates, evidence and overlay are shown"));
  add_->setObjectName("addToModel");
  base_->setToolTip(tr("The model to extend (with any effects it has): the effects missing from it are "
                       "looked for"));
  cancel_->setToolTip(tr("Stop the search; no effect is named from a part of it"));
  find_->setToolTip(tr("Fit the base model, map where it disagrees with the log, fit each "
                       "candidate effect and name the one that is significant"));
  add_->setToolTip(tr("Add the base model with every effect found to the model list (undoable)"));
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
                                     tr("F / threshold"), tr("Size"), tr("Significant"), tr("Why")});
  table_->horizontalHeader()->setStretchLastSection(true);
  table_->setWordWrap(true);
  table_->setToolTip(tr("Each candidate effect fitted on the estimation range: its loss, the RMS "
                        "error on the validation range, the AIC change against the base model "
                        "and the F test; hover a cell for its whole text"));
  table_->verticalHeader()->setVisible(false);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);

  setupPlot(residualTime_, tr("time (s)"), tr("residual (rad/s)"));
  addCurve(residualTime_, tr("base"), QColor(200, 40, 40));
  addCurve(residualTime_, tr("augmented"), QColor(30, 90, 200));
  setupPlot(residualSpectrum_, tr("frequency (rad/s)"), tr("amplitude (rad/s)"));
  residualSpectrum_->xAxis->setScaleType(QCPAxis::stLogarithmic);
  residualSpectrum_->yAxis->setScaleType(QCPAxis::stLogarithmic);
  residualSpectrum_->xAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
  residualSpectrum_->yAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
  addCurve(residualSpectrum_, tr("base"), QColor(200, 40, 40));
  addCurve(residualSpectrum_, tr("augmented"), QColor(30, 90, 200));
  // The motor's velocity; the title short enough to fit beside the axis of a short plot.
  setupPlot(overlay_, tr("time (s)"), tr("velocity (rad/s)"));
  addCurve(overlay_, tr("measured"), Qt::black);
  addCurve(overlay_, tr("base"), QColor(200, 40, 40));
  addCurve(overlay_, tr("augmented"), QColor(30, 90, 200));
  // The ladder: held-out residual RMS (bars, left) and fit % (line, right) per step.
  ladder_->setObjectName("ladderPlot");
  // The steps are named by their tick labels (base, + effect ...): the axis needs no title.
  ladder_->yAxis->setLabel(tr("RMS (rad/s)"));
  ladder_->yAxis2->setVisible(true);
  ladder_->yAxis2->setLabel(tr("fit (5.2) %"));
  ladder_->setMinimumHeight(140);
  ladder_->setMinimumWidth(260);
  ladder_->setToolTip(tr("The gap step by step: the held-out residual RMS and fit % of the base and after each "
                         "effect found; click a step to show it"));
  {
    auto* bars = new QCPBars(ladder_->xAxis, ladder_->yAxis);
    bars->setName(tr("held-out residual RMS"));
    bars->setBrush(QColor(200, 40, 40, 120));
    bars->setPen(QPen(QColor(200, 40, 40)));
    bars->setWidth(0.5);
    QCPGraph* fit = ladder_->addGraph(ladder_->xAxis, ladder_->yAxis2);
    fit->setName(tr("held-out fit %"));
    fit->setPen(QPen(QColor(30, 90, 200), 1.6));
    fit->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCircle, 6));
    ladder_->legend->setVisible(true);
    ladder_->legend->setFont(QFont(ladder_->font().family(), 8));
    placeLegendAbove(ladder_);
    ladder_->setInteractions(QCP::iSelectPlottables);
    PlotTools::install(ladder_);
    connect(ladder_, &QCustomPlot::plottableClick, this,
            [this](QCPAbstractPlottable*, int index, QMouseEvent*) { selectStep(index); });
  }

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Base model:"), this));
  top->addWidget(base_, 1);
  top->addWidget(find_);
  top->addWidget(findAll_);
  top->addWidget(cancel_);
  top->addWidget(add_);
  auto* status = new QHBoxLayout;
  status->addWidget(progress_, 1);
  status->addWidget(stage_, 2);

  auto* stepRow = new QHBoxLayout;
  stepRow->addWidget(new QLabel(tr("Step:"), this));
  stepRow->addWidget(step_, 1);
  // The ladder beside the chosen step's candidates, the plots over time and frequency below:
  // the whole panel fits a 1366x768 window.
  auto* rung = new QSplitter(Qt::Horizontal, this);
  rung->addWidget(ladder_);
  rung->addWidget(table_);
  rung->setStretchFactor(0, 2);
  rung->setStretchFactor(1, 3);
  for (QCustomPlot* p : {residualTime_, residualSpectrum_, overlay_}) p->setMinimumHeight(136);
  auto* plots = new QSplitter(Qt::Vertical, this);
  plots->addWidget(rung);
  plots->addWidget(residualTime_);
  plots->addWidget(residualSpectrum_);
  plots->addWidget(overlay_);
  table_->setMaximumHeight(240);
  table_->setMinimumHeight(140);
  plots->setStretchFactor(0, 2);
  for (int i = 1; i < 4; ++i) plots->setStretchFactor(i, 2);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(top);
  layout->addLayout(status);
  layout->addWidget(verdict_);
  layout->addWidget(evidence_);
  layout->addWidget(comparison_);
  layout->addLayout(stepRow);
  layout->addWidget(plots, 1);
  layout->addWidget(where_);

  connect(find_, &QPushButton::clicked, this, &DiscoveryPanel::findMissingEffect);
  connect(findAll_, &QPushButton::clicked, this, &DiscoveryPanel::findAllEffects);
  connect(step_, qOverload<int>(&QComboBox::currentIndexChanged), this, [this](int) { showStep(); });
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
    base_->addItem(nameOf(m), static_cast<int>(i));
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
  findAll_->setEnabled(true);
  add_->setEnabled(false);
  cancel_->setVisible(false);
  progress_->setVisible(false);
  verdict_->setText(tr("Choose a base model and press \"Find missing effect\"."));
  for (QLabel* l : {evidence_, where_, comparison_, stage_}) l->clear();
  table_->setRowCount(0);
  {
    const QSignalBlocker block(step_);
    step_->clear();
  }
  clearPlots();
}

void DiscoveryPanel::clearPlots() {
  for (QCustomPlot* p : {residualTime_, residualSpectrum_, overlay_, ladder_}) {
    for (int g = 0; g < p->graphCount(); ++g) p->graph(g)->data()->clear();
    p->clearItems();
    p->replot();
  }
  if (auto* bars = qobject_cast<QCPBars*>(ladder_->plottable(0))) bars->data()->clear();
  ladder_->replot();
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
QString DiscoveryPanel::stageText() const { return stage_->text(); }

void DiscoveryPanel::findMissingEffect() { run(1); }

void DiscoveryPanel::findAllEffects() { run(4); }

void DiscoveryPanel::run(int maxEffects) {
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
  // The request as a session stores it: the workspace's log as preprocessed, its ranges, the
  // base's effects as the start effects.
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
  request.options.maxEffects = maxEffects;
  request.options.startEffects = existing;
  pendingRequest_ = request;
  const int run = ++run_;
  std::shared_ptr<const PhysicalModel> baseModel(std::move(base));
  cancelFlag_ = std::make_shared<std::atomic<bool>>(false);
  auto flag = cancelFlag_;
  const DiscoveryOptions o = request.options;
  QPointer<DiscoveryPanel> self(this);
  find_->setEnabled(false);
  findAll_->setEnabled(false);
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
      out.result = std::make_shared<DiscoveryResult>(discoverMissingEffect(*baseModel, *est, val.get(), o, progress));
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
  findAll_->setEnabled(true);
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
  // A loop cancelled between steps keeps the steps it finished.
  const bool partial = out.result->termination == Termination::Cancelled && !out.result->found.empty();
  if (out.result->termination == Termination::Cancelled && !partial) {
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
  if (partial) {
    verdict_->setText(tr("Cancelled after %n step(s): ", "", static_cast<int>(result_->found.size())) +
                      verdict_->text());
    stage_->setText(QString::fromStdString(result_->message));
  }
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
  findAll_->setEnabled(true);
  cancel_->setVisible(false);
  progress_->setVisible(false);
  showResult();
  // The summary has no augmented model to add; a new run gives one.
  add_->setEnabled(false);
  stage_->setText(tr("Stored result of the session; \"Find missing effect\" recomputes it with its plots."));
}

void DiscoveryPanel::showResult() {
  const DiscoveryResult& r = *result_;
  QString verdict;
  if (r.found.size() > 1 || (request_ && request_->options.maxEffects > 1)) {
    QStringList names;
    for (const auto& f : r.found)
      names << QString("%1 (%2)").arg(toString(f.kind), f.confirmation.confirmed ? tr("confirmed") : tr("not confirmed"));
    verdict = tr("Missing effects: %1").arg(names.isEmpty() ? tr("none") : names.join(", "));
  } else {
    verdict = r.effect ? tr("Missing effect: %1").arg(toString(*r.effect)) : tr("Missing effect: none");
    if (!r.found.empty()) verdict += r.found[0].confirmation.confirmed ? tr(" (confirmed)") : tr(" (not confirmed)");
  }
  if (!r.tied.empty()) {
    QStringList t;
    for (EffectKind k : r.tied) t << toString(k);
    verdict += tr("  (tie with %1)").arg(t.join(", "));
  }
  // What was tried and rejected, apart from what was found.
  if (!r.alsoTried.empty()) {
    QStringList t;
    for (const auto& x : r.alsoTried) {
      QString name = toString(x.kind);
      if (x.size.measured()) name += tr(" (%1 % of the torques)").arg(100.0 * x.size.share(), 0, 'f', 1);
      if (!t.contains(name)) t << name;
    }
    verdict += "\n" + tr("Also tried, not named: %1").arg(t.join(", "));
  }
  verdict_->setText(verdict);
  stage_->setText(tr("%1 step(s) in %2 s").arg(std::max<std::size_t>(1, r.rounds.size())).arg(r.seconds, 0, 'f', 1));
  add_->setEnabled(!r.found.empty() && r.augmentedModel != nullptr);
  // The steps: every round of a live result; the effects found of a stored summary.
  {
    const QSignalBlocker block(step_);
    step_->clear();
    const std::size_t n = r.rounds.empty() ? std::max<std::size_t>(1, r.found.size()) : r.rounds.size();
    QString model = tr("base");
    for (std::size_t i = 0; i < n; ++i) {
      const std::optional<EffectKind> k =
          r.rounds.empty() ? (i < r.found.size() ? std::optional<EffectKind>(r.found[i].kind) : std::nullopt)
                           : r.rounds[i].effect;
      step_->addItem(k ? tr("Step %1: %2 + %3").arg(i + 1).arg(model, toString(*k))
                       : tr("Step %1: %2, nothing more missing").arg(i + 1).arg(model));
      if (k) model += QString(" + ") + toString(*k);
    }
    step_->setCurrentIndex(0);
  }
  showLadder();
  showStep();
}

void DiscoveryPanel::showLadder() {
  const DiscoveryResult& r = *result_;
  auto* bars = qobject_cast<QCPBars*>(ladder_->plottable(0));
  QVector<double> x, rmsV, fit;
  QSharedPointer<QCPAxisTickerText> ticks(new QCPAxisTickerText);
  const DiscoveryScore& base = r.found.empty() ? r.base : r.found.front().before;
  x << 0;
  rmsV << base.rmsValidation;
  fit << base.fitPercentValidation;
  ticks->addTick(0, tr("base"));
  for (std::size_t i = 0; i < r.found.size(); ++i) {
    x << static_cast<double>(i + 1);
    rmsV << r.found[i].after.rmsValidation;
    fit << r.found[i].after.fitPercentValidation;
    ticks->addTick(static_cast<double>(i + 1), QString("+ ") + toString(r.found[i].kind));
  }
  bars->setData(x, rmsV);
  ladder_->graph(0)->setData(x, fit);
  ladder_->xAxis->setTicker(ticks);
  ladder_->xAxis->setRange(-0.6, static_cast<double>(r.found.size()) + 0.6);
  double top = 0.0;
  for (double v : rmsV) top = std::max(top, std::isfinite(v) ? v : 0.0);
  ladder_->yAxis->setRange(0.0, top > 0.0 ? 1.15 * top : 1.0);
  double lo = 100.0, hi = 0.0;
  for (double v : fit)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (hi < lo) lo = 0.0, hi = 100.0;
  const double pad = std::max(1.0, 0.1 * (hi - lo));
  ladder_->yAxis2->setRange(lo - pad, std::min(100.0 + pad, hi + pad));
  ladder_->replot();
}

void DiscoveryPanel::selectStep(int step) {
  if (step >= 0 && step < step_->count()) step_->setCurrentIndex(step);
}

void DiscoveryPanel::showStep() {
  if (!result_) return;
  const DiscoveryResult& r = *result_;
  const int at = std::max(0, step_->currentIndex());
  const DiscoveryRound* round = at < static_cast<int>(r.rounds.size()) ? &r.rounds[static_cast<std::size_t>(at)] : nullptr;
  const std::vector<CandidateFit>& candidates = round ? round->candidates : r.candidates;
  const int best = round ? round->best : r.best;
  const double aic = round ? round->aic : r.baseAic;
  const bool storedStep = !round && at < static_cast<int>(r.found.size());
  evidence_->setText(QString::fromStdString(round ? round->evidence : storedStep ? r.found[static_cast<std::size_t>(at)].evidence : r.evidence));
  where_->setText(QString::fromStdString(round ? round->disagreement.summary : r.disagreement.summary));

  table_->setRowCount(static_cast<int>(candidates.size()));
  // The named effect's row first, where the table opens; the others in the candidates' order.
  std::vector<std::size_t> order;
  if (best >= 0 && best < static_cast<int>(candidates.size())) order.push_back(static_cast<std::size_t>(best));
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (static_cast<int>(i) != best) order.push_back(i);
  for (std::size_t row0 = 0; row0 < order.size(); ++row0) {
    const std::size_t i = order[row0];
    const CandidateFit& c = candidates[i];
    const int row = static_cast<int>(row0);
    // The confirmation's numbers are in the evidence above and in the tooltip: in the cell
    // they made the named effect's row taller than the table.
    // The size is in its own column: the cell keeps the reason's statistics (the tooltip has
    // every word).
    const QString reason = QString::fromStdString(c.reason);
    const QString why = reason.section("; it adds", 0, 0);
    const QString whyWhole = c.confirmation.ran ? reason + " — " + QString::fromStdString(c.confirmation.text) : reason;
    const QStringList cells = {
        toString(c.kind),
        num(c.lossEst, 4),
        r.hasValidation ? num(c.score.rmsValidation, 4) : tr("no validation range"),
        std::isfinite(c.aic) ? QString::number(c.aic - aic, 'f', 1) : tr("-"),
        num(c.fStatistic, 3) + " / " + num(c.fThreshold, 3),
        // The torque it adds against the model's friction and spring torques.
        c.size.measured() ? QString::number(100.0 * c.size.share(), 'f', 1) + " %" : tr("-"),
        c.significant ? (c.confirmation.ran ? (c.confirmation.confirmed ? tr("yes, confirmed") : tr("yes, not confirmed"))
                                            : tr("yes"))
                      : tr("no"),
        why};
    for (int col = 0; col < cells.size(); ++col) {
      auto* item = new QTableWidgetItem(cells[col]);
      item->setToolTip(col == cells.size() - 1 ? whyWhole : cells[col]);  // the whole text
      if (static_cast<int>(i) == best) {
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
  const int whyCol = table_->columnCount() - 1;
  int others = 0;
  for (int col = 0; col < whyCol; ++col) others += table_->columnWidth(col);
  table_->setColumnWidth(whyCol, std::max(220, table_->viewport()->width() - others));
  table_->resizeRowsToContents();
  table_->scrollToTop();

  // The step's residual before it in time and frequency, the model's resonances marked (a
  // stored summary has no traces).
  const DiscoveryTrace& e = round ? round->estimation : r.estimation;
  if (e.time.size() < 8) {
    for (QCustomPlot* p : {residualTime_, residualSpectrum_, overlay_}) {
      for (int g = 0; g < p->graphCount(); ++g) p->graph(g)->data()->clear();
      p->clearItems();
      p->replot();
    }
    showComparison();
    return;
  }
  const auto before = difference(e.measured, e.base);
  residualTime_->graph(0)->setData(toQ(e.time), toQ(before), true);
  residualTime_->graph(1)->data()->clear();
  residualTime_->rescaleAxes();
  residualTime_->replot();
  residualSpectrum_->clearItems();
  setSpectrum(residualSpectrum_->graph(0), before, r.sampleTime);
  residualSpectrum_->graph(1)->data()->clear();
  residualSpectrum_->rescaleAxes();
  for (double w : (round ? round->disagreement : r.disagreement).resonancesRadS) {
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
  const int at = std::max(0, step_->currentIndex());
  const DiscoveryRound* round = at < static_cast<int>(r.rounds.size()) ? &r.rounds[static_cast<std::size_t>(at)] : nullptr;
  const DiscoveryTrace& t = round ? round->validation : (r.hasValidation ? r.validation : r.estimation);
  const bool named = round ? round->effect.has_value() : !r.found.empty();
  const QString stepName = round && round->effect ? QString("+ ") + toString(*round->effect) : tr("augmented");
  overlay_->graph(0)->setData(toQ(t.time), toQ(t.measured), true);
  overlay_->graph(1)->setName(at == 0 ? tr("base") : tr("before step %1").arg(at + 1));
  overlay_->graph(1)->setData(toQ(t.time), toQ(t.base), true);
  overlay_->graph(2)->setName(stepName);
  // A step that named an effect shows the model with it at once; the one-search result waits
  // for "Add to model" as before.
  const bool showAfter = named && (added_ || r.found.size() > 1 || (request_ && request_->options.maxEffects > 1));
  if (showAfter) {
    overlay_->graph(2)->setData(toQ(t.time), toQ(t.augmented), true);
    const DiscoveryTrace& e = round ? round->estimation : r.estimation;
    const auto after = difference(e.measured, e.augmented);
    residualTime_->graph(1)->setName(stepName);
    residualSpectrum_->graph(1)->setName(stepName);
    residualTime_->graph(1)->setData(toQ(e.time), toQ(after), true);
    setSpectrum(residualSpectrum_->graph(1), after, r.sampleTime);
    residualTime_->replot();
    residualSpectrum_->replot();
  } else {
    overlay_->graph(2)->data()->clear();
  }
  overlay_->xAxis->setLabel(r.heldOutSplit ? tr("time (s), estimation log (held-out blocks inside)")
                                           : tr("time (s), validation data"));
  overlay_->rescaleAxes();
  overlay_->replot();
  showComparison();
}

void DiscoveryPanel::showComparison() {
  const DiscoveryResult& r = *result_;
  // A stored summary shows the final scores at once: its model is not in the list.
  const bool after = added_ || (!r.found.empty() && (r.estimation.time.empty() || r.found.size() > 1));
  // The fit % of every panel is fitPercents (core/ident/evaluation.h); this one is of
  // discovery's predictor, which the tooltip says.
  comparison_->setToolTip(tr("Fit %: the seed's (5.2), %1").arg(QString::fromStdString(r.fitBasis)));
  QString text = tr("Base: fit (5.2) %1 % (estimation)").arg(r.base.fitPercent, 0, 'f', 1);
  text += tr(", %1 % (held out), residual RMS %2 rad/s").arg(r.base.fitPercentValidation, 0, 'f', 1).arg(num(r.base.rmsValidation));
  if (after) {
    text += tr(".   With %n effect(s): fit (5.2) %1 % (estimation)", "", static_cast<int>(r.found.size()))
                .arg(r.augmented.fitPercent, 0, 'f', 1);
    text += tr(", %1 % (held out), residual RMS %2 rad/s (%3 % lower)")
                .arg(r.augmented.fitPercentValidation, 0, 'f', 1)
                .arg(num(r.augmented.rmsValidation))
                .arg(100.0 * (1.0 - r.augmented.rmsValidation / r.base.rmsValidation), 0, 'f', 0);
  }
  if (!r.validationData.empty()) text += tr(".  Held-out data: %1").arg(QString::fromStdString(r.validationData));
  comparison_->setText(text + ".");
}

void DiscoveryPanel::addToModel() {
  if (!result_ || result_->found.empty() || !result_->augmentedModel) return;
  ModelEntry entry;
  QString label = baseName_;
  label.remove(tr(" (nominal)"));
  for (const auto& f : result_->found) label += QString(" + ") + toString(f.kind);
  entry.name = label.toStdString();
  entry.origin = ModelOrigin::Discovery;
  // An extra mass becomes the larger structure: the model list and the fit take it so.
  auto merged = mergedModel(*result_->augmentedModel, result_->augmentedEffects);
  entry.model = std::shared_ptr<const PhysicalModel>(std::move(merged.first));
  entry.effects = merged.second;
  const int index = workspace_->addModel(entry);
  added_ = true;
  add_->setEnabled(false);
  showOverlay();
  emit modelAdded(index);
}

}  // namespace flexarm
