#include "widgets/diagnosis_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPointer>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QSettings>
#include <QSplitter>
#include <QTableWidget>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <cmath>
#include <qcustomplot.h>

#include "core/diagnosis/diagnosis_json.h"
#include "core/io/log_io.h"
#include "widgets/playhead.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {

namespace {

void setupPlot(QCustomPlot* p, const QString& y) {
  p->xAxis->setLabel(QObject::tr("time (s)"));
  p->yAxis->setLabel(y);
  p->legend->setVisible(true);
  p->legend->setFont(QFont(p->font().family(), 7));
  p->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(p);
  p->setMinimumHeight(150);
}

}  // namespace

DiagnosisPanel::DiagnosisPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent),
      workspace_(workspace),
      reference_(new QComboBox(this)),
      chooseLog_(new QPushButton(tr("Fault-free log..."), this)),
      referenceName_(new QLabel(tr("none: theta_0 from the model"), this)),
      window_(new QComboBox(this)),
      calibrate_(new QCheckBox(tr("Calibrate thresholds"), this)),
      alpha_(new QDoubleSpinBox(this)),
      run_(new QPushButton(tr("Diagnose"), this)),
      cancel_(new QPushButton(tr("Cancel"), this)),
      progress_(new QProgressBar(this)),
      stage_(new QLabel(this)),
      verdict_(new QLabel(this)),
      statement_(new QLabel(this)),
      thresholds_(new QLabel(this)),
      estimates_(new QCustomPlot(this)),
      cusum_(new QCustomPlot(this)),
      hypothesis_(new QCustomPlot(this)),
      timeline_(new QCustomPlot(this)),
      table_(new QTableWidget(5, 5, this)) {
  run_->setObjectName("diagnose");
  run_->setToolTip(tr("Fit theta_0 on the fault-free reference, follow k_T, J_a^-1 and f_m through "
                      "the log with the recursive estimator and run the tests of chapter 7"));
  chooseLog_->setToolTip(tr("The fault-free log theta_0 is fitted on (another experiment on the same axis)"));
  calibrate_->setToolTip(tr("Choose the thresholds by Monte-Carlo runs of the arm under this log's "
                            "conditions for 1 false alarm per hour (takes a minute)"));
  const char* names[] = {"classical", "robust", "CUSUM", "hypothesis", "joint"};
  const char* tips[] = {
      QT_TR_NOOP("Classical approach (Section 7.4.1): a fault when an estimate leaves theta_0 by "
                 "more than a fixed threshold"),
      QT_TR_NOOP("Adaptive threshold 3 sigma_i(t) from the estimate's variance (Section 7.4.1)"),
      QT_TR_NOOP("CUSUM test (7.1) with drift nu = 3 sigma_i(t) and alarm level h"),
      QT_TR_NOOP("Hypothesis tests and decision structure (Section 7.4.2): which fault explains "
                 "the estimates, the table below"),
      QT_TR_NOOP("Joint test: the change of every parameter at once against its full covariance "
                 "(chi-square, correlations from P), isolated by the change's direction")};
  for (int i = 0; i < 5; ++i) {
    tests_[i] = new QCheckBox(tr(names[i]), this);
    tests_[i]->setChecked(true);
    tests_[i]->setToolTip(tr(tips[i]));
  }
  window_->addItem(tr("sliding 5 s"), 5.0);
  window_->addItem(tr("cumulative (seed)"), 0.0);
  window_->setToolTip(tr("Data the estimates of the tests rest on: a sliding 5 s window, or all "
                         "data since the start as the seed does (Section 7.5)"));
  reference_->setToolTip(tr("Where the fault-free parameters theta_0 come from: the model, or a "
                            "fit on a fault-free log"));
  cancel_->setToolTip(tr("Stop the diagnosis; nothing is decided on a part of the log"));
  progress_->setRange(0, 1000);
  progress_->setVisible(false);
  cancel_->setVisible(false);
  QFont bold = verdict_->font();
  bold.setBold(true);
  bold.setPointSizeF(bold.pointSizeF() * 1.2);
  verdict_->setFont(bold);
  verdict_->setText(tr("Choose the fault-free reference and press \"Diagnose\"."));
  // The verdict wraps too: a restored session's summary is a paragraph.
  for (QLabel* l : {verdict_, statement_, thresholds_, stage_, referenceName_}) {
    l->setWordWrap(true);
    l->setTextInteractionFlags(Qt::TextSelectableByMouse);
  }
  table_->setHorizontalHeaderLabels({"T_NF", "T_kT", "T_Ja^-1", "T_fm", "S"});
  table_->setVerticalHeaderLabels({"F_kT", "F_Ja^-1", "F_fm", "NF", tr("now")});
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->setSelectionMode(QAbstractItemView::NoSelection);
  table_->setMaximumHeight(170);
  table_->setMinimumHeight(140);
  table_->setObjectName("decisionTable");

  setupPlot(estimates_, "");
  estimates_->legend->setVisible(false);
  estimates_->setMinimumHeight(170);
  setupPlot(cusum_, tr("g / h [-]"));
  setupPlot(hypothesis_, tr("T [-]"));
  for (QCustomPlot* p : {cusum_, hypothesis_}) showLegendAbove(p);  // none until a result
  alpha_->setObjectName("frictionAlpha");
  alpha_->setRange(-2.5, 2.5);  // FrictionTemperatureModel::isValid over T_ref +- 40 degC
  alpha_->setDecimals(3);
  alpha_->setSingleStep(0.1);
  alpha_->setSuffix(tr(" %/degC"));
  alpha_->setValue(0.0);
  alpha_->setToolTip(tr("Friction against temperature, f_m = f_m0 (1 + alpha (T - T_ref)): with "
                        "alpha, theta_0's f_m is carried from the reference log's temperature to "
                        "this log's (their temperature_c channel or metadata value) before the "
                        "tests compare, so a warm healthy axis raises no friction alarm (negative: "
                        "friction falling as the lubricant warms). 0: f_m is compared as fitted. flexarm diagnose --temperature-logs estimates "
                        "alpha from healthy logs at several temperatures"));
  setupPlot(timeline_, "");
  timeline_->legend->setVisible(false);
  timeline_->yAxis->setRange(-0.3, 5.0);
  timeline_->setMinimumHeight(140);  // six rows whose labels must not overlap

  // Short rows, so that the dock's usual width (a third of a 1366-pixel window) shows them
  // whole, "Diagnose" included.
  reference_->setMinimumContentsLength(12);
  reference_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Model:"), this));
  top->addWidget(reference_, 1);
  top->addWidget(chooseLog_);
  auto* testsRow = new QHBoxLayout;
  for (QCheckBox* c : tests_) testsRow->addWidget(c);
  testsRow->addStretch(1);
  auto* options = new QHBoxLayout;
  options->addWidget(new QLabel(tr("Hypothesis window:"), this));
  options->addWidget(window_);
  options->addWidget(calibrate_);
  options->addStretch(1);
  auto* temperature = new QHBoxLayout;
  temperature->addWidget(new QLabel(tr("Friction alpha (0: none):"), this));
  temperature->addWidget(alpha_);
  temperature->addStretch(1);
  options->addWidget(run_);
  options->addWidget(cancel_);
  auto* status = new QHBoxLayout;
  status->addWidget(progress_, 1);
  status->addWidget(stage_, 2);

  auto* plots = new QSplitter(Qt::Vertical, this);
  plots->addWidget(estimates_);
  auto* middle = new QSplitter(Qt::Horizontal, this);
  middle->addWidget(cusum_);
  middle->addWidget(hypothesis_);
  plots->addWidget(middle);
  plots->addWidget(timeline_);
  // The decision table beside the statement S and the thresholds' provenance; the long
  // provenance scrolls rather than growing the panel.
  auto* bottom = new QWidget;
  auto* bottomLayout = new QHBoxLayout(bottom);
  bottomLayout->setContentsMargins(0, 0, 0, 0);
  bottomLayout->addWidget(table_, 3);
  auto* words = new QWidget;
  auto* wordsLayout = new QVBoxLayout(words);
  wordsLayout->setContentsMargins(2, 2, 2, 2);
  wordsLayout->addWidget(statement_);
  wordsLayout->addWidget(thresholds_);
  wordsLayout->addStretch(1);
  auto* wordsScroll = new QScrollArea;
  wordsScroll->setWidget(words);
  wordsScroll->setWidgetResizable(true);
  wordsScroll->setFrameShape(QFrame::NoFrame);
  wordsScroll->setMaximumHeight(170);
  bottomLayout->addWidget(wordsScroll, 2);
  plots->addWidget(bottom);
  plots->setStretchFactor(0, 3);
  plots->setStretchFactor(1, 2);
  plots->setStretchFactor(2, 1);
  plots->setStretchFactor(3, 0);
  plots->setChildrenCollapsible(false);

  // Everything scrolls inside the dock: at 1366x768 the window keeps its size.
  auto* content = new QWidget;
  auto* layout = new QVBoxLayout(content);
  layout->setContentsMargins(4, 4, 4, 4);
  layout->addLayout(top);
  layout->addWidget(referenceName_);
  layout->addLayout(testsRow);
  layout->addLayout(options);
  layout->addLayout(temperature);
  layout->addLayout(status);
  layout->addWidget(verdict_);
  layout->addWidget(plots, 1);
  auto* scroll = new QScrollArea(this);
  scroll->setWidget(content);
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setMinimumSize(240, 200);
  auto* outer = new QVBoxLayout(this);
  outer->setContentsMargins(0, 0, 0, 0);
  outer->addWidget(scroll);

  connect(run_, &QPushButton::clicked, this, &DiagnosisPanel::diagnose);
  connect(cancel_, &QPushButton::clicked, this, &DiagnosisPanel::cancel);
  connect(chooseLog_, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Fault-free reference log"),
                                                      QSettings().value("lastDir").toString(),
                                                      tr("Robot logs (*.csv *.mat);;All files (*)"));
    if (!path.isEmpty()) setReferenceLog(path);
  });
  connect(&watcher_, &QFutureWatcher<Outcome>::finished, this, &DiagnosisPanel::onFinished);
  connect(workspace_, &Workspace::modelsChanged, this, &DiagnosisPanel::refillReferences);
  // A result is shown only beside its log: another log drops it with its request (a run in
  // flight too), and the Arm view's highlight goes with the verdict.
  auto drop = [this] {
    clearResult();
    request_.reset();
  };
  connect(workspace_, &Workspace::logChanged, this, drop);
  connect(workspace_, &Workspace::resultWithdrawn, this, [drop](const QString& key) {
    if (key == "diagnosis") drop();
  });
  auto* poll = new QTimer(this);
  poll->setInterval(100);
  connect(poll, &QTimer::timeout, this, [this] {
    if (progressValue_) progress_->setValue(static_cast<int>(1000.0 * progressValue_->load()));
  });
  poll->start();
  refillReferences();
}

DiagnosisPanel::~DiagnosisPanel() {
  if (cancelFlag_) *cancelFlag_ = true;
  watcher_.waitForFinished();
}

void DiagnosisPanel::setPlayhead(Playhead* playhead) {
  playhead_ = playhead;
  for (QCustomPlot* p : {estimates_, cusum_, hypothesis_, timeline_}) {
    auto* c = new PlayheadCursor(p, this);
    c->setPlayhead(playhead);
    cursors_.push_back(c);
  }
  connect(playhead, &Playhead::timeChanged, this, &DiagnosisPanel::showAt);
}

void DiagnosisPanel::setReferenceLog(const QString& path) {
  referencePath_ = path;
  referenceName_->setText(path.isEmpty() ? tr("none: theta_0 from the model")
                                         : tr("theta_0 fitted on %1").arg(QFileInfo(path).fileName()));
  referenceName_->setToolTip(path);
}

void DiagnosisPanel::refillReferences() {
  const QString keep = reference_->currentText();
  reference_->clear();
  const auto& models = workspace_->models();
  for (std::size_t i = 0; i < models.size(); ++i)
    if (models[i].model && models[i].model->indexOf("k_T") >= 0 && models[i].model->indexOf("f_m") >= 0)
      reference_->addItem(nameOf(models[i]), static_cast<int>(i));
  for (const char* s : {"three-mass", "two-mass", "four-mass"})
    reference_->addItem(tr("%1 (nominal)").arg(s), QString(s));
  const int k = reference_->findText(keep);
  reference_->setCurrentIndex(k >= 0 ? k : reference_->findData(QString("three-mass")));
}

DiagnosisOptions DiagnosisPanel::chosenOptions() const {
  DiagnosisOptions o = storedOptions_ ? *storedOptions_ : DiagnosisOptions{};
  const DiagnosisTest all[] = {DiagnosisTest::Classical, DiagnosisTest::Robust, DiagnosisTest::Cusum,
                               DiagnosisTest::Hypothesis, DiagnosisTest::Joint};
  o.tests.clear();
  for (int i = 0; i < 5; ++i)
    if (tests_[i]->isChecked()) o.tests.push_back(all[i]);
  std::vector<DiagnosisTest> decide;
  for (DiagnosisTest t : DiagnosisOptions{}.decision)
    if (o.uses(t)) decide.push_back(t);
  o.decision = decide.empty() ? o.tests : decide;
  const double w = window_->currentData().toDouble();
  o.window = w > 0.0 ? HypothesisWindow::Sliding : HypothesisWindow::Cumulative;
  if (w > 0.0) o.windowS = w;
  if (alpha_->value() == 0.0) {
    o.friction.reset();
  } else {
    FrictionTemperatureModel f = o.friction.value_or(FrictionTemperatureModel{});
    if (f.alpha != alpha_->value() / 100.0) f = FrictionTemperatureModel{};  // given, not estimated
    f.alpha = alpha_->value() / 100.0;
    o.friction = f;
  }
  return o;
}

void DiagnosisPanel::setBusy(bool busy) {
  run_->setEnabled(!busy);
  cancel_->setVisible(busy);
  progress_->setVisible(busy);
  stage_->setText(busy ? (calibrate_->isChecked() ? tr("Fitting theta_0, calibrating, diagnosing...")
                                                  : tr("Fitting theta_0 and diagnosing..."))
                       : QString());
}

void DiagnosisPanel::diagnose() {
  if (isBusy()) return;
  const IdData* log = workspace_->raw();
  if (!log) {
    verdict_->setText(tr("Open a log to diagnose first."));
    return;
  }
  DiagnosisRequest request;
  request.options = chosenOptions();
  request.seedFault = seedFault_;
  request.calibrate = calibrate_->isChecked();
  request.calibration.healthyRuns = 20;
  request.calibration.faultyRuns = 4;
  const QVariant v = reference_->currentData();
  if (v.typeId() == QMetaType::Int) {
    const auto& models = workspace_->models();
    const int i = v.toInt();
    if (i < 0 || i >= static_cast<int>(models.size()) || !models[static_cast<std::size_t>(i)].model) return;
    request.model = models[static_cast<std::size_t>(i)].model;
  } else {
    request.model = makeModel(v.toString().toStdString());
  }
  std::string why;
  if (!request.isValid(&why)) {
    verdict_->setText(tr("Cannot diagnose: %1").arg(QString::fromStdString(why)));
    return;
  }
  DiagnosisSessionRequest stored;
  stored.referenceLog = referencePath_.isEmpty() ? "" : "diagnosis_reference";
  stored.model = v.typeId() == QMetaType::Int ? reference_->currentText().toStdString() : "";
  stored.structure = v.typeId() == QMetaType::Int ? "three-mass" : v.toString().toStdString();
  stored.seedFault = seedFault_;
  stored.options = request.options;
  stored.calibrate = false;
  request_ = stored;
  storedResult_ = nullptr;  // this run replaces what a session stored
  runData_ = workspace_->dataProvenance();
  cancelFlag_ = std::make_shared<std::atomic<bool>>(false);
  progressValue_ = std::make_shared<std::atomic<double>>(0.0);
  const int id = ++runId_;
  setBusy(true);
  auto data = std::make_shared<const IdData>(*log);
  const std::string referencePath = referencePath_.toStdString();
  auto flag = cancelFlag_;
  auto value = progressValue_;
  watcher_.setFuture(QtConcurrent::run([request, data, referencePath, flag, value, id]() mutable {
    Outcome out;
    out.id = id;
    try {
      if (!referencePath.empty()) {
        const auto read = readLog(referencePath);
        if (!read.ok) {
          out.error = QString::fromStdString(read.error.toString());
          return out;
        }
        request.referenceLog = std::make_shared<const IdData>(read.data);
      }
      out.run = std::make_shared<DiagnosisRun>(runDiagnosisRequest(request, *data, [flag, value](double f, const std::string&) {
        value->store(f);
        return *flag ? ProgressAction::Abort : ProgressAction::Continue;
      }));
    } catch (const std::exception& e) {
      out.error = QString::fromUtf8(e.what());
    }
    return out;
  }));
}

void DiagnosisPanel::cancel() {
  if (cancelFlag_) *cancelFlag_ = true;
}

void DiagnosisPanel::clearResult() {
  if (isBusy()) cancel();
  ++runId_;
  shownRun_.reset();
  storedResult_ = nullptr;
  workspace_->forgetResult("diagnosis");
  if (!shownVerdict_.isEmpty()) {
    shownVerdict_.clear();
    emit verdictShown({});
  }
  for (QCustomPlot* p : {estimates_, cusum_, hypothesis_, timeline_}) {
    p->clearGraphs();
    p->clearItems();
    showLegendAbove(p);  // without entries: out of the layout
    p->replot();
  }
  shown_.clear();
  shownSample_ = static_cast<std::size_t>(-1);
  verdict_->setText(tr("Choose the fault-free reference and press \"Diagnose\"."));
  verdict_->setStyleSheet({});
  statement_->clear();
  thresholds_->clear();
  table_->clearContents();
}

void DiagnosisPanel::onFinished() {
  setBusy(false);
  const Outcome out = watcher_.result();
  if (out.id != runId_) return;  // a dropped run
  emit finished();
  if (!out.error.isEmpty() || !out.run || out.run->termination == Termination::Failed ||
      out.run->termination == Termination::Cancelled) {
    const QString why = !out.error.isEmpty() ? out.error
                        : out.run          ? QString::fromStdString(out.run->message)
                                           : tr("no result");
    verdict_->setText(out.run && out.run->termination == Termination::Cancelled ? tr("Cancelled.")
                                                                                 : tr("The diagnosis failed: %1").arg(why));
    verdict_->setStyleSheet("color: rgb(200,40,40)");
    return;
  }
  if (!workspace_->recordResult("diagnosis", runData_, true)) {  // the log changed meanwhile
    clearResult();
    request_.reset();
    return;
  }
  shownRun_ = out.run;
  if (shownRun_->calibration) {
    storedCalibration_ = calibrationJson(*shownRun_->calibration);
    if (request_) {
      request_->options = shownRun_->result.options;
      request_->calibration = storedCalibration_;
    }
  } else if (request_) {
    request_->calibration = storedCalibration_;
  }
  buildPlots();
  showAt(playhead_ && playhead_->hasSpan() ? playhead_->time()
                                           : (shownRun_->result.time.empty() ? 0.0 : shownRun_->result.time.back()));
}

std::optional<DiagnosisSessionRequest> DiagnosisPanel::sessionRequest(const std::string& referenceLogName) const {
  if (!request_) return std::nullopt;
  DiagnosisSessionRequest q = *request_;
  q.referenceLog = referencePath_.isEmpty() ? "" : referenceLogName;
  return q;
}

void DiagnosisPanel::setRequest(const DiagnosisSessionRequest& request, const QString& referencePath,
                                const nlohmann::json& storedResult) {
  clearResult();
  storedResult_ = storedResult.is_object() ? storedResult : nlohmann::json();
  request_ = request;
  storedOptions_ = request.options;
  storedCalibration_ = request.calibration;
  seedFault_ = request.seedFault;
  setReferenceLog(referencePath);
  const DiagnosisTest all[] = {DiagnosisTest::Classical, DiagnosisTest::Robust, DiagnosisTest::Cusum,
                               DiagnosisTest::Hypothesis, DiagnosisTest::Joint};
  for (int i = 0; i < 5; ++i) tests_[i]->setChecked(request.options.uses(all[i]));
  window_->setCurrentIndex(request.options.window == HypothesisWindow::Sliding ? 0 : 1);
  alpha_->setValue(request.options.friction ? 100.0 * request.options.friction->alpha : 0.0);
  const int k = request.model.empty() ? reference_->findData(QString::fromStdString(request.structure))
                                      : reference_->findText(QString::fromStdString(request.model));
  if (k >= 0) reference_->setCurrentIndex(k);
  if (storedResult_.contains("summary") && storedResult_["summary"].is_string())
    verdict_->setText(tr("From the session: %1 Press \"Diagnose\" to draw its plots again.")
                          .arg(QString::fromStdString(storedResult_["summary"].get<std::string>())));
  else
    verdict_->setText(tr("Restored from the session: press \"Diagnose\" to run it."));
}

}  // namespace flexarm
