#pragma once
// Sessions in the window: File -> Open session, Save session (Ctrl+S), Save session as
// (Ctrl+Shift+S), Open recent session, Export report (PDF or HTML); autosave of unsaved work
// every minute next to the settings, offered back after a crash. Opening reads the file,
// its logs and the preprocessing off the GUI thread and changes the window only when all
// of it succeeded.
#include <QFutureWatcher>
#include <QObject>
#include <QString>
#include <QStringList>
#include <atomic>
#include <functional>
#include <memory>

#include "core/session/replay.h"
#include "core/session/session.h"

class QMenu;
class QProgressDialog;
class QTimer;

namespace flexarm {

class MainWindow;
class Workspace;

// The answer to "save the changes before X replaces them?".
enum class ReplaceDecision { Save, Discard, Cancel };

class SessionController : public QObject {
  Q_OBJECT
 public:
  SessionController(MainWindow* window, Workspace* workspace);
  ~SessionController() override;

  // The window's state as a session; log paths are stored relative to sessionPath when the
  // log lies beside it (absolute when sessionPath is empty). Needs an open log.
  Session capture(const QString& sessionPath) const;
  // Writes the session atomically; the previous file survives any failure.
  bool save(const QString& path, QString* why);
  // Reads a session, its logs and preprocessing in the background; emits sessionOpened or
  // openFailed (then the window is unchanged).
  void open(const QString& path);
  bool isBusy() const { return opener_.isRunning() || replayer_.isRunning() || writer_.isRunning(); }
  // Replays the current state in the background, with progress and Cancel, and writes the
  // report (.pdf or .html); emits reportExported, reportFailed or reportCancelled.
  void exportReport(const QString& path);
  // Stops the report being computed: nothing is written (what Cancel in its progress does).
  void cancelReport();

  QString sessionPath() const { return path_; }
  // The file of the session's log `name` (paths resolved against the session); empty when the
  // session has no such log. Parts restoring a session use it for the logs they name.
  QString sessionLogPath(const std::string& name) const;
  // Any change to the workspace since it was opened or saved: preprocessing, ranges, models,
  // designs. The window title shows it with "*".
  // Changes that go through the undo stack count until undone back to the saved state.
  bool isDirty() const;
  // Before something replaces the workspace (`what`: "opening chirp.csv", "closing the window"):
  // with unsaved changes asks Save / Discard / Cancel. True when the caller may go on (saved
  // or discarded), false to keep everything (Cancel, or saving failed or was cancelled).
  bool confirmReplace(const QString& what);
  // Who answers confirmReplace's question; unset: a modal QMessageBox ("replaceBox"). Tests
  // answer without a dialog.
  void setReplaceDecision(std::function<ReplaceDecision(const QString& what)> decide) {
    decide_ = std::move(decide);
  }
  // Opens a session after confirmReplace (the File menu's path).
  void requestOpen(const QString& path);
  // Estimates of the model list computed on other data than the open ones, each with the
  // sentence saying so ("computed on X; the open log is Y").
  QList<QPair<QString, QString>> staleEstimates() const;
  // Runs every stale estimate's fit again on the open data, one after another through the
  // Fit panel (off the GUI thread, progress and Cancel); each joins the list under a new name.
  void recomputeStale();
  QStringList recentSessions() const;
  QString autosavePath() const;
  // Writes the autosave file now when there is unsaved work; true when written.
  bool autosave();
  void setAutosaveInterval(int ms);
  // Whether a start that finds an autosave asks to recover it, and the window autosaves
  // (default). A window started to take a screenshot, or by a script, asks nothing and
  // leaves the autosave alone: it may be another running instance's, and a question would
  // hold the run up.
  void setOfferRecovery(bool offer) { offerRecovery_ = offer; }
  // The SHA-256 of the log about to be opened, formed where it was read (off the GUI thread);
  // without it the checksum is formed when the log changes.
  void setLogChecksum(const std::string& sha256) { pendingSha256_ = sha256; }

 signals:
  void sessionOpened(const QString& path);
  void openFailed(const QString& message);
  void sessionSaved(const QString& path);
  void reportExported(const QString& path);
  void reportFailed(const QString& message);
  void reportCancelled(const QString& path);
  // After a start that found an autosave: the recovery question is showing.
  void recoveryOffered(const QString& autosavePath);
  // After a log was opened with estimates of other data in the list: the offer is showing.
  void recomputeOffered(int stale);

 private:
  struct Opened {
    SessionParseResult parsed;
    PreparedSession prepared;
  };
  void addMenuActions();
  void saveAs();
  void saveCurrent();
  void openDialog();
  void exportDialog();
  void onOpened();
  void onReplayed();
  void onReportWritten(const QString& error);  // empty when the report was written
  void addRecent(const QString& path);
  void rebuildRecent();
  void offerRecovery();
  void markDirty();
  void setDirty(bool dirty);
  void offerRecompute();
  void recomputeNext();
  void fail(const QString& title, const QString& message);

  MainWindow* window_;
  Workspace* workspace_;
  QString path_;             // the session file, empty until saved or opened
  QString openingPath_, reportPath_;
  bool recovering_ = false;
  bool restoring_ = false;
  bool dirty_ = false;        // changes outside the undo stack (a panel's new result)
  bool offerRecovery_ = true;
  std::function<ReplaceDecision(const QString&)> decide_;
  QList<QString> recomputeQueue_;  // names of estimates still to recompute
  std::string logSha256_;    // of the log when it was opened
  std::string pendingSha256_;  // of the log being opened, from its reader
  Session loaded_;           // the last opened session (its extra logs and parts are kept)
  Session opened_;           // the session being restored (its parts read its logs)
  QMenu* recentMenu_ = nullptr;
  QTimer* autosaveTimer_;
  QProgressDialog* progress_ = nullptr;
  bool cancelled_ = false;
  QFutureWatcher<Opened> opener_;
  QFutureWatcher<ReplayResult> replayer_;
  QFutureWatcher<QString> writer_;  // HTML encoding and writing
  // The report's replay: its progress (per mille, from the worker) and its cancel flag.
  std::shared_ptr<std::atomic<int>> reportPermille_;
  std::shared_ptr<std::atomic<bool>> reportAbort_;
  QProgressDialog* reportProgress_ = nullptr;
  QTimer* reportPoll_ = nullptr;
};

}  // namespace flexarm
