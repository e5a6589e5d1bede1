#include "widgets/fleet_panel.h"

#include <QComboBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSplitter>
#include <QTableWidget>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <cmath>
#include <qcustomplot.h>

#include "core/fleet/fleet_report.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {

namespace {

enum Column { kRobot, kAxis, kStatus, kKT, kJa, kFm, kSince, kDays, kLogs, kColumns };
const char* kParameters[] = {"k_T", "J_a", "f_m"};

// Sorts by the number in UserRole (the text shows units and signs).
class NumberItem : public QTableWidgetItem {
 public:
  NumberItem(const QString& text, double value) : QTableWidgetItem(text) { setData(Qt::UserRole, value); }
  bool operator<(const QTableWidgetItem& other) const override {
    return data(Qt::UserRole).toDouble() < other.data(Qt::UserRole).toDouble();
  }
};

QColor kindColor(const std::string& kind) {
  if (kind == "step" || kind == "fault") return QColor(239, 154, 154);
  if (kind == "drift") return QColor(255, 204, 128);
  return QColor(200, 230, 201);
}

QString dateOf(double day) { return QString::fromStdString(isoFromDay(day).substr(0, 10)); }

}  // namespace

FleetPanel::FleetPanel(QWidget* parent) : QWidget(parent) {
  setObjectName("fleetPanel");
  auto* layout = new QVBoxLayout(this);
  auto* top = new QHBoxLayout;
  open_ = new QPushButton(tr("Open store..."), this);
  run_ = new QPushButton(tr("Run manifest..."), this);
  run_->setToolTip(tr("Analyse the new logs of a fleet manifest into the store, as flexarm fleet does"));
  cancel_ = new QPushButton(tr("Cancel"), this);
  progress_ = new QProgressBar(this);
  progress_->setRange(0, 1000);
  open_->setToolTip(tr("Open a fleet store (SQLite) that flexarm fleet writes; it may be writing now"));
  cancel_->setToolTip(tr("Stop the run after the results in hand; everything stored so far stays"));
  progress_->setToolTip(tr("Logs of the manifest analysed so far"));
  cancel_->setVisible(false);
  progress_->setVisible(false);
  storeLabel_ = new QLabel(tr("No store open"), this);
  storeLabel_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  top->addWidget(open_);
  top->addWidget(run_);
  top->addWidget(storeLabel_, 1);
  top->addWidget(progress_, 1);
  top->addWidget(cancel_);
  layout->addLayout(top);
  summary_ = new QLabel(this);
  summary_->setWordWrap(true);
  layout->addWidget(summary_);

  auto* split = new QSplitter(Qt::Vertical, this);
  grid_ = new QTableWidget(0, kColumns, split);
  grid_->setObjectName("fleetGrid");
  grid_->setHorizontalHeaderLabels({tr("Robot"), tr("Axis"), tr("Status"), "k_T", "J_a", "f_m", tr("Since"),
                                    tr("Days to threshold"), tr("Logs")});
  grid_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  grid_->setSelectionBehavior(QAbstractItemView::SelectRows);
  grid_->setSelectionMode(QAbstractItemView::SingleSelection);
  grid_->verticalHeader()->setVisible(false);
  grid_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  grid_->setToolTip(tr("Each parameter's change over days relative to theta_0 at the last log: green steady, "
                       "orange drifting, red stepped. Click a header to sort."));
  auto* lower = new QWidget(split);
  auto* lowerLayout = new QVBoxLayout(lower);
  lowerLayout->setContentsMargins(0, 0, 0, 0);
  auto* pick = new QHBoxLayout;
  pick->addWidget(new QLabel(tr("Trend of"), lower));
  parameter_ = new QComboBox(lower);
  for (const char* p : kParameters) parameter_->addItem(p);
  parameter_->setToolTip(tr("The parameter whose change from theta_0 over days is drawn (f_m at the reference "
                            "log's temperature)"));
  pick->addWidget(parameter_);
  pick->addWidget(new QLabel(tr("(click a day to open its log with its diagnosis)"), lower), 1);
  lowerLayout->addLayout(pick);
  plot_ = new QCustomPlot(lower);
  plot_->setObjectName("fleetTrendPlot");
  plot_->setToolTip(tr("Each day's estimate with +-2 std, the fitted level, the temperature (right axis), the "
                       "threshold and the predicted crossing; click a day to open its log with its diagnosis"));
  plot_->setMinimumHeight(220);
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  plot_->yAxis2->setVisible(true);
  plot_->yAxis2->setLabel(tr("temperature [degC]"));
  plot_->legend->setVisible(true);
  QFont small = plot_->legend->font();
  small.setPointSizeF(small.pointSizeF() * 0.8);
  plot_->legend->setFont(small);
  placeLegendAbove(plot_);
  PlotTools::install(plot_);
  lowerLayout->addWidget(plot_, 1);
  evidence_ = new QLabel(lower);
  evidence_->setWordWrap(true);
  evidence_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  lowerLayout->addWidget(evidence_);
  split->addWidget(grid_);
  split->addWidget(lower);
  grid_->setMinimumHeight(90);
  split->setStretchFactor(0, 1);
  split->setStretchFactor(1, 3);
  layout->addWidget(split, 1);

  connect(open_, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Open fleet store"), storePath_,
                                                      tr("Fleet stores (*.sqlite *.db);;All files (*)"));
    if (!path.isEmpty()) openStore(path);
  });
  connect(run_, &QPushButton::clicked, this, [this] {
    const QString manifest = QFileDialog::getOpenFileName(this, tr("Run fleet manifest"), {},
                                                          tr("Fleet manifests (*.csv);;All files (*)"));
    if (manifest.isEmpty()) return;
    QString store = storePath_;
    if (store.isEmpty())
      store = QFileDialog::getSaveFileName(this, tr("Fleet store"), QFileInfo(manifest).dir().filePath("fleet.sqlite"),
                                           tr("Fleet stores (*.sqlite)"), nullptr, QFileDialog::DontConfirmOverwrite);
    if (!store.isEmpty()) runManifest(manifest, store);
  });
  connect(cancel_, &QPushButton::clicked, this, &FleetPanel::cancel);
  connect(grid_, &QTableWidget::itemSelectionChanged, this, [this] {
    const auto rows = grid_->selectionModel()->selectedRows();
    if (rows.isEmpty()) return;
    const int index = grid_->item(rows.front().row(), kRobot)->data(Qt::UserRole + 1).toInt();
    const auto& t = axes_[static_cast<std::size_t>(index)].trend;
    showAxis(index, t.parameter.empty() ? QString() : QString::fromStdString(t.parameter));
  });
  connect(parameter_, &QComboBox::currentIndexChanged, this, [this] { plotTrend(); });
  connect(plot_, &QCustomPlot::mousePress, this, [this](QMouseEvent* e) {
    if (e->button() == Qt::LeftButton) requestLogAt(plot_->xAxis->pixelToCoord(e->position().x()));
  });
  connect(&watcher_, &QFutureWatcher<FleetRunResult>::finished, this, &FleetPanel::onRunFinished);
  auto* poll = new QTimer(this);
  poll->setInterval(100);
  connect(poll, &QTimer::timeout, this, [this] {
    if (progressValue_) progress_->setValue(static_cast<int>(1000.0 * progressValue_->load()));
  });
  poll->start();
  plotTrend();
}

FleetPanel::~FleetPanel() {
  if (cancelFlag_) *cancelFlag_ = true;
  watcher_.waitForFinished();
}

bool FleetPanel::openStore(const QString& path) {
  std::string why;
  auto store = FleetStore::open(path.toStdString(), false, &why);
  if (!store) {
    storeLabel_->setText(tr("Cannot open the store: %1").arg(QString::fromStdString(why)));
    return false;
  }
  storePath_ = path;
  model_ = store->meta("model").value_or("three-mass");
  TrendOptions options;
  if (auto t = store->meta("threshold")) options.threshold = std::stod(*t);
  axes_ = fleetTrends(*store, options);
  const auto runs = store->runs();
  storeLabel_->setText(tr("Store %1: %2 logs of %3 axes; last run %4")
                           .arg(QFileInfo(path).fileName())
                           .arg(store->logCount())
                           .arg(axes_.size())
                           .arg(runs.empty() ? tr("none") : QString::fromStdString(runs.back().started)));
  storeLabel_->setToolTip(path);
  firstDay_ = 0.0;
  fillGrid();
  current_ = -1;
  int first = -1;
  for (std::size_t i = 0; i < axes_.size() && first < 0; ++i)
    if (axes_[i].trend.status != "healthy") first = static_cast<int>(i);
  if (!axes_.empty()) showAxis(first >= 0 ? first : 0, first >= 0 ? QString::fromStdString(axes_[static_cast<std::size_t>(first)].trend.parameter) : QString());
  emit storeOpened();
  return true;
}

void FleetPanel::fillGrid() {
  grid_->setSortingEnabled(false);
  grid_->setRowCount(static_cast<int>(axes_.size()));
  int healthy = 0, drift = 0, fault = 0, due = 0;
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    const auto& a = axes_[i];
    const auto& t = a.trend;
    const int row = static_cast<int>(i);
    healthy += t.status == "healthy";
    drift += t.status == "drift";
    fault += t.status == "fault";
    due += t.serviceAtNextStop;
    auto* robot = new QTableWidgetItem(QString::fromStdString(a.robot));
    robot->setData(Qt::UserRole + 1, row);
    grid_->setItem(row, kRobot, robot);
    grid_->setItem(row, kAxis, new NumberItem(QString::number(a.axis), a.axis));
    const int rank = t.status == "fault" ? 2 : t.status == "drift" ? 1 : 0;
    auto* status = new NumberItem(QString::fromStdString(t.status) +
                                      (t.parameter.empty() ? QString() : " " + QString::fromStdString(t.parameter)),
                                  rank);
    status->setBackground(kindColor(t.status));
    status->setToolTip(QString::fromStdString(t.evidence));
    grid_->setItem(row, kStatus, status);
    for (int c = 0; c < 3; ++c) {
      const auto* s = t.find(kParameters[c]);
      if (!s) {
        grid_->setItem(row, kKT + c, new NumberItem("-", 0));
        continue;
      }
      auto* cell = new NumberItem(QString::asprintf("%+.1f %%", 100.0 * s->level), std::abs(s->level));
      cell->setBackground(kindColor(s->kind));
      cell->setToolTip(tr("%1 at the last log, relative to theta_0; %2").arg(kParameters[c]).arg(
          s->kind == "none" ? tr("steady") : QString::fromStdString(s->kind)));
      grid_->setItem(row, kKT + c, cell);
    }
    grid_->setItem(row, kSince, new NumberItem(t.since ? dateOf(*t.since) : "-", t.since.value_or(0)));
    grid_->setItem(row, kDays, new NumberItem(t.daysToThreshold ? QString::asprintf("%.1f", *t.daysToThreshold) : "-",
                                             t.daysToThreshold.value_or(1e9)));
    grid_->setItem(row, kLogs, new NumberItem(QString::number(a.logs), a.logs));
  }
  grid_->setSortingEnabled(true);
  summary_->setText(tr("%1 axes: %2 healthy, %3 drifting, %4 with a fault; %5 to service at the next stop.")
                        .arg(axes_.size())
                        .arg(healthy)
                        .arg(drift)
                        .arg(fault)
                        .arg(due));
}

void FleetPanel::showAxis(int index, const QString& parameter) {
  if (index < 0 || index >= static_cast<int>(axes_.size())) return;
  current_ = index;
  if (!parameter.isEmpty()) {
    const QSignalBlocker block(parameter_);
    parameter_->setCurrentText(parameter);
  }
  plotTrend();
}

QString FleetPanel::evidenceText() const { return evidence_->text(); }

void FleetPanel::showEvent(QShowEvent* event) {
  QWidget::showEvent(event);
  plot_->replot(QCustomPlot::rpQueuedReplot);  // laid out at the size it is shown at
}

void FleetPanel::plotTrend() {
  plot_->clearGraphs();
  plot_->clearItems();
  if (current_ < 0) {
    plot_->xAxis->setLabel(tr("time [days]"));
    plot_->yAxis2->setVisible(false);
    // An empty legend would cap the plot's column at its own width of nothing.
    plot_->addGraph()->setName(tr("no axis chosen"));
    plot_->yAxis->setLabel(tr("change from theta_0 [%]"));
    evidence_->setText(tr("Open a fleet store (written by flexarm fleet), or run a manifest."));
    plot_->replot();
    return;
  }
  const FleetAxisReport& a = axes_[static_cast<std::size_t>(current_)];
  const auto* series = a.trend.find(parameter_->currentText().toStdString());
  if (!series) return;
  const ReportPlot p = fleetTrendPlot(a, *series, a.trend.threshold);
  plot_->xAxis->setLabel(QString::fromStdString(p.xLabel));
  plot_->yAxis->setLabel(QString::fromStdString(p.yLabel));
  const QColor blue(31, 119, 180), red(214, 39, 40), dark(60, 60, 60);
  QCPGraph* upper = nullptr;
  for (const auto& s : p.series) {
    QCPGraph* g = plot_->addGraph();
    g->setName(QString::fromStdString(s.name));
    g->setData(QVector<double>(s.x.begin(), s.x.end()), QVector<double>(s.y.begin(), s.y.end()));
    if (s.name == "estimate") {
      g->setLineStyle(QCPGraph::lsNone);
      g->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssDisc, blue, 6));
    } else if (s.name == "+2 std") {
      g->setPen(QPen(QColor(31, 119, 180, 60)));
      g->setName(tr("+-2 std"));
      upper = g;
    } else if (s.name == "-2 std") {
      g->setPen(QPen(QColor(31, 119, 180, 60)));
      g->setBrush(QColor(31, 119, 180, 40));
      if (upper) g->setChannelFillGraph(upper);
      g->removeFromLegend();
    } else if (s.name.rfind("threshold", 0) == 0) {
      g->setPen(QPen(red, 1.5, Qt::DashLine));
    } else if (s.name.rfind("crossing", 0) == 0) {
      g->setPen(QPen(red, 1.5, Qt::DotLine));
    } else if (s.name == "predicted") {
      g->setPen(QPen(dark, 1.5, Qt::DashLine));
    } else {
      g->setPen(QPen(dark, 2));
    }
  }
  // Temperature on the right axis.
  const ReportPlot temperature = fleetTemperaturePlot(a);
  if (!temperature.series.empty() && !temperature.series[0].x.empty()) {
    QCPGraph* g = plot_->addGraph(plot_->xAxis, plot_->yAxis2);
    g->setName(tr("temperature"));
    const auto& s = temperature.series[0];
    g->setData(QVector<double>(s.x.begin(), s.x.end()), QVector<double>(s.y.begin(), s.y.end()));
    g->setPen(QPen(QColor(150, 150, 150), 1));
    g->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCross, QColor(150, 150, 150), 5));
    plot_->yAxis2->setVisible(true);
  } else {
    plot_->yAxis2->setVisible(false);
  }
  plot_->rescaleAxes();
  plot_->xAxis->scaleRange(1.05);
  plot_->yAxis->scaleRange(1.15);
  plot_->yAxis2->scaleRange(1.15);
  PlotTools::of(plot_)->setReset([this] {
    plot_->rescaleAxes();
    plot_->xAxis->scaleRange(1.05);
    plot_->yAxis->scaleRange(1.15);
    plot_->replot();
  });
  const auto& t = a.trend;
  evidence_->setText(QString("<b>%1 axis %2: %3</b> - %4<br>%5")
                         .arg(QString::fromStdString(a.robot))
                         .arg(a.axis)
                         .arg(QString::fromStdString(t.status + (t.parameter.empty() ? "" : " in " + t.parameter)))
                         .arg(QString::fromStdString(t.evidence).toHtmlEscaped())
                         .arg(tr("Suggestion: %1.").arg(QString::fromStdString(t.suggestion)) +
                              (t.caveat.empty() ? QString() : "<br><i>" + QString::fromStdString(t.caveat).toHtmlEscaped() + "</i>")));
  plot_->replot();
}

bool FleetPanel::requestLogAt(double x) {
  if (current_ < 0) return false;
  const FleetAxisReport& a = axes_[static_cast<std::size_t>(current_)];
  if (a.points.empty()) return false;
  const double d0 = a.points.front().day;
  std::size_t best = 0;
  for (std::size_t i = 1; i < a.points.size(); ++i)
    if (std::abs(a.points[i].day - d0 - x) < std::abs(a.points[best].day - d0 - x)) best = i;
  if (std::abs(a.points[best].day - d0 - x) > 0.6) return false;
  emit logRequested(QString::fromStdString(a.points[best].path), QString::fromStdString(a.referenceLog),
                    QString::fromStdString(model_));
  return true;
}

void FleetPanel::runManifest(const QString& manifest, const QString& store) {
  if (watcher_.isRunning()) return;
  cancelFlag_ = std::make_shared<std::atomic<bool>>(false);
  progressValue_ = std::make_shared<std::atomic<double>>(0.0);
  progress_->setValue(0);
  progress_->setVisible(true);
  cancel_->setVisible(true);
  run_->setEnabled(false);
  open_->setEnabled(false);
  storePath_ = store;
  storeLabel_->setText(tr("Running %1 into %2...").arg(QFileInfo(manifest).fileName(), QFileInfo(store).fileName()));
  const std::string m = manifest.toStdString(), s = store.toStdString();
  auto flag = cancelFlag_;
  auto value = progressValue_;
  watcher_.setFuture(QtConcurrent::run([m, s, flag, value] {
    FleetRunResult r;
    ManifestError e;
    const auto read = readFleetManifest(m, &e);
    if (!read) {
      r.message = e.toString();
      return r;
    }
    std::string why;
    auto writer = FleetStore::open(s, true, &why);
    if (!writer) {
      r.message = why;
      return r;
    }
    return runFleet(*read, *writer, FleetOptions{}, [flag, value](double f, const std::string&) {
      value->store(f);
      return *flag ? ProgressAction::Abort : ProgressAction::Continue;
    });
  }));
}

void FleetPanel::cancel() {
  if (cancelFlag_) *cancelFlag_ = true;
}

void FleetPanel::onRunFinished() {
  const FleetRunResult r = watcher_.result();
  progress_->setVisible(false);
  cancel_->setVisible(false);
  run_->setEnabled(true);
  open_->setEnabled(true);
  const bool ok = r.termination == Termination::Converged;
  openStore(storePath_);
  if (!ok) storeLabel_->setText(storeLabel_->text() + " - " + QString::fromStdString(r.message));
  emit runFinished(ok, QString::fromStdString(r.message));
}

}  // namespace flexarm
