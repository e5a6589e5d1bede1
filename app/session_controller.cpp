#include "app/session_controller.h"

#include <algorithm>

#include "app/recent_files.h"

#include <QAction>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QProgressDialog>
#include <QPushButton>
#include <QSettings>
#include <QStatusBar>
#include <QTimer>
#include <QUndoStack>
#include <QtConcurrent>

#include "app/main_window.h"
#include "app/report_writer.h"
#include "app/session_parts.h"
#include "widgets/diagnosis_panel.h"
#include "widgets/discovery_panel.h"
#include "widgets/fit_panel.h"
#include "widgets/preprocess_panel.h"
#include "widgets/recursive_panel.h"
#include "core/session/fit_request.h"
#include "core/session/sha256.h"
#include "widgets/workspace.h"

namespace flexarm {
namespace {

constexpr int kMaxRecentSessions = 8;
constexpr int kAutosaveMs = 60000;

}  // namespace

SessionController::SessionController(MainWindow* window, Workspace* workspace)
    : QObject(window), window_(window), workspace_(workspace), autosaveTimer_(new QTimer(this)) {
  addMenuActions();
  connect(&opener_, &QFutureWatcher<Opened>::finished, this, &SessionController::onOpened);
  connect(&replayer_, &QFutureWatcher<ReplayResult>::finished, this, &SessionController::onReplayed);
  connect(&writer_, &QFutureWatcher<QString>::finished, this,
          [this] { onReportWritten(writer_.result()); });
  connect(workspace_, &Workspace::logChanged, this, [this] {
    if (restoring_) return;
    std::string why;
    logSha256_ = !pendingSha256_.empty()
                     ? pendingSha256_
                     : sha256OfFile(workspace_->logPath().toStdString(), &why).value_or("");
    pendingSha256_.clear();
    workspace_->setLogSha256(logSha256_);
    loaded_ = Session{};  // a log opened by hand starts a new session
    path_.clear();
    setDirty(false);  // nothing of the new workspace is unsaved yet
  });
  // Preprocessing, ranges and model edits go through the undo stack: its clean state is the
  // saved one. A panel's new result (discovery, diagnosis, recursive run), recorded by its
  // panel with the data it ran on (Workspace::recordResult), marks the workspace changed.
  connect(workspace_->undoStack(), &QUndoStack::cleanChanged, this, [this] { setDirty(dirty_); });
  connect(window_->discoveryPanel(), &DiscoveryPanel::finished, this, &SessionController::markDirty);
  connect(window_->diagnosisPanel(), &DiagnosisPanel::finished, this, &SessionController::markDirty);
  connect(window_, &MainWindow::logOpened, this, &SessionController::offerRecompute);
  connect(window_->fitPanel(), &FitPanel::estimated, this, [this] {
    if (!recomputeQueue_.isEmpty()) recomputeNext();
  });
  connect(window_->recursivePanel(), &RecursivePanel::runFinished, this, &SessionController::markDirty);
  autosaveTimer_->setInterval(kAutosaveMs);
  connect(autosaveTimer_, &QTimer::timeout, this, &SessionController::autosave);
  autosaveTimer_->start();
  // A window closed normally leaves no autosave behind; one found on start means a crash.
  connect(qApp, &QCoreApplication::aboutToQuit, this, [this] {
    if (offerRecovery_) QFile::remove(autosavePath());
  });
  QTimer::singleShot(0, this, &SessionController::offerRecovery);
}

SessionController::~SessionController() {
  opener_.waitForFinished();
  replayer_.waitForFinished();
  writer_.waitForFinished();
  if (offerRecovery_) QFile::remove(autosavePath());  // a normal end; only a crash leaves it
}

void SessionController::addMenuActions() {
  QMenu* file = window_->menuBar()->actions().first()->menu();
  QAction* before = nullptr;  // the separator above Quit
  for (QAction* a : file->actions())
    if (a->isSeparator()) before = a;
  auto add = [&](const QString& text, const QString& keys, auto slot) {
    auto* a = new QAction(text, file);
    if (!keys.isEmpty()) a->setShortcut(QKeySequence(keys));
    connect(a, &QAction::triggered, this, slot);
    file->insertAction(before, a);
    return a;
  };
  file->insertSeparator(before);
  add(tr("Open &session..."), "Ctrl+Shift+O", &SessionController::openDialog);
  recentMenu_ = new QMenu(tr("Open recent sess&ion"), file);
  file->insertMenu(before, recentMenu_);
  add(tr("&Save session"), "Ctrl+S", &SessionController::saveCurrent)->setObjectName("saveSessionAction");
  add(tr("Save session &as..."), "Ctrl+Shift+S", &SessionController::saveAs);
  add(tr("Export re&port (PDF, HTML)..."), "Ctrl+Shift+E", &SessionController::exportDialog);
  add(tr("Recompute estimates on the open &data"), "", &SessionController::recomputeStale)
      ->setObjectName("recomputeAction");
  rebuildRecent();
}

Session SessionController::capture(const QString& sessionPath) const {
  Session s;
  const std::string sp = sessionPath.toStdString();
  auto stored = [&](const std::string& path) {
    return sp.empty() ? QFileInfo(QString::fromStdString(path)).absoluteFilePath().toStdString()
                      : storedLogPath(sp, path);
  };
  LogReference main;
  main.name = loaded_.logs.empty() ? "log" : loaded_.logs.front().name;
  main.path = stored(workspace_->logPath().toStdString());
  main.sha256 = logSha256_;
  main.read = workspace_->logReadOptions();
  s.logs.push_back(main);
  for (std::size_t i = 1; i < loaded_.logs.size(); ++i) {
    LogReference extra = loaded_.logs[i];
    extra.path = stored(resolveLogPath(path_.toStdString(), extra.path));
    s.logs.push_back(extra);
  }
  // Logs a part names (a panel's reference log), replacing one of the same name.
  for (const auto& part : windowSessionParts()) {
    if (!part.logs) continue;
    for (LogReference extra : part.logs(*window_)) {
      extra.sha256 = sha256OfFile(extra.path, nullptr).value_or("");
      extra.path = stored(extra.path);
      auto same = std::find_if(s.logs.begin() + 1, s.logs.end(),
                               [&](const LogReference& l) { return l.name == extra.name; });
      if (same != s.logs.end()) *same = extra;
      else s.logs.push_back(extra);
    }
  }
  s.preprocessed = workspace_->isPreprocessed();
  if (s.preprocessed) s.preprocess = workspace_->preprocessOptions();
  auto seconds = [&](RangeKind k) -> std::optional<SecondsRange> {
    auto r = workspace_->range(k);
    if (!r || !(r->start < r->end)) return std::nullopt;
    return SecondsRange{r->start, r->end};
  };
  s.estimation = seconds(RangeKind::Estimation);
  s.validation = seconds(RangeKind::Validation);
  s.parts = loaded_.parts.is_object() ? loaded_.parts : nlohmann::json::object();
  for (const auto& part : windowSessionParts()) {
    nlohmann::json section = part.capture(*window_);
    if (section.is_null()) s.parts.erase(part.key);
    else s.parts[part.key] = section;
  }
  return s;
}

bool SessionController::save(const QString& path, QString* why) {
  if (!workspace_->hasLog()) {
    if (why) *why = tr("Open a log first: a session starts from a log.");
    return false;
  }
  std::string message;
  Session s = capture(path);
  if (!saveSession(s, path.toStdString(), &message)) {
    if (why) *why = QString::fromStdString(message);
    return false;
  }
  loaded_.logs = s.logs;
  loaded_.parts = s.parts;
  path_ = path;
  setDirty(false);
  workspace_->undoStack()->setClean();
  QFile::remove(autosavePath());
  addRecent(path);
  window_->statusBar()->showMessage(tr("Saved session %1").arg(path), 6000);
  emit sessionSaved(path);
  return true;
}

void SessionController::saveCurrent() {
  if (path_.isEmpty() || recovering_) return saveAs();
  QString why;
  if (!save(path_, &why)) fail(tr("Could not save the session"), why);
}

void SessionController::saveAs() {
  if (!workspace_->hasLog()) {
    fail(tr("Nothing to save"), tr("Open a log first: a session starts from a log."));
    return;
  }
  QString start = path_.isEmpty() ? QSettings().value("lastDir").toString() : path_;
  const QString path = QFileDialog::getSaveFileName(window_, tr("Save session"), start,
                                                    tr("FlexArm sessions (*.json)"));
  if (path.isEmpty()) return;
  QString why;
  if (!save(path.endsWith(".json") ? path : path + ".json", &why))
    fail(tr("Could not save the session"), why);
}

void SessionController::openDialog() {
  const QString path = QFileDialog::getOpenFileName(window_, tr("Open session"),
                                                    QSettings().value("lastDir").toString(),
                                                    tr("FlexArm sessions (*.json);;All files (*)"));
  if (!path.isEmpty()) requestOpen(path);
}

void SessionController::open(const QString& path) {
  if (isBusy()) {
    window_->statusBar()->showMessage(tr("Still busy with %1").arg(openingPath_), 4000);
    return;
  }
  openingPath_ = path;
  cancelled_ = false;
  if (!progress_) {
    progress_ = new QProgressDialog(window_);
    progress_->setRange(0, 0);
    progress_->setMinimumDuration(400);
    progress_->setAutoClose(false);
    progress_->setAutoReset(false);
    connect(progress_, &QProgressDialog::canceled, this, [this] { cancelled_ = true; });
  }
  progress_->setWindowTitle(tr("Opening session"));
  progress_->setLabelText(tr("Reading %1 and its logs").arg(QFileInfo(path).fileName()));
  progress_->reset();
  progress_->setRange(0, 0);
  window_->statusBar()->showMessage(tr("Opening session %1...").arg(path));
  const std::string p = path.toStdString();
  opener_.setFuture(QtConcurrent::run([p] {
    Opened o;
    o.parsed = loadSession(p);
    if (o.parsed.ok) o.prepared = prepareSession(o.parsed.session, p);
    return o;
  }));
}

void SessionController::onOpened() {
  if (progress_) progress_->hide();
  const bool recovered = openingPath_ == autosavePath();
  if (cancelled_) {
    window_->statusBar()->showMessage(tr("Opening %1 cancelled").arg(openingPath_), 5000);
    return;
  }
  Opened o = opener_.result();
  QString message;
  if (!o.parsed.ok) message = QString::fromStdString(o.parsed.message);
  else if (!o.prepared.ok) message = openingPath_ + ": " + QString::fromStdString(o.prepared.message);
  if (!message.isEmpty()) {
    window_->statusBar()->showMessage(tr("Could not open %1").arg(openingPath_), 10000);
    fail(tr("Could not open the session"), message);
    emit openFailed(message);
    return;
  }
  // Everything that can fail is done: now change the window.
  const Session& s = o.parsed.session;
  PreparedLog& log = o.prepared.logs.front();
  restoring_ = true;
  workspace_->setLog(std::move(log.raw), QString::fromStdString(log.path), s.logs.front().read);
  workspace_->setLogSha256(log.sha256);
  if (s.preprocessed) {
    IdData processed = std::move(log.data);
    processed.estimationRange.reset();
    processed.validationRange.reset();
    workspace_->setPreprocessedDirect(std::make_shared<IdData>(std::move(processed)), s.preprocess);
    window_->preprocessPanel()->setOptions(s.preprocess);
  }
  auto toTime = [](const std::optional<SecondsRange>& r) -> std::optional<TimeRange> {
    if (!r) return std::nullopt;
    return TimeRange{r->start, r->end};
  };
  workspace_->setRangeDirect(RangeKind::Estimation, toTime(s.estimation));
  workspace_->setRangeDirect(RangeKind::Validation, toTime(s.validation));
  opened_ = s;  // sessionLogPath() answers the parts' restore from it
  for (const auto& part : windowSessionParts()) {
    if (s.parts.contains(part.key)) part.restore(s.parts[part.key], *window_);
    else if (part.reset) part.reset(*window_);
  }
  workspace_->undoStack()->clear();
  restoring_ = false;
  logSha256_ = log.sha256;
  loaded_ = s;
  recovering_ = recovered;
  path_ = recovered ? QString() : openingPath_;
  setDirty(recovered);
  if (!recovered) {
    addRecent(openingPath_);
    QSettings().setValue("lastDir", QFileInfo(openingPath_).absolutePath());
  }
  window_->setWindowTitle(QString("FlexArm - %1[*]").arg(recovered ? tr("recovered session")
                                                                : QFileInfo(openingPath_).fileName()));
  QString status = recovered ? tr("Recovered the autosaved session: save it with Ctrl+S")
                             : tr("Opened session %1").arg(QFileInfo(openingPath_).fileName());
  for (const auto& w : o.prepared.warnings) status += " - " + QString::fromStdString(w);
  window_->statusBar()->showMessage(status, 15000);
  emit sessionOpened(openingPath_);
}

QString SessionController::sessionLogPath(const std::string& name) const {
  const Session& s = restoring_ ? opened_ : loaded_;
  const std::string base = restoring_ ? openingPath_.toStdString() : path_.toStdString();
  for (const auto& l : s.logs)
    if (l.name == name) return QString::fromStdString(resolveLogPath(base, l.path));
  return {};
}

void SessionController::exportDialog() {
  if (!workspace_->hasLog()) {
    fail(tr("Nothing to report"), tr("Open a log or a session first."));
    return;
  }
  QString start = QSettings().value("lastDir").toString() + "/report.pdf";
  const QString path = QFileDialog::getSaveFileName(window_, tr("Export report"), start,
                                                    tr("PDF (*.pdf);;HTML (*.html)"));
  if (!path.isEmpty()) exportReport(path);
}

void SessionController::exportReport(const QString& path) {
  if (isBusy() || !workspace_->hasLog()) {
    emit reportFailed(tr("Open a log first, or wait for the current task."));
    return;
  }
  if (!path.endsWith(".pdf", Qt::CaseInsensitive) && !path.endsWith(".html", Qt::CaseInsensitive)) {
    emit reportFailed(tr("A report is a .pdf or .html file."));
    return;
  }
  reportPath_ = path;
  const Session s = capture(path_);
  const std::string sp = path_.toStdString();
  window_->statusBar()->showMessage(tr("Computing the report..."));
  reportPermille_ = std::make_shared<std::atomic<int>>(0);
  reportAbort_ = std::make_shared<std::atomic<bool>>(false);
  if (!reportProgress_) {
    reportProgress_ = new QProgressDialog(window_);
    reportProgress_->setObjectName("reportProgress");
    reportProgress_->setWindowTitle(tr("Export report"));
    reportProgress_->setRange(0, 1000);
    reportProgress_->setMinimumDuration(300);
    reportProgress_->setAutoClose(false);
    reportProgress_->setAutoReset(false);
    connect(reportProgress_, &QProgressDialog::canceled, this, &SessionController::cancelReport);
    reportPoll_ = new QTimer(this);
    reportPoll_->setInterval(100);
    connect(reportPoll_, &QTimer::timeout, this, [this] {
      if (reportPermille_) reportProgress_->setValue(reportPermille_->load());
    });
  }
  reportProgress_->reset();
  reportProgress_->setLabelText(tr("Computing the report %1").arg(QFileInfo(path).fileName()));
  reportProgress_->setValue(0);
  reportPoll_->start();
  ReplayOptions options;
  options.progress = [permille = reportPermille_, abort = reportAbort_](double f, const std::string&) {
    permille->store(static_cast<int>(1000.0 * std::clamp(f, 0.0, 1.0)));
    return abort->load() ? ProgressAction::Abort : ProgressAction::Continue;
  };
  replayer_.setFuture(QtConcurrent::run([s, sp, options] { return replaySession(s, sp, options); }));
}

void SessionController::cancelReport() {
  if (!reportAbort_ || !replayer_.isRunning()) return;
  reportAbort_->store(true);
  window_->statusBar()->showMessage(tr("Cancelling the report..."));
}

void SessionController::onReplayed() {
  ReplayResult r = replayer_.result();
  reportPoll_->stop();
  reportProgress_->hide();
  if (r.termination == Termination::Cancelled || (reportAbort_ && reportAbort_->load())) {
    // Cancelled, even when the replay ended before it saw the request: nothing is written.
    window_->statusBar()->showMessage(tr("Report export cancelled: %1 not written").arg(reportPath_), 8000);
    emit reportCancelled(reportPath_);
    return;
  }
  QString why;
  if (r.termination == Termination::Converged) {
    if (path_.isEmpty()) r.report.session = "unsaved session";
    if (reportPath_.endsWith(".pdf", Qt::CaseInsensitive)) {
      const bool ok = writeReportPdf(r.report, reportPath_, &why);
      return onReportWritten(ok ? QString() : why);
    }
    // Plots are drawn here (widgets); encoding them as PNG and writing run in the background.
    const QList<QImage> plots = reportPlotImages(r.report);
    const QString path = reportPath_;
    writer_.setFuture(QtConcurrent::run([report = std::move(r.report), plots, path] {
      QString message;
      return writeReportHtml(report, plots, path, &message) ? QString() : message;
    }));
    return;
  }
  onReportWritten(QString::fromStdString(r.message));
}

void SessionController::onReportWritten(const QString& error) {
  if (error.isEmpty()) {
    window_->statusBar()->showMessage(tr("Wrote report %1").arg(reportPath_), 8000);
    emit reportExported(reportPath_);
    return;
  }
  fail(tr("Could not export the report"), error);
  emit reportFailed(error);
}

QString SessionController::autosavePath() const {
  return QFileInfo(QSettings().fileName()).absolutePath() + "/autosave-session.json";
}

bool SessionController::autosave() {
  if (!offerRecovery_ || !isDirty() || !workspace_->hasLog() || restoring_) return false;
  std::string why;
  return saveSession(capture(autosavePath()), autosavePath().toStdString(), &why);
}

void SessionController::setAutosaveInterval(int ms) { autosaveTimer_->setInterval(ms); }

void SessionController::offerRecovery() {
  const QString path = autosavePath();
  if (!offerRecovery_ || !QFile::exists(path)) return;
  auto* box = new QMessageBox(QMessageBox::Question, tr("Recover unsaved work?"),
                              tr("FlexArm did not close normally last time. Open the session "
                                 "saved automatically at %1?")
                                  .arg(QFileInfo(path).lastModified().toString("yyyy-MM-dd hh:mm")),
                              QMessageBox::Open | QMessageBox::Discard, window_);
  box->setObjectName("recoverBox");
  box->setAttribute(Qt::WA_DeleteOnClose);
  connect(box, &QMessageBox::finished, this, [this, path](int result) {
    if (result == QMessageBox::Open) open(path);
    else QFile::remove(path);
  });
  box->open();
  emit recoveryOffered(path);
}

void SessionController::markDirty() {
  if (!restoring_) setDirty(true);
}

void SessionController::setDirty(bool dirty) {
  dirty_ = dirty;
  window_->setWindowModified(isDirty());
}

bool SessionController::isDirty() const { return dirty_ || !workspace_->undoStack()->isClean(); }

bool SessionController::confirmReplace(const QString& what) {
  if (!isDirty() || !workspace_->hasLog()) return true;
  ReplaceDecision d = ReplaceDecision::Cancel;
  if (decide_) {
    d = decide_(what);
  } else {
    QMessageBox box(QMessageBox::Warning, tr("Unsaved changes"),
                    tr("The workspace has changes that are not saved (preprocessing, ranges, "
                       "models or designs). Save them before %1?").arg(what),
                    QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, window_);
    box.setObjectName("replaceBox");
    box.setDefaultButton(QMessageBox::Save);
    const int answer = box.exec();
    d = answer == QMessageBox::Save      ? ReplaceDecision::Save
        : answer == QMessageBox::Discard ? ReplaceDecision::Discard
                                         : ReplaceDecision::Cancel;
  }
  if (d == ReplaceDecision::Cancel) {
    window_->statusBar()->showMessage(tr("Kept the workspace: nothing was replaced"), 5000);
    return false;
  }
  if (d == ReplaceDecision::Discard) return true;
  if (path_.isEmpty() || recovering_) saveAs();
  else saveCurrent();
  return !isDirty();  // saved; a failed or cancelled save keeps everything
}

QList<QPair<QString, QString>> SessionController::staleEstimates() const {
  QList<QPair<QString, QString>> stale;
  if (!workspace_->hasLog()) return stale;
  const Provenance open = workspace_->dataProvenance();
  for (const auto& m : workspace_->models()) {
    if (!m.fitRequest || !m.fitRequest->provenance) continue;
    const std::string other = dataMismatch(*m.fitRequest->provenance, open);
    if (!other.empty()) stale.append({nameOf(m), QString::fromStdString(other)});
  }
  return stale;
}

void SessionController::offerRecompute() {
  const auto stale = staleEstimates();
  if (stale.isEmpty()) return;
  QString text = stale.size() == 1 ? tr("An estimate of the model list was computed on other data:")
                                   : tr("%1 estimates of the model list were computed on other data:")
                                         .arg(stale.size());
  for (const auto& [name, why] : stale) text += "\n\n" + name + ": " + why + ".";
  auto* box = new QMessageBox(QMessageBox::Question, tr("Estimates of other data"),
                              text + tr("\n\nRecompute them on the open data? The estimates "
                                        "shown now stay in the list as they are."),
                              QMessageBox::NoButton, window_);
  box->setObjectName("recomputeBox");
  box->addButton(tr("Recompute"), QMessageBox::AcceptRole)->setObjectName("recomputeButton");
  box->addButton(tr("Keep as they are"), QMessageBox::RejectRole);
  box->setAttribute(Qt::WA_DeleteOnClose);
  connect(box, &QMessageBox::accepted, this, &SessionController::recomputeStale);
  box->open();
  emit recomputeOffered(static_cast<int>(stale.size()));
}

void SessionController::recomputeStale() {
  recomputeQueue_.clear();
  for (const auto& item : staleEstimates()) recomputeQueue_.append(item.first);
  if (recomputeQueue_.isEmpty()) {
    window_->statusBar()->showMessage(tr("Every estimate was computed on the open data"), 5000);
    return;
  }
  recomputeNext();
}

void SessionController::recomputeNext() {
  while (!recomputeQueue_.isEmpty()) {
    const QString name = recomputeQueue_.takeFirst();
    for (const auto& m : workspace_->models()) {
      if (nameOf(m) != name || !m.fitRequest) continue;
      const FitRequest request = *m.fitRequest;  // the list changes when the fit lands
      window_->statusBar()->showMessage(tr("Recomputing %1 on the open data...").arg(name));
      if (window_->fitPanel()->recompute(request)) return;  // the next starts when it ends
    }
  }
}

void SessionController::requestOpen(const QString& path) {
  if (confirmReplace(tr("opening the session %1").arg(QFileInfo(path).fileName()))) open(path);
}

QStringList SessionController::recentSessions() const { return recentList("sessions/recent"); }

void SessionController::addRecent(const QString& path) {
  addToRecentList("sessions/recent", path, kMaxRecentSessions);
  rebuildRecent();
}

void SessionController::rebuildRecent() {
  recentMenu_->clear();
  const QStringList list = recentSessions();
  for (const QString& p : list)
    recentMenu_->addAction(QFileInfo(p).fileName(), this, [this, p] { requestOpen(p); })->setToolTip(p);
  recentMenu_->setEnabled(!list.isEmpty());
}

void SessionController::fail(const QString& title, const QString& message) {
  auto* box = new QMessageBox(QMessageBox::Warning, title, message, QMessageBox::Ok, window_);
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->setObjectName("sessionErrorBox");
  box->open();
}

}  // namespace flexarm
