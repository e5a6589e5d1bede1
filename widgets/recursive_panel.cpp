#include "widgets/recursive_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <qcustomplot.h>

#include "widgets/playhead.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {

namespace {

const char* kStructures[] = {"three-mass", "two-mass", "four-mass", "rigid"};
const char* kSeedParameters[] = {"k_T", "J_a", "f_m"};
const QColor kColors[] = {QColor(30, 90, 200), QColor(200, 60, 30), QColor(30, 150, 60),
                          QColor(150, 60, 170), QColor(200, 150, 20), QColor(20, 150, 160)};

QColor colorOf(std::size_t i) { return kColors[i % (sizeof kColors / sizeof kColors[0])]; }

// An axis label: the name, and below it the unit in brackets as the Log panel writes it (none
// for a dimensionless parameter).
QString axisLabel(const std::string& name, const std::string& unit) {
  const QString n = QString::fromStdString(name);
  if (unit.empty() || unit == "1" || unit == "-") return n;
  return n + "\n[" + QString::fromStdString(unit) + "]";
}

QDoubleSpinBox* spin(QWidget* parent, double lo, double hi, int decimals, double value, double step) {
  auto* s = new QDoubleSpinBox(parent);
  s->setRange(lo, hi);
  s->setDecimals(decimals);
  s->setSingleStep(step);
  s->setValue(value);
  return s;
}

// "5e-8, 5e-7, 5e-6" -> numbers; false for anything else.
bool parseList(const QString& text, std::vector<double>& out) {
  out.clear();
  for (const QString& part : text.split(',', Qt::SkipEmptyParts)) {
    bool ok = false;
    const double v = part.trimmed().toDouble(&ok);
    if (!ok || !std::isfinite(v)) return false;
    out.push_back(v);
  }
  return true;
}

}  // namespace

RecursivePanel::RecursivePanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent),
      workspace_(workspace),
      model_(new QComboBox(this)),
      algorithm_(new QComboBox(this)),
      gradient_(new QComboBox(this)),
      lambda_(spin(this, 0.5, 1.0, 4, 0.995, 0.001)),
      r1_(new QLineEdit(this)),
      r2_(spin(this, 1e-12, 1e12, 4, 1.0, 0.1)),
      mu_(spin(this, 0.0, 1e12, 4, 0.0, 0.1)),
      startOffset_(spin(this, -90.0, 500.0, 1, 20.0, 5.0)),
      decimation_(new QSpinBox(this)),
      tracking_(new QComboBox(this)),
      inverse_(new QCheckBox(tr("theta holds J_a^-1 (seed)"), this)),
      parameters_(new QListWidget(this)),
      overlay_(new QCheckBox(tr("Overlay the previous run"), this)),
      play_(new QPushButton(tr("Play"), this)),
      again_(new QPushButton(tr("Run again"), this)),
      cancel_(new QPushButton(tr("Cancel"), this)),
      progress_(new QProgressBar(this)),
      status_(new QLabel(this)),
      plot_(new QCustomPlot(this)),
      cursor_(new PlayheadCursor(plot_, this)) {
  play_->setObjectName("recursivePlay");
  again_->setObjectName("recursiveRunAgain");
  cancel_->setObjectName("recursiveCancel");
  cancel_->setToolTip(tr("Stop the estimator where it is; the estimates so far stay"));
  cancel_->setEnabled(false);
  progress_->setRange(0, 1000);
  progress_->setValue(0);
  progress_->setFormat(tr("computed %p %"));
  progress_->setToolTip(tr("How far the estimator has computed"));
  play_->setToolTip(tr("Estimate as the log plays (Space pauses; the transport bar sets the speed)"));
  again_->setToolTip(tr("Start again from the log's beginning with the settings as they are now"));
  algorithm_->addItem(tr("forgetting factor (6.1)"), "forgetting");
  algorithm_->addItem(tr("Kalman gain (6.2)"), "kalman");
  tracking_->setObjectName("recursiveTracking");
  tracking_->addItem(tr("fixed"), "fixed");
  tracking_->addItem(tr("variable forgetting"), "variable");
  tracking_->addItem(tr("bank of change times"), "bank");
  tracking_->setToolTip(tr("How changing parameters are followed (the seed's 9.2): lambda or R1 as "
                           "designed; information-constant forgetting, lambda(t) lower while the "
                           "prediction errors grow; or estimators started at hypothesised change "
                           "times every 0.25 s, the change accepted (a dashed line) when one "
                           "explains the data since then better"));
  gradient_->addItem(tr("sensitivity (6.27)"), "sensitivity");
  gradient_->addItem(tr("differences (6.33)"), "difference");
  model_->setToolTip(tr("Model of the shared list the estimator starts from and predicts with"));
  algorithm_->setToolTip(tr("Time update of P: forgetting factor lambda (6.6) or a random walk "
                            "of the parameters with covariance R1 (6.7)"));
  gradient_->setToolTip(tr("How the gradient psi of the prediction is computed: sensitivity "
                           "equations (6.27) or finite differences (6.33)"));
  lambda_->setToolTip(tr("Forgetting factor lambda of (6.6) per 200 Hz sample, 0.5 .. 1; memory "
                         "about 1/(1 - lambda) samples of 5 ms at whatever rate the estimator runs"));
  r2_->setToolTip(tr("Measurement noise variance R2 of the Kalman-gain algorithm"));
  mu_->setToolTip(tr("Regularisation mu of (6.8) and (6.9); 0 switches it off, as the seed's "
                     "experiments do"));
  decimation_->setToolTip(tr("Use every N-th sample (the torque held as its mean over each new "
                             "period); the special value runs at the log's rate up to 2 kHz, "
                             "where the zero-order hold of the torque is exact"));
  r1_->setPlaceholderText(tr("(6.54): 5e-8, 5e-7, 5e-6"));
  r1_->setToolTip(tr("diag R1 per 200 Hz sample, one value per tracked parameter; empty: the "
                     "seed's (6.54)"));
  decimation_->setRange(0, 1000);
  decimation_->setSpecialValueText(tr("log's rate"));
  startOffset_->setSuffix(" %");
  startOffset_->setToolTip(tr("theta(0) = (1 + offset) x nominal; the seed starts 20 % above"));
  inverse_->setChecked(true);
  overlay_->setChecked(true);
  parameters_->setFlow(QListView::LeftToRight);
  parameters_->setWrapping(true);
  parameters_->setMaximumHeight(48);
  parameters_->setToolTip(tr("The parameters to estimate; the others stay at the model's values"));
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  status_->setText(tr("Open a log, pick the model and the parameters, and press Play."));

  // Two columns of label and field, narrow enough to dock beside the log at 1366 pixels.
  auto* grid = new QGridLayout;
  int row = 0;
  auto pair = [&](int column, const QString& label, QWidget* field) {
    grid->addWidget(new QLabel(label, this), row, 2 * column);
    grid->addWidget(field, row, 2 * column + 1);
  };
  grid->addWidget(new QLabel(tr("Model"), this), row, 0);
  grid->addWidget(model_, row++, 1, 1, 3);
  grid->addWidget(new QLabel(tr("Track"), this), row, 0);
  grid->addWidget(parameters_, row, 1, 1, 2);
  grid->addWidget(inverse_, row++, 3);
  pair(0, tr("Algorithm"), algorithm_);
  pair(1, tr("Start"), startOffset_);
  ++row;
  pair(0, tr("lambda"), lambda_);
  pair(1, tr("mu (6.9)"), mu_);
  ++row;
  pair(0, tr("R1"), r1_);
  pair(1, tr("R2"), r2_);
  ++row;
  pair(0, tr("Gradient"), gradient_);
  pair(1, tr("Decimate"), decimation_);
  ++row;
  pair(0, tr("Tracking"), tracking_);
  ++row;
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(play_);
  buttons->addWidget(again_);
  buttons->addWidget(cancel_);
  buttons->addWidget(overlay_);
  buttons->addWidget(progress_, 1);
  grid->addLayout(buttons, row++, 0, 1, 4);
  grid->setColumnStretch(1, 3);
  grid->setColumnStretch(3, 2);
  for (QWidget* w : std::initializer_list<QWidget*>{model_, algorithm_, gradient_, r1_})
    w->setMinimumWidth(60);
  model_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  model_->setMinimumContentsLength(12);
  for (QComboBox* c : {algorithm_, gradient_, tracking_}) {
    c->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    c->setMinimumContentsLength(8);
  }
  inverse_->setText(tr("J_a^-1 (seed)"));
  inverse_->setToolTip(tr("theta holds the inverse of J_a, as the seed does; results use J_a"));
  overlay_->setText(tr("Overlay previous"));
  overlay_->setToolTip(tr("Draw the previous run's estimates beside this one to compare"));

  plot_->setMinimumHeight(340);
  plot_->setNoAntialiasingOnDrag(true);
  // Redrawn every frame while playing: fast polylines and no antialiasing of the curves and
  // bands keep a frame to a few milliseconds (axes and text stay smooth).
  plot_->setPlottingHints(QCP::phFastPolylines | QCP::phCacheLabels);
  plot_->setNotAntialiasedElements(QCP::aePlottables | QCP::aeFills);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(grid);
  layout->addWidget(status_);
  layout->addWidget(plot_, 1);

  connect(play_, &QPushButton::clicked, this, &RecursivePanel::play);
  connect(again_, &QPushButton::clicked, this, &RecursivePanel::runAgain);
  connect(cancel_, &QPushButton::clicked, this, &RecursivePanel::cancel);
  // Showing or hiding the previous run redraws the plots as far as the playhead.
  connect(overlay_, &QCheckBox::toggled, this, [this] {
    buildPlot();
    if (current_) showUpTo(playhead_ ? playhead_->time() : current_->end);
  });
  connect(model_, &QComboBox::currentIndexChanged, this, &RecursivePanel::refillParameters);
  auto algorithmChanged = [this] {
    const bool kalman = algorithm_->currentData().toString() == "kalman";
    lambda_->setEnabled(!kalman);
    r1_->setEnabled(kalman);
    r2_->setEnabled(kalman);
  };
  connect(algorithm_, &QComboBox::currentIndexChanged, this, algorithmChanged);
  algorithmChanged();
  connect(workspace_, &Workspace::modelsChanged, this, &RecursivePanel::refillModels);
  connect(workspace_, &Workspace::logChanged, this, &RecursivePanel::clearRuns);
  connect(workspace_, &Workspace::resultWithdrawn, this, [this](const QString& key) {
    if (key == "recursive") clearRuns();
  });
  connect(plot_, &QCustomPlot::afterReplot, this, &RecursivePanel::frameDrawn);
  refillModels();
  buildPlot();
}

RecursivePanel::~RecursivePanel() {
  runner_.stop();
  if (playhead_) playhead_->release(this);
}

void RecursivePanel::setPlayhead(Playhead* playhead) {
  if (playhead_) disconnect(playhead_, nullptr, this, nullptr);
  playhead_ = playhead;
  cursor_->setPlayhead(playhead);
  if (playhead_) connect(playhead_, &Playhead::timeChanged, this, &RecursivePanel::onTime);
}

void RecursivePanel::refillModels() {
  const QString keep = model_->currentText();
  QSignalBlocker block(model_);
  model_->clear();
  const auto& models = workspace_->models();
  for (std::size_t i = 0; i < models.size(); ++i)
    if (models[i].model) model_->addItem(nameOf(models[i]), static_cast<int>(i));
  for (const char* s : kStructures) model_->addItem(tr("%1 (nominal)").arg(s), QString(s));
  const int k = model_->findText(keep);
  model_->setCurrentIndex(k >= 0 ? k : model_->findData(QString("three-mass")));
  refillParameters();
}

void RecursivePanel::refillParameters() {
  QStringList checked;
  for (int i = 0; i < parameters_->count(); ++i)
    if (parameters_->item(i)->checkState() == Qt::Checked) checked << parameters_->item(i)->text();
  if (checked.isEmpty())
    for (const char* s : kSeedParameters) checked << s;
  parameters_->clear();
  const auto model = chosenModel();
  if (!model) return;
  for (const auto& p : model->parameters()) {
    auto* item = new QListWidgetItem(QString::fromStdString(p.name), parameters_);
    item->setFlags(item->flags() | Qt::ItemIsUserCheckable);
    item->setCheckState(checked.contains(item->text()) ? Qt::Checked : Qt::Unchecked);
  }
}

std::shared_ptr<const PhysicalModel> RecursivePanel::chosenModel() const {
  const QVariant v = model_->currentData();
  if (v.typeId() == QMetaType::Int) {
    const auto& models = workspace_->models();
    const int i = v.toInt();
    if (i < 0 || i >= static_cast<int>(models.size())) return nullptr;
    return models[static_cast<std::size_t>(i)].model;
  }
  if (v.toString().isEmpty()) return nullptr;
  return std::shared_ptr<const PhysicalModel>(makeModel(v.toString().toStdString()));
}

RecursiveRequest RecursivePanel::request() const {
  RecursiveRequest q;
  const QVariant v = model_->currentData();
  if (v.typeId() == QMetaType::Int) q.model = model_->currentText().toStdString();
  else q.structure = v.toString().toStdString();
  q.data.decimation = decimation_->value();
  q.data.maxRateHz = maxRateHz_;
  RecursiveOptions& o = q.options;
  o.designSampleTime = designSampleTime_;
  // The seed's parameters first, in its order (k_T, J_a, f_m), then the others as the model
  // lists them.
  o.estimate.clear();
  std::vector<std::string> checked;
  for (int i = 0; i < parameters_->count(); ++i)
    if (parameters_->item(i)->checkState() == Qt::Checked)
      checked.push_back(parameters_->item(i)->text().toStdString());
  for (const char* seed : kSeedParameters)
    if (std::find(checked.begin(), checked.end(), seed) != checked.end()) o.estimate.push_back(seed);
  for (const auto& name : checked)
    if (std::find(o.estimate.begin(), o.estimate.end(), name) == o.estimate.end()) o.estimate.push_back(name);
  o.inverted = inverse_->isChecked() ? std::vector<std::string>{"J_a"} : std::vector<std::string>{};
  o.algorithm = *recursiveAlgorithmFromString(algorithm_->currentData().toString().toStdString());
  o.gradient = *recursiveGradientFromString(gradient_->currentData().toString().toStdString());
  o.tracking = *recursiveTrackingFromString(tracking_->currentData().toString().toStdString());
  // Variable forgetting belongs to the forgetting factor: with the Kalman gain it stays fixed.
  if (o.tracking == RecursiveTracking::Variable && o.algorithm == RecursiveAlgorithm::Kalman)
    o.tracking = RecursiveTracking::Fixed;
  o.lambda = lambda_->value();
  o.lambdaMin = std::min(o.lambdaMin, o.lambda);
  parseList(r1_->text(), o.r1);
  o.r2 = r2_->value();
  o.mu = mu_->value();
  o.startScale = 1.0 + startOffset_->value() / 100.0;
  return q;
}

void RecursivePanel::setRequest(const RecursiveRequest& q) {
  const int m = q.model.empty() ? model_->findData(QString::fromStdString(q.structure))
                                : model_->findText(QString::fromStdString(q.model));
  if (m >= 0) model_->setCurrentIndex(m);
  for (int i = 0; i < parameters_->count(); ++i) {
    const std::string name = parameters_->item(i)->text().toStdString();
    const bool on = std::find(q.options.estimate.begin(), q.options.estimate.end(), name) !=
                        q.options.estimate.end() ||
                    std::find(q.options.estimate.begin(), q.options.estimate.end(), name + "^-1") !=
                        q.options.estimate.end();
    parameters_->item(i)->setCheckState(on ? Qt::Checked : Qt::Unchecked);
  }
  inverse_->setChecked(std::find(q.options.inverted.begin(), q.options.inverted.end(), "J_a") !=
                       q.options.inverted.end());
  algorithm_->setCurrentIndex(algorithm_->findData(QString(toString(q.options.algorithm))));
  gradient_->setCurrentIndex(gradient_->findData(QString(toString(q.options.gradient))));
  tracking_->setCurrentIndex(tracking_->findData(QString(toString(q.options.tracking))));
  maxRateHz_ = q.data.maxRateHz;
  designSampleTime_ = q.options.designSampleTime;
  lambda_->setValue(q.options.lambda);
  QStringList r1;
  for (double v : q.options.r1) r1 << QString::number(v, 'g', 6);
  r1_->setText(r1.join(", "));
  r2_->setValue(q.options.r2);
  mu_->setValue(q.options.mu);
  startOffset_->setValue(100.0 * (q.options.startScale - 1.0));
  decimation_->setValue(q.data.decimation);
}

std::vector<const RecursivePanel::Run*> RecursivePanel::runs() const {
  std::vector<const Run*> out;
  if (previous_ && overlay_->isChecked()) out.push_back(&*previous_);
  if (current_) out.push_back(&*current_);
  return out;
}

void RecursivePanel::clearRuns() {
  runner_.stop();
  workspace_->forgetResult("recursive");
  current_.reset();
  previous_.reset();
  shown_ = 0;
  if (playhead_) playhead_->release(this);
  holding_ = false;
  buildPlot();
  showProgress();
  status_->setToolTip({});
  status_->setText(workspace_->hasLog() ? tr("Pick the model and the parameters, and press Play.")
                                        : tr("Open a log, pick the model and the parameters, and press Play."));
}

void RecursivePanel::showStored(const QString& summary) {
  if (!current_) status_->setText(summary);
}

QString RecursivePanel::statusText() const { return status_->text(); }

void RecursivePanel::play() {
  const bool stopped = current_ && current_->result &&
                       current_->result->termination == Termination::Cancelled;
  if (!current_ || current_->failure.size() || stopped) {
    startRun();
    if (!current_) return;
    if (playhead_) playhead_->setTime(playhead_->start());
  }
  if (playhead_ && !playhead_->isPlaying()) playhead_->play();
}

void RecursivePanel::runAgain() {
  startRun();
  if (!current_ || !playhead_) return;
  playhead_->setTime(playhead_->start());
  if (!playhead_->isPlaying()) playhead_->play();
}

void RecursivePanel::cancel() {
  if (!current_ || current_->finished) return;
  runner_.cancel();  // the last chunk (termination cancelled) follows
  if (playhead_) {
    playhead_->pause();
    playhead_->release(this);
  }
  holding_ = false;
  status_->setText(tr("Cancelling..."));
}

void RecursivePanel::showProgress() {
  const Run* run = current_ ? &*current_ : nullptr;
  const bool running = run && !run->finished;
  cancel_->setEnabled(running);
  double fraction = 0.0;
  if (run && run->end > run->start)
    fraction = std::clamp((run->reached - run->start) / (run->end - run->start), 0.0, 1.0);
  if (run && run->finished && run->result && run->result->termination == Termination::Converged)
    fraction = 1.0;
  progress_->setValue(static_cast<int>(std::lround(1000.0 * fraction)));
}

void RecursivePanel::startRun() {
  if (!workspace_->hasLog()) {
    status_->setText(tr("Open a log first."));
    return;
  }
  const auto model = chosenModel();
  RecursiveRequest q = request();
  std::vector<double> r1;
  std::string why;
  if (!parseList(r1_->text(), r1)) why = "R1 must be numbers separated by commas";
  else if (!model) why = "pick a model";
  else if (q.options.estimate.empty()) why = "tick at least one parameter to track";
  else if (!q.isValid(&why)) {}
  if (!why.empty()) {
    status_->setText(tr("Cannot start: %1.").arg(QString::fromStdString(why)));
    return;
  }
  if (current_ && !current_->rows.time.empty()) previous_ = std::move(current_);
  current_.emplace();
  current_->id = ++nextRun_;
  q.label = "run " + std::to_string(current_->id);
  current_->request = q;
  shown_ = 0;
  buildPlot();
  showProgress();
  status_->setToolTip({});
  status_->setText(tr("Preparing the log and choosing P(0)..."));
  // The runs are results of the log as read from their start (Workspace::recordResult).
  workspace_->recordResult("recursive", workspace_->dataProvenance(), true);
  auto log = std::make_shared<const IdData>(*workspace_->raw());
  runner_.start(current_->id, log, model, q.data, q.options, [this](RecursiveRunner::Chunk c) {
    QMetaObject::invokeMethod(this, [this, c = std::move(c)]() mutable { onChunk(std::move(c)); },
                              Qt::QueuedConnection);
  });
  runner_.setTarget((playhead_ ? playhead_->start() : 0.0) + 0.5);
}

void RecursivePanel::onChunk(RecursiveRunner::Chunk c) {
  if (!current_ || c.run != current_->id) return;  // a run replaced since
  Run& run = *current_;
  if (!c.failure.empty()) {
    run.failure = QString::fromStdString(c.failure);
    run.finished = true;
    status_->setText(tr("The run could not start: %1").arg(run.failure));
    showProgress();
    updateHold();
    emit runFinished();
    return;
  }
  if (!c.parameters.empty() || c.sampleTime > 0.0) {
    run.parameters = c.parameters;
    run.start = c.startTime;
    run.end = c.endTime;
    run.sampleTime = c.sampleTime;
    buildPlot();
    status_->setToolTip(QString::fromStdString(c.preparation));
  }
  RecursiveTrajectory& all = run.rows;
  const RecursiveTrajectory& add = c.rows;
  auto extend = [](std::vector<double>& to, const std::vector<double>& from) {
    to.insert(to.end(), from.begin(), from.end());
  };
  extend(all.time, add.time);
  extend(all.y, add.y);
  extend(all.yhat, add.yhat);
  extend(all.epsilon, add.epsilon);
  extend(all.noiseVariance, add.noiseVariance);
  extend(all.lambda, add.lambda);
  extend(all.changeDetected, add.changeDetected);
  extend(all.changeTime, add.changeTime);
  for (auto* m : {&all.theta, &all.pDiagonal, &all.sigma}) m->resize(run.parameters.size());
  for (std::size_t i = 0; i < add.theta.size() && i < run.parameters.size(); ++i) {
    extend(all.theta[i], add.theta[i]);
    extend(all.pDiagonal[i], add.pDiagonal[i]);
    extend(all.sigma[i], add.sigma[i]);
  }
  run.reached = c.reached;
  if (!c.finished && run.sampleTime > 0.0) {
    QStringList names;
    for (const auto& q : run.parameters) names << QString::fromStdString(q.modelName);
    status_->setText(tr("Estimating %1 at %2 Hz: %3 of %4 s computed.")
                         .arg(names.join(", "))
                         .arg(1.0 / run.sampleTime, 0, 'g', 4)
                         .arg(std::max(0.0, run.reached - run.start), 0, 'f', 1)
                         .arg(run.end - run.start, 0, 'f', 1));
  }
  if (c.finished) {
    run.finished = true;
    run.result = c.result;
    if (run.result) {
      // Two lines at most (the plots keep their height): the verdict, then the final values
      // with sigma in the model's units; the caveat, when there is one, in the tooltip.
      QStringList values;
      for (const auto& e : run.result->estimates) {
        const std::string& unit = e.parameter.modelUnit;
        values << QString::fromUtf8("%1 = %2 ± %3%4")
                      .arg(QString::fromStdString(e.parameter.modelName))
                      .arg(e.modelFinal, 0, 'g', 4)
                      .arg(e.modelSigma, 0, 'g', 2)
                      .arg(unit.empty() || unit == "1" ? QString() : " " + QString::fromStdString(unit));
      }
      QString text = QString::fromStdString(run.result->message) + "\n" + values.join(",  ");
      if (run.request.options.tracking == RecursiveTracking::Variable && !run.rows.lambda.empty())
        text += tr("; lambda(t) down to %1")
                    .arg(*std::min_element(run.rows.lambda.begin(), run.rows.lambda.end()), 0, 'f', 4);
      QString tip = status_->toolTip();
      if (!run.result->caveat.empty()) {
        text += QString::fromUtf8(" (σ understates: hover)");
        tip += (tip.isEmpty() ? "" : "\n\n") + QString::fromStdString(run.result->caveat);
      }
      status_->setText(text);
      status_->setToolTip(tip);
    }
    emit runFinished();
  }
  showProgress();
  showUpTo(playhead_ ? playhead_->time() : run.end);
  updateHold();
}

void RecursivePanel::onTime(double t) {
  // The estimator computes a little ahead of the playhead (the rows wait in the cache), so
  // that a frame finds its rows ready instead of waiting for a round trip to the runner.
  if (current_ && !current_->finished)
    runner_.setTarget(t + std::max(0.5, playhead_ ? 6.0 * playhead_->frameSeconds() : 0.0));
  showUpTo(t);
  updateHold();
}

// While playing, a run that has fallen behind the playhead holds it (the playhead's
// contract) until it has caught up; a small lag (a few frames) is drawn as it comes.
void RecursivePanel::updateHold() {
  if (!playhead_) return;
  const bool behind = current_ && !current_->finished &&
                      playhead_->time() > current_->reached +
                                              std::max(0.1, 3.0 * playhead_->frameSeconds());
  if (behind && !holding_) playhead_->hold(this);
  if (!behind && holding_) playhead_->release(this);
  holding_ = behind;
}

void RecursivePanel::buildPlot() {
  plot_->clearGraphs();
  plot_->clearItems();
  changesShown_ = 0;
  plot_->plotLayout()->clear();
  graphs_.clear();
  epsilon_ = nullptr;
  const Run* run = current_ ? &*current_ : nullptr;
  const std::size_t p = run ? run->parameters.size() : 0;
  auto addRect = [this](int row, const QString& label) {
    auto* rect = new QCPAxisRect(plot_);
    plot_->plotLayout()->addElement(row, 0, rect);
    QFont small = plot_->font();
    small.setPointSizeF(std::max(6.0, small.pointSizeF() - 1.5));
    for (QCPAxis* a : rect->axes()) {
      a->setTickLabelFont(small);
      a->setLabelFont(small);
    }
    rect->axis(QCPAxis::atLeft)->setLabel(label);
    // Three ticks: the rects are short, more labels would run into each other.
    rect->axis(QCPAxis::atLeft)->ticker()->setTickCount(3);
    rect->axis(QCPAxis::atLeft)->ticker()->setTickStepStrategy(QCPAxisTicker::tssMeetTickCount);
    rect->axis(QCPAxis::atBottom)->setTickLabels(false);
    rect->setupFullAxesBox(true);
    // Stacked close (the time axis' labels only under the last one): the rects keep their
    // height in a dock of 768 pixels.
    rect->setAutoMargins(QCP::msLeft | QCP::msRight | QCP::msBottom);
    rect->setMargins(QMargins(0, 3, 0, 0));
    rect->setRangeDrag(Qt::Horizontal);
    rect->setRangeZoom(Qt::Horizontal);
    return rect;
  };
  int row = 1;  // row 0: the legend (buildLegend)
  for (std::size_t i = 0; i < p; ++i) {
    const RecursiveParameter& q = run->parameters[i];
    ParameterGraphs g;
    g.rect = addRect(row++, axisLabel(q.modelName, q.modelUnit));
    QCPAxis* x = g.rect->axis(QCPAxis::atBottom);
    QCPAxis* y = g.rect->axis(QCPAxis::atLeft);
    const QColor c = colorOf(i);
    QColor band = c;
    band.setAlpha(50);
    g.lower = plot_->addGraph(x, y);
    g.upper = plot_->addGraph(x, y);
    g.lower->setPen(Qt::NoPen);
    g.upper->setPen(Qt::NoPen);
    g.upper->setBrush(QBrush(band));
    g.upper->setChannelFillGraph(g.lower);
    g.estimate = plot_->addGraph(x, y);
    g.estimate->setPen(QPen(c, 1.5));
    g.previous = plot_->addGraph(x, y);
    g.previous->setPen(QPen(QColor(90, 90, 90), 1.2, Qt::DashLine));
    const double nominal = q.toModel(q.nominal);
    auto* line = new QCPItemStraightLine(plot_);
    line->setClipAxisRect(g.rect);
    line->point1->setAxes(x, y);
    line->point2->setAxes(x, y);
    line->point1->setCoords(0.0, nominal);
    line->point2->setCoords(1.0, nominal);
    line->setPen(QPen(Qt::black, 1.0, Qt::DashLine));
    const double start = q.toModel(run->request.options.startScale * q.nominal);
    g.lo = std::min(nominal, start);
    g.hi = std::max(nominal, start);
    const double margin = 0.1 * std::max(std::abs(g.hi - g.lo), 0.05 * std::abs(nominal));
    y->setRange(g.lo - margin, g.hi + margin);
    graphs_.push_back(g);
  }
  epsilonRect_ = addRect(row++, tr("pred. error\n[rad/s]"));
  epsilon_ = plot_->addGraph(epsilonRect_->axis(QCPAxis::atBottom), epsilonRect_->axis(QCPAxis::atLeft));
  epsilon_->setPen(QPen(QColor(60, 60, 60), 1.0));
  pRect_ = addRect(row++, tr("diag P\n[units²]"));
  QCPAxis* py = pRect_->axis(QCPAxis::atLeft);
  py->setScaleType(QCPAxis::stLogarithmic);
  auto logTicker = QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog);
  logTicker->setTickCount(3);
  logTicker->setSubTickCount(0);
  py->setTicker(logTicker);
  py->setNumberFormat("eb");  // 10^-4 as a power
  py->setNumberPrecision(0);
  for (std::size_t i = 0; i < graphs_.size(); ++i) {
    graphs_[i].p = plot_->addGraph(pRect_->axis(QCPAxis::atBottom), py);
    graphs_[i].p->setPen(QPen(colorOf(i), 1.5));
    graphs_[i].p->setName(QString("P: ") + QString::fromStdString(run->parameters[i].name));
  }
  pRect_->axis(QCPAxis::atBottom)->setTickLabels(true);
  pRect_->axis(QCPAxis::atBottom)->setLabel(tr("time [s]"));
  // One time axis for every rect.
  const double t0 = run && run->sampleTime > 0.0 ? run->start
                    : (playhead_ && playhead_->hasSpan() ? playhead_->start() : 0.0);
  const double t1 = run && run->sampleTime > 0.0 ? run->end
                    : (playhead_ && playhead_->hasSpan() ? playhead_->end() : 1.0);
  auto* group = new QCPMarginGroup(plot_);
  for (QCPAxisRect* rect : plot_->axisRects()) {
    rect->axis(QCPAxis::atBottom)->setRange(t0, std::max(t1, t0 + 1e-9));
    rect->setMarginGroup(QCP::msLeft | QCP::msRight, group);
    for (QCPAxisRect* other : plot_->axisRects())
      if (other != rect)
        connect(rect->axis(QCPAxis::atBottom), qOverload<const QCPRange&>(&QCPAxis::rangeChanged),
                other->axis(QCPAxis::atBottom), qOverload<const QCPRange&>(&QCPAxis::setRange));
  }
  py->setRange(1e-8, 1.0);
  epsilonRect_->axis(QCPAxis::atLeft)->setRange(-1.0, 1.0);
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(plot_);
  keepRectsTall(plot_, 80);  // the parameters, P and the prediction error stacked
  plot_->setMinimumHeight(std::max(340, plot_->minimumHeight()));
  drawOverlay();
  buildLegend();
  if (graphs_.empty()) plot_->plotLayout()->simplify();  // no legend: no empty row above
  cursor_->attach();
  shown_ = 0;
  plot_->replot();
}

// One legend row above the plots: what the lines of every parameter's plot mean (samples
// drawn by graphs without data, added after the others), and whose P each colour is.
void RecursivePanel::buildLegend() {
  if (graphs_.empty()) return;
  auto* legend = new QCPLegend;
  plot_->plotLayout()->addElement(0, 0, legend);
  plot_->plotLayout()->setRowStretchFactor(0, 0.001);
  legend->setFillOrder(QCPLayoutGrid::foColumnsFirst);
  legend->setWrap(4);
  legend->setBorderPen(Qt::NoPen);
  legend->setBrush(Qt::NoBrush);
  QFont small = plot_->font();
  small.setPointSizeF(std::max(6.0, small.pointSizeF() - 1.5));
  legend->setFont(small);
  legend->setIconSize(18, 12);
  legend->setMargins(QMargins(2, 1, 2, 2));
  QCPAxis* x = graphs_.front().rect->axis(QCPAxis::atBottom);
  QCPAxis* y = graphs_.front().rect->axis(QCPAxis::atLeft);
  auto sample = [&](const QString& name, const QPen& pen, const QBrush& brush = Qt::NoBrush) {
    QCPGraph* g = plot_->addGraph(x, y);
    g->setName(name);
    g->setPen(pen);
    g->setBrush(brush);
    g->addToLegend(legend);
  };
  sample(tr("estimate"), QPen(QColor(60, 60, 60), 1.5));
  sample(QString::fromUtf8("±3σ"), Qt::NoPen, QColor(60, 60, 60, 90));
  sample(tr("nominal"), QPen(Qt::black, 1.0, Qt::DashLine));
  if (previous_ && overlay_->isChecked() && current_)
    sample(tr("previous (%1)").arg(QString::fromStdString(previous_->request.label)), QPen(QColor(90, 90, 90), 1.2, Qt::DashLine));
  for (auto& g : graphs_) g.p->addToLegend(legend);
  // Room below the text for the underscores of the parameters' names.
  for (int i = 0; i < legend->itemCount(); ++i)
    if (QCPAbstractLegendItem* item = legend->item(i)) item->setMargins(QMargins(6, 1, 6, 4));
}

void RecursivePanel::drawOverlay() {
  if (!previous_ || !overlay_->isChecked()) return;
  const Run& old = *previous_;
  for (std::size_t i = 0; i < graphs_.size() && current_; ++i) {
    const std::string& name = current_->parameters[i].modelName;
    for (std::size_t j = 0; j < old.parameters.size() && j < old.rows.theta.size(); ++j) {
      if (old.parameters[j].modelName != name) continue;
      QVector<double> t(old.rows.time.begin(), old.rows.time.end()), v;
      v.reserve(t.size());
      for (double th : old.rows.theta[j]) v << old.parameters[j].toModel(th);
      graphs_[i].previous->setData(t, v, true);
      graphs_[i].previous->setName(QString::fromStdString(old.request.label));
    }
  }
}

void RecursivePanel::showUpTo(double t) {
  if (!current_ || graphs_.size() != current_->parameters.size() || !epsilon_) return;
  const Run& run = *current_;
  const auto& time = run.rows.time;
  const auto target = static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), t + 1e-9) - time.begin());
  if (target > shown_) {
    const std::size_t from = shown_;
    const auto count = static_cast<int>(target - from);
    QVector<double> keys(time.begin() + static_cast<std::ptrdiff_t>(from), time.begin() + static_cast<std::ptrdiff_t>(target));
    for (std::size_t i = 0; i < graphs_.size(); ++i) {
      ParameterGraphs& g = graphs_[i];
      const RecursiveParameter& q = run.parameters[i];
      QVector<double> est(count), lo(count), hi(count), pd(count);
      for (int k = 0; k < count; ++k) {
        const std::size_t r = from + static_cast<std::size_t>(k);
        const double th = run.rows.theta[i][r];
        const double value = q.toModel(th);
        const double s = 3.0 * q.sigmaToModel(th, run.rows.sigma[i][r]);
        est[k] = value;
        lo[k] = value - s;
        hi[k] = value + s;
        pd[k] = run.rows.pDiagonal[i][r];
        // The band may be wide at the start (P(0) before the estimate settles): the axis
        // follows the estimate, and the band only while it stays within twice its span.
        g.lo = std::min(g.lo, value);
        g.hi = std::max(g.hi, value);
      }
      g.estimate->addData(keys, est, true);
      g.lower->addData(keys, lo, true);
      g.upper->addData(keys, hi, true);
      g.p->addData(keys, pd, true);
      const double margin = 0.15 * std::max(g.hi - g.lo, 1e-3 * std::abs(q.toModel(q.nominal)));
      g.rect->axis(QCPAxis::atLeft)->setRange(g.lo - margin, g.hi + margin);
    }
    QVector<double> eps(run.rows.epsilon.begin() + static_cast<std::ptrdiff_t>(from),
                        run.rows.epsilon.begin() + static_cast<std::ptrdiff_t>(target));
    epsilon_->addData(keys, eps, true);
    double e = epsilonRect_->axis(QCPAxis::atLeft)->range().upper;
    for (double v : eps) e = std::max(e, 1.1 * std::abs(v));
    epsilonRect_->axis(QCPAxis::atLeft)->setRange(-e, e);
    bool anyP = false;
    QCPRange pr = pRect_->axis(QCPAxis::atLeft)->range();
    for (auto& g : graphs_) {
      bool found = false;
      const QCPRange r = g.p->getValueRange(found);
      if (found && r.lower > 0.0) {
        pr = anyP ? QCPRange(std::min(pr.lower, r.lower), std::max(pr.upper, r.upper)) : r;
        anyP = true;
      }
    }
    if (anyP) pRect_->axis(QCPAxis::atLeft)->setRange(pr.lower / 2.0, pr.upper * 2.0);
  } else if (target < shown_) {
    const double cut = target > 0 ? time[target - 1] : run.start - 1.0;
    for (auto& g : graphs_)
      for (QCPGraph* graph : {g.estimate, g.lower, g.upper, g.p}) graph->data()->removeAfter(cut + 1e-12);
    epsilon_->data()->removeAfter(cut + 1e-12);
  } else {
    return;
  }
  shown_ = target;
  showChanges(target > 0 ? time[target - 1] : run.start - 1.0);
  plot_->replot(QCustomPlot::rpQueuedReplot);
}

// The changes the bank accepted up to time t: a dashed line at each hypothesised change time
// in every estimate's rect, drawn once its detection time is shown.
void RecursivePanel::showChanges(double t) {
  const RecursiveTrajectory& rows = current_->rows;
  std::size_t due = 0;
  while (due < rows.changeDetected.size() && rows.changeDetected[due] <= t + 1e-9) ++due;
  if (due == changesShown_) return;
  for (int i = plot_->itemCount() - 1; i >= 0; --i)
    if (plot_->item(i)->objectName() == "change") plot_->removeItem(i);
  for (std::size_t c = 0; c < due; ++c)
    for (const ParameterGraphs& g : graphs_) {
      auto* line = new QCPItemStraightLine(plot_);
      line->setObjectName("change");
      line->setClipAxisRect(g.rect);
      for (auto* p : {line->point1, line->point2}) p->setAxes(g.rect->axis(QCPAxis::atBottom), g.rect->axis(QCPAxis::atLeft));
      line->point1->setCoords(rows.changeTime[c], 0.0);
      line->point2->setCoords(rows.changeTime[c], 1.0);
      line->setPen(QPen(QColor(150, 60, 170), 1.2, Qt::DashLine));
    }
  changesShown_ = due;
}

void RecursivePanel::frameDrawn() {
  if (!fpsClock_.isValid()) fpsClock_.start();
  ++fpsFrames_;
  const qint64 ms = fpsClock_.elapsed();
  if (ms >= 1000) {
    fps_ = 1000.0 * fpsFrames_ / static_cast<double>(ms);
    fpsFrames_ = 0;
    fpsClock_.restart();
  }
}

}  // namespace flexarm
