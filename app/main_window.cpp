#include "app/main_window.h"

#include <QAction>
#include <QApplication>
#include <QCloseEvent>
#include <QDateTime>
#include <QDialog>
#include <QDialogButtonBox>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QInputDialog>
#include <QFormLayout>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QProgressDialog>
#include <QSettings>
#include <QSpinBox>
#include <QUndoStack>
#include <QScreen>
#include <QStatusBar>
#include <QTabBar>
#include <QToolBar>
#include <QtConcurrent>
#include <fstream>
#include <sstream>

#include "app/busy_progress.h"
#include "app/cli/cli.h"
#include "app/log_importer.h"
#include "app/panel_docks.h"
#include "app/recent_files.h"
#include "app/session_controller.h"
#include "core/io/ranges.h"
#include "core/session/sha256.h"
#include "core/models/physical_models.h"
#include "widgets/arm_panel.h"
#include "widgets/bode_panel.h"
#include "widgets/compare_panel.h"
#include "widgets/fit_panel.h"
#include "widgets/diagnosis_panel.h"
#include "widgets/fleet_panel.h"
#include "widgets/discovery_panel.h"
#include "widgets/log_panel.h"
#include "widgets/lqg_panel.h"
#include "widgets/model_panel.h"
#include "widgets/playhead.h"
#include "widgets/preprocess_panel.h"
#include "widgets/recursive_panel.h"
#include "widgets/residuals_panel.h"
#include "widgets/transport_bar.h"
#include "widgets/wheel_guard.h"
#include "widgets/workspace.h"

namespace flexarm {
namespace {

constexpr int kMaxRecent = 8;

// True when the first non-comment line of the file starts with a number: a headerless table.
bool looksLikeTable(const QString& path) {
  if (path.endsWith(".mat", Qt::CaseInsensitive)) return false;
  std::ifstream in(path.toStdString());
  std::string line;
  for (int n = 0; n < 200 && std::getline(in, line); ++n) {
    const auto p = line.find_first_not_of(" \t\r");
    if (p == std::string::npos || line[p] == '#' || line[p] == '%') continue;
    const char c = line[p];
    return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
  }
  return false;
}

}  // namespace

MainWindow::MainWindow(QWidget* parent)
    : QMainWindow(parent), workspace_(new Workspace(this)), playhead_(new Playhead(this)),
      logPanel_(new LogPanel(workspace_, this)) {
  setObjectName("mainWindow");
  setWindowTitle("FlexArm[*]");
  setAcceptDrops(true);
  WheelGuard::install();  // the wheel scrolls panels, not the controls it passes over
  setCentralWidget(logPanel_);
  createMenus();
  // Panels: each a dock on the right, tabbed with the Preprocess panel unless it has its own
  // place, with a View menu entry and shortcut.
  preprocessDock_ = addPanel(preprocessPanel_ = new PreprocessPanel(workspace_, this),
                             tr("Preprocess"), "preprocessDock", "Ctrl+Shift+P", nullptr);
  armDock_ = addPanel(armPanel_ = new ArmPanel(workspace_, this), tr("Arm"), "armDock",
                      "Ctrl+Shift+A", nullptr);
  modelDock_ = addPanel(modelPanel_ = new ModelPanel(workspace_, this), tr("Model"),
                        "modelDock", "Ctrl+Shift+M", preprocessDock_);
  fitDock_ = addPanel(fitPanel_ = new FitPanel(workspace_, this), tr("Fit"), "fitDock",
                      "Ctrl+Shift+F", preprocessDock_);
  bodeDock_ = addPanel(bodePanel_ = new BodePanel(workspace_, this), tr("Bode"), "bodeDock",
                       "Ctrl+Shift+B", preprocessDock_);
  compareDock_ = addPanel(comparePanel_ = new ComparePanel(workspace_, this), tr("Compare"),
                          "compareDock", "Ctrl+Shift+C", preprocessDock_);
  residualsDock_ = addPanel(residualsPanel_ = new ResidualsPanel(workspace_, this),
                            tr("Residuals"), "residualsDock", "Ctrl+Shift+R", preprocessDock_);
  lqgDock_ = addPanel(lqgPanel_ = new LqgPanel(workspace_, this), tr("LQG"), "lqgDock",
                      "Ctrl+Shift+L", preprocessDock_);
  discoveryDock_ = addPanel(discoveryPanel_ = new DiscoveryPanel(workspace_, this), tr("Discovery"), "discoveryDock", "Ctrl+Shift+D", preprocessDock_);
  diagnosisDock_ = addPanel(diagnosisPanel_ = new DiagnosisPanel(workspace_, this), tr("Diagnosis"),
                            "diagnosisDock", "Ctrl+Shift+G", preprocessDock_);
  recursiveDock_ = addPanel(recursivePanel_ = new RecursivePanel(workspace_, this), tr("Recursive"),
                            "recursiveDock", "Ctrl+Shift+I", preprocessDock_);
  // The Fleet panel: a day's log opens with its diagnosis against its axis' reference.
  auto* fleetPanel = new FleetPanel(this);
  addPanel(fleetPanel, tr("Fleet"), "fleetDock", "Ctrl+Shift+T", preprocessDock_);
  connect(fleetPanel, &FleetPanel::logRequested, this,
          [this](const QString& log, const QString& reference, const QString& model) {
            auto once = std::make_shared<QMetaObject::Connection>();
            *once = connect(workspace_, &Workspace::logChanged, this, [this, once, log, reference, model] {
              QObject::disconnect(*once);
              if (workspace_->logPath() != log) return;
              diagnosisPanel_->setReferenceLog(reference);
              QComboBox* box = diagnosisPanel_->referenceBox();
              box->setCurrentIndex(std::max(0, box->findText(model + " (nominal)")));
              docks_->showPanel(diagnosisDock_);
              // The whole day's diagnosis at once: the playhead to the log's end when it is done.
              auto shown = std::make_shared<QMetaObject::Connection>();
              *shown = connect(diagnosisPanel_, &DiagnosisPanel::finished, this, [this, shown] {
                QObject::disconnect(*shown);
                const IdData* d = workspace_->raw();
                if (d && d->samples() > 0) playhead_->setTime(d->timeAt(d->samples() - 1));
              });
              diagnosisPanel_->diagnose();
            });
            openFile(log);
          });
  // A row of the time-stamp report shows its place in the Log panel.
  connect(preprocessPanel_, &PreprocessPanel::timeSelected, logPanel_, &LogPanel::showAround);
  // The playhead spans the log as read (preprocessing keeps its times); every panel that
  // shows time follows it.
  connect(workspace_, &Workspace::logChanged, this, [this] {
    const IdData* d = workspace_->raw();
    if (d && d->samples() > 0)
      playhead_->setSpan(d->startTime, d->timeAt(d->samples() - 1), d->sampleTime);
    else
      playhead_->clearSpan();
  });
  logPanel_->setPlayhead(playhead_);
  armPanel_->setPlayhead(playhead_);
  comparePanel_->setPlayhead(playhead_);
  modelPanel_->setPlayhead(playhead_);
  discoveryPanel_->setPlayhead(playhead_);
  diagnosisPanel_->setPlayhead(playhead_);
  recursivePanel_->setPlayhead(playhead_);
  // A finished recursive run hands the Arm view the model at its final estimate, named so.
  connect(recursivePanel_, &RecursivePanel::runFinished, this, [this] {
    const RecursivePanel::Run* run = recursivePanel_->currentRun();
    if (!run || !run->result || !run->result->model) return;
    if (auto m = std::dynamic_pointer_cast<const PhysicalModel>(run->result->model))
      armPanel_->setExternalModel(tr("recursive estimate (run %1, at %2 s)")
                                      .arg(run->id)
                                      .arg(run->reached, 0, 'f', 1),
                                  m, {}, "recursive");
  });
  // The Arm view highlights the part whose parameter the diagnosis names at the playhead.
  connect(diagnosisPanel_, &DiagnosisPanel::verdictShown, this, [this](const QString& parameter) {
    if (parameter.isEmpty())
      armPanel_->clearFault();
    else
      armPanel_->showParameterFault(parameter, tr("diagnosis: %1 changed").arg(parameter), "diagnosis");
  });
  transportBar_ = new TransportBar(playhead_, this);
  auto* transport = new QToolBar(tr("Playhead"), this);
  transport->setObjectName("transportToolBar");
  transport->setMovable(false);
  transport->addWidget(transportBar_);
  addToolBar(Qt::BottomToolBarArea, transport);
  session_ = new SessionController(this, workspace_);  // File menu: sessions and reports
  importer_ = new LogImporter(this);
  // The first size fits the screen (a 1366x768 laptop too); the docks scroll what is taller,
  // and are arranged for the screen's size. A layout kept from the last run comes back when
  // it was made for a screen of the same kind.
  const QRect screenRect = screen() ? screen()->availableGeometry() : QRect(0, 0, 1280, 860);
  const PanelDocks::Layout layout = PanelDocks::layoutFor(screenRect.size());
  // A laptop's whole screen; nine tenths of a larger one.
  if (layout == PanelDocks::Layout::Compact) resize(screenRect.size());
  else resize(screenRect.width() * 9 / 10, screenRect.height() * 9 / 10);
  docks_->arrange(layout);
  showWholeTabTitles();
  connect(this, &QMainWindow::tabifiedDockWidgetActivated, this, &MainWindow::showWholeTabTitles);

  QSettings settings;
  restoreGeometry(settings.value("window/geometry").toByteArray());
  if (settings.value("window/layout").toString() == PanelDocks::toString(docks_->layout()))
    restoreState(settings.value("window/state").toByteArray());
  showWholeTabTitles();
  rebuildRecentMenu();
  statusBar()->showMessage(tr("Open a robot log with Ctrl+O, or drop it on the window"));

  connect(&reader_, &QFutureWatcher<ReadLog>::finished, this, &MainWindow::onReadFinished);
  connect(workspace_, &Workspace::rangesChanged, this, [this] {
    QStringList parts;
    for (RangeKind k : {RangeKind::Estimation, RangeKind::Validation})
      if (auto r = workspace_->range(k))
        parts << tr("%1 %2-%3 s (%4 samples)")
                     .arg(toString(k))
                     .arg(r->start, 0, 'f', 3)
                     .arg(r->end, 0, 'f', 3)
                     .arg(workspace_->samples(k).size());
    if (!parts.isEmpty()) statusBar()->showMessage(parts.join("; "), 8000);
  });
  connect(workspace_, &Workspace::currentChanged, this, [this] {
    if (workspace_->isPreprocessed())
      statusBar()->showMessage(tr("Preprocessed data in use: %1 samples at %2 Hz")
                                   .arg(workspace_->current()->samples())
                                   .arg(workspace_->current()->sampleRateHz(), 0, 'g', 6),
                               8000);
  });
}

MainWindow::~MainWindow() { reader_.waitForFinished(); }

bool MainWindow::isBusy() const {
  return reader_.isRunning() || session_->isBusy() || logPanel_->isBusy() || comparePanel_->isBusy() ||
         residualsPanel_->isBusy() || bodePanel_->isBusy() || preprocessPanel_->isBusy();
}

void MainWindow::createMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  QAction* open = file->addAction(tr("&Open log..."), this, &MainWindow::openDialog);
  file->addAction(tr("&Import log..."), this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Import robot log"), QSettings().value("lastDir").toString(),
                                                      tr("Robot logs (*.csv *.dat *.txt *.mat);;All files (*)"));
    if (!path.isEmpty()) importFile(path);
  })->setShortcut(QKeySequence("Ctrl+I"));
  open->setShortcut(QKeySequence::Open);
  recentMenu_ = file->addMenu(tr("Open &recent"));
  QAction* exportAction = file->addAction(tr("&Export data as CSV..."), this, &MainWindow::exportData);
  exportAction->setShortcut(QKeySequence("Ctrl+E"));
  file->addSeparator();
  QAction* quit = file->addAction(tr("&Quit"), this, &QWidget::close);
  quit->setShortcut(QKeySequence::Quit);

  QMenu* data = menuBar()->addMenu(tr("&Data"));
  auto mode = [this, data](const QString& text, const QString& keys, LogPanel::Mode m) {
    QAction* a = data->addAction(text, this, [this, m] { logPanel_->setMode(m); });
    a->setShortcut(QKeySequence(keys));
  };
  mode(tr("&Zoom and pan"), "Ctrl+1", LogPanel::Mode::Navigate);
  mode(tr("Select &estimation range"), "Ctrl+2", LogPanel::Mode::SelectEstimation);
  mode(tr("Select &validation range"), "Ctrl+3", LogPanel::Mode::SelectValidation);
  data->addSeparator();
  QAction* all = data->addAction(tr("&Show whole log"), logPanel_, &LogPanel::showAll);
  all->setShortcut(QKeySequence("Ctrl+0"));
  QAction* apply = data->addAction(tr("&Apply preprocessing"), this, [this] { preprocessPanel_->apply(); });
  apply->setShortcut(QKeySequence("Ctrl+Return"));
  data->addAction(tr("&Undo preprocessing"), this, [this] { preprocessPanel_->reset(); });

  viewMenu_ = menuBar()->addMenu(tr("&View"));
  docks_ = new PanelDocks(this, viewMenu_);

  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  QAction* undo = workspace_->undoStack()->createUndoAction(this, tr("&Undo"));
  undo->setShortcut(QKeySequence::Undo);
  edit->addAction(undo);
  QAction* redo = workspace_->undoStack()->createRedoAction(this, tr("&Redo"));
  redo->setShortcut(QKeySequence::Redo);
  edit->addAction(redo);
  menuBar()->insertMenu(data->menuAction(), edit);

  QMenu* help = menuBar()->addMenu(tr("&Help"));
  help->addAction(tr("&Command line..."), this, [this] {
    std::ostringstream out, err;
    cli::runCommandLine({"--help"}, out, err);
    QMessageBox box(QMessageBox::Information, tr("FlexArm command line"),
                    tr("The same executable runs every step without a window:"), QMessageBox::Ok, this);
    box.setInformativeText(QString::fromStdString(out.str()));
    box.exec();
  });
  help->addAction(tr("&About FlexArm"), this, [this] {
    QMessageBox::about(this, tr("About FlexArm"),
                       tr("<b>FlexArm %1</b><p>Identification, diagnosis and control of "
                          "flexible robot arms.</p>").arg(FLEXARM_VERSION));
  });
}

void MainWindow::showWholeTabTitles() {
  // Eleven panels share one dock area: their tabs keep whole titles and scroll, rather than
  // reading "Prepr...", "M...".
  // A point smaller than the window's text, so that on a laptop's dock all eleven fit.
  QFont small = font();
  small.setPointSizeF(std::max(7.0, small.pointSizeF() - 1.0));
  for (QTabBar* bar : findChildren<QTabBar*>(Qt::FindDirectChildrenOnly)) {
    bar->setElideMode(Qt::ElideNone);
    bar->setUsesScrollButtons(true);
    bar->setFont(small);
  }
}

QDockWidget* MainWindow::addPanel(QWidget* panel, const QString& title, const char* objectName,
                                  const QString& shortcut, QDockWidget* /*tabWith*/) {
  // The layout for the screen places every panel (PanelDocks::arrange); the 3D view fills its
  // dock at any size and has a place of its own on a wide screen.
  const bool arm = panel == armPanel_;
  return docks_->add(panel, title, objectName, shortcut,
                     arm ? PanelDocks::Place::Own : PanelDocks::Place::Tabs, !arm);
}

void MainWindow::openDialog() {
  QSettings settings;
  const QString path = QFileDialog::getOpenFileName(
      this, tr("Open robot log"), settings.value("lastDir").toString(),
      tr("Robot logs (*.csv *.dat *.txt *.mat);;All files (*)"));
  if (!path.isEmpty()) requestOpenFile(path);
}

void MainWindow::requestOpenFile(const QString& path) {
  if (session_->confirmReplace(tr("opening %1").arg(QFileInfo(path).fileName()))) openFile(path);
}

void MainWindow::openFile(const QString& path) {
  // A headerless table names nothing: the import dialog asks which column is what.
  if (looksLikeTable(path)) importer_->start(path, LogReadOptions{});
  else openFile(path, LogReadOptions{});
}

void MainWindow::importFile(const QString& path) {
  if (session_->confirmReplace(tr("opening %1").arg(QFileInfo(path).fileName())))
    importer_->start(path, workspace_->logPath() == path ? workspace_->logReadOptions() : LogReadOptions{});
}

void MainWindow::openFile(const QString& path, const LogReadOptions& options) {
  if (reader_.isRunning()) {
    statusBar()->showMessage(tr("Still reading %1").arg(readingPath_), 4000);
    return;
  }
  readingPath_ = path;
  readingOptions_ = options;
  readStartMs_ = QDateTime::currentMSecsSinceEpoch();
  statusBar()->showMessage(tr("Reading %1...").arg(path));
  startBusyProgress(progress_, this, tr("Opening log"), tr("Reading %1").arg(QFileInfo(path).fileName()),
                    &readCancelled_);
  const std::string p = path.toStdString();
  reader_.setFuture(QtConcurrent::run([p, options] {
    ReadLog r{readLog(p, options), {}};
    // The checksum a session records, formed here rather than on the GUI thread.
    if (r.result.ok) r.sha256 = sha256OfFile(p, nullptr).value_or("");
    return r;
  }));
}

void MainWindow::onReadFinished() {
  if (progress_) progress_->hide();
  if (readCancelled_) {
    statusBar()->showMessage(tr("Opening %1 cancelled").arg(readingPath_), 5000);
    return;
  }
  ReadLog read = reader_.result();
  LogReadResult& r = read.result;
  if (!r.ok && r.irregularTime && !readingOptions_.keepIrregularTime) {
    offerResampling(QString::fromStdString(r.error.toString()));
    return;
  }
  if (!r.ok && r.needsSampleTime && !(readingOptions_.sampleTime > 0.0)) {
    // The file stores no time: ask for the sample time instead of guessing one.
    bool given = false;
    const double ts = QInputDialog::getDouble(
        this, tr("Sample time"),
        tr("%1 stores no time. Seconds between samples (e.g. 0.0005 for 2 kHz):")
            .arg(QFileInfo(readingPath_).fileName()),
        0.001, 1e-6, 1e6, 6, &given);
    if (given) {
      LogReadOptions options = readingOptions_;
      options.sampleTime = ts;
      openFile(readingPath_, options);
    } else {
      statusBar()->showMessage(tr("Opening %1 cancelled").arg(readingPath_), 5000);
    }
    return;
  }
  if (!r.ok && (r.needsMapping || readingOptions_.mapping != LogMapping{})) {
    // Signals named otherwise, or choices that did not hold: the import dialog asks (again).
    importer_->start(readingPath_, readingOptions_,
                     r.needsMapping ? QString() : QString::fromStdString(r.error.toString()));
    return;
  }
  if (!r.ok) {
    const QString msg = QString::fromStdString(r.error.toString());
    statusBar()->showMessage(tr("Could not open %1").arg(readingPath_), 10000);
    showError(tr("Could not open the log"), msg);
    emit openFailed(msg);
    return;
  }
  const std::size_t samples = r.data.samples(), channels = r.data.channels.size();
  const double rate = r.data.sampleRateHz();
  session_->setLogChecksum(read.sha256);
  workspace_->setLog(std::move(r.data), readingPath_, readingOptions_);
  // The time from the request to the log shown in the Log panel (reading, checking and
  // drawing); the panels that simulate models on it go on in the background.
  const double seconds = (QDateTime::currentMSecsSinceEpoch() - readStartMs_) / 1000.0;
  addRecent(readingPath_);
  QSettings().setValue("lastDir", QFileInfo(readingPath_).absolutePath());
  setWindowTitle(QString("FlexArm - %1[*]").arg(QFileInfo(readingPath_).fileName()));
  statusBar()->showMessage(tr("Opened %1: %2 channels, %3 samples at %4 Hz (%5 s)")
                               .arg(QFileInfo(readingPath_).fileName())
                               .arg(channels)
                               .arg(samples)
                               .arg(rate, 0, 'g', 6)
                               .arg(seconds, 0, 'f', 2));
  if (!r.warnings.empty()) {
    // What was assumed or skipped, where the user sees it.
    QString text;
    for (const auto& w : r.warnings) text += (text.isEmpty() ? "" : "\n") + QString::fromStdString(w);
    statusBar()->showMessage(tr("Opened %1 - %2").arg(QFileInfo(readingPath_).fileName(), text.section('\n', 0, 0)), 15000);
    auto* box = new QMessageBox(QMessageBox::Information, tr("Read with assumptions"),
                                tr("%1 was read; note:\n\n%2").arg(QFileInfo(readingPath_).fileName(), text),
                                QMessageBox::Ok, this);
    box->setObjectName("readWarningsBox");
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->open();
  }
  if (!workspace_->raw()->isUniform()) {
    statusBar()->showMessage(tr("Opened %1 with irregular time stamps: resample it in the Preprocess panel")
                                 .arg(QFileInfo(readingPath_).fileName()));
    preprocessDock_->show();
    preprocessDock_->raise();
  }
  emit logOpened(readingPath_);
}

void MainWindow::offerResampling(const QString& problem) {
  // Reading stays strict: the log opens as recorded only when the engineer asks, and then
  // waits for the explicit resampling step before any analysis.
  auto* box = new QMessageBox(QMessageBox::Question, tr("Irregular time stamps"),
                              tr("%1\n\nOpen the log as recorded and put it on a uniform grid in "
                                 "the Preprocess panel?").arg(problem),
                              QMessageBox::Open | QMessageBox::Cancel, this);
  box->setObjectName("irregularTimeBox");
  box->setAttribute(Qt::WA_DeleteOnClose);
  const QString path = readingPath_;
  LogReadOptions options = readingOptions_;
  options.keepIrregularTime = true;
  connect(box, &QMessageBox::finished, this, [this, path, options](int result) {
    if (result == QMessageBox::Open) openFile(path, options);
    else statusBar()->showMessage(tr("Opening %1 cancelled").arg(path), 5000);
  });
  statusBar()->showMessage(tr("%1 has irregular time stamps").arg(QFileInfo(path).fileName()), 10000);
  box->open();
}

void MainWindow::showError(const QString& title, const QString& message) {
  // Not modal-blocking: the window stays usable and tests are not held up.
  auto* box = new QMessageBox(QMessageBox::Warning, title, message, QMessageBox::Ok, this);
  box->setObjectName("errorBox");
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
}

void MainWindow::exportData() {
  if (!workspace_->current()) {
    statusBar()->showMessage(workspace_->needsResampling()
                                 ? tr("Nothing to export: resample the log in the Preprocess panel first")
                                 : tr("Nothing to export: open a log first"), 5000);
    return;
  }
  QSettings settings;
  const QString path = QFileDialog::getSaveFileName(this, tr("Export data"),
                                                    settings.value("lastDir").toString(),
                                                    tr("FlexArm CSV log (*.csv)"));
  if (path.isEmpty()) return;
  IdData d = workspace_->currentWithRanges();
  storeRanges(d);
  ReadError err;
  if (!writeFlexArmCsv(d, path.toStdString(), &err))
    showError(tr("Export failed"), QString::fromStdString(err.toString()));
  else
    statusBar()->showMessage(tr("Wrote %1 (%2 samples)").arg(path).arg(d.samples()), 6000);
}

QStringList MainWindow::recentFiles() const { return recentList("recentFiles"); }

void MainWindow::addRecent(const QString& path) {
  addToRecentList("recentFiles", path, kMaxRecent);
  rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu() {
  recentMenu_->clear();
  const QStringList list = recentFiles();
  for (int i = 0; i < list.size(); ++i) {
    QAction* a = recentMenu_->addAction(QString("&%1 %2").arg(i + 1).arg(QFileInfo(list[i]).fileName()),
                                        this, [this, p = list[i]] { requestOpenFile(p); });
    a->setToolTip(list[i]);
    if (i < 9) a->setShortcut(QKeySequence(QString("Alt+Shift+%1").arg(i + 1)));
  }
  recentMenu_->setEnabled(!list.isEmpty());
}

void MainWindow::closeEvent(QCloseEvent* e) {
  if (!session_->confirmReplace(tr("closing the window"))) {
    e->ignore();
    return;
  }
  QSettings settings;
  settings.setValue("window/geometry", saveGeometry());
  settings.setValue("window/state", saveState());
  settings.setValue("window/layout", PanelDocks::toString(docks_->layout()));
  QMainWindow::closeEvent(e);
}

void MainWindow::keyPressEvent(QKeyEvent* e) {
  // Keys reach the window only when no focused widget used them.
  if (TransportBar::handleKey(playhead_, e) || logPanel_->handleModeKey(e)) {
    e->accept();
    return;
  }
  QMainWindow::keyPressEvent(e);
}

void MainWindow::dragEnterEvent(QDragEnterEvent* e) {
  if (e->mimeData()->hasUrls() && !e->mimeData()->urls().isEmpty() &&
      e->mimeData()->urls().first().isLocalFile())
    e->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* e) {
  const auto urls = e->mimeData()->urls();
  if (urls.isEmpty() || !urls.first().isLocalFile()) return;
  e->acceptProposedAction();
  requestOpenFile(urls.first().toLocalFile());
}

}  // namespace flexarm
