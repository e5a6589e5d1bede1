#pragma once
// The main window: the Log panel in the centre, dockable Preprocess and Arm panels, menus
// with shortcuts, recent files, drag-and-drop to open, settings kept between runs and
// status bar messages. Logs are read off the GUI thread. It owns the one playhead (the
// current time every panel follows) and its transport bar at the bottom; keys no focused
// widget takes (Space, arrows) drive the playhead.
#include <QFutureWatcher>
#include <QMainWindow>
#include <QStringList>

#include "core/io/log_io.h"

class QDockWidget;
class QMenu;
class QProgressDialog;

namespace flexarm {

class ArmPanel;
class BodePanel;
class ComparePanel;
class FitPanel;
class DiscoveryPanel;
class LogPanel;
class LqgPanel;
class ModelPanel;
class Playhead;
class PreprocessPanel;
class RecursivePanel;
class TransportBar;
class ResidualsPanel;
class DiagnosisPanel;
class PanelDocks;
class SessionController;
class Workspace;
class LogImporter;

class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  // Reads a log in the background; a headerless table, a CSV file with other column names and
  // a .mat file whose signals are not named the FlexArm way go through the import dialog
  // (app/log_importer.h) unless options are given. Emits logOpened or openFailed.
  void openFile(const QString& path);
  void openFile(const QString& path, const LogReadOptions& options);
  // File -> Import log: the import dialog for path whatever it holds (after confirmReplace).
  void importFile(const QString& path);
  bool isOpening() const { return reader_.isRunning(); }
  // Opens a log as File -> Open, a recent file or a drop does: with unsaved changes it first
  // asks Save / Discard / Cancel (SessionController::confirmReplace); Cancel keeps everything.
  void requestOpenFile(const QString& path);
  // Reading a log, a session or a report, or a panel still computing in the background.
  bool isBusy() const;

  Workspace* workspace() const { return workspace_; }
  LogPanel* logPanel() const { return logPanel_; }
  PreprocessPanel* preprocessPanel() const { return preprocessPanel_; }
  ArmPanel* armPanel() const { return armPanel_; }
  ModelPanel* modelPanel() const { return modelPanel_; }
  FitPanel* fitPanel() const { return fitPanel_; }
  BodePanel* bodePanel() const { return bodePanel_; }
  ComparePanel* comparePanel() const { return comparePanel_; }
  ResidualsPanel* residualsPanel() const { return residualsPanel_; }
  LqgPanel* lqgPanel() const { return lqgPanel_; }
  SessionController* sessionController() const { return session_; }
  DiscoveryPanel* discoveryPanel() const { return discoveryPanel_; }
  DiagnosisPanel* diagnosisPanel() const { return diagnosisPanel_; }
  RecursivePanel* recursivePanel() const { return recursivePanel_; }
  QDockWidget* recursiveDock() const { return recursiveDock_; }
  // Every panel's dock, its View menu entry, the switcher and the layout for the screen.
  PanelDocks* docks() const { return docks_; }
  QStringList recentFiles() const;
  Playhead* playhead() const { return playhead_; }
  TransportBar* transportBar() const { return transportBar_; }

 signals:
  void logOpened(const QString& path);
  void openFailed(const QString& message);

 protected:
  void closeEvent(QCloseEvent* e) override;
  void dragEnterEvent(QDragEnterEvent* e) override;
  void dropEvent(QDropEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;

 private:
  void createMenus();
  // Registers a panel with its dock, View menu entry, shortcut and switcher line
  // (PanelDocks::add); where it goes is the screen's layout's choice (tabWith is not used).
  QDockWidget* addPanel(QWidget* panel, const QString& title, const char* objectName,
                        const QString& shortcut, QDockWidget* tabWith);
  // Tabs of tabified docks show whole titles and scroll when there are many.
  void showWholeTabTitles();
  void openDialog();
  void exportData();
  void addRecent(const QString& path);
  void rebuildRecentMenu();
  void onReadFinished();
  void showError(const QString& title, const QString& message);
  // The log was refused for its time stamps alone: asks whether to open it for resampling.
  void offerResampling(const QString& problem);

  Workspace* workspace_;
  Playhead* playhead_;
  LogPanel* logPanel_;
  TransportBar* transportBar_ = nullptr;
  PreprocessPanel* preprocessPanel_ = nullptr;
  ArmPanel* armPanel_ = nullptr;
  ModelPanel* modelPanel_ = nullptr;
  DiscoveryPanel* discoveryPanel_ = nullptr;
  QDockWidget* preprocessDock_ = nullptr;
  QDockWidget* armDock_ = nullptr;
  QDockWidget* modelDock_ = nullptr;
  FitPanel* fitPanel_ = nullptr;
  BodePanel* bodePanel_ = nullptr;
  ComparePanel* comparePanel_ = nullptr;
  ResidualsPanel* residualsPanel_ = nullptr;
  QDockWidget* fitDock_ = nullptr;
  QDockWidget* bodeDock_ = nullptr;
  QDockWidget* compareDock_ = nullptr;
  QDockWidget* residualsDock_ = nullptr;
  LqgPanel* lqgPanel_ = nullptr;
  QDockWidget* lqgDock_ = nullptr;
  SessionController* session_ = nullptr;
  LogImporter* importer_ = nullptr;
  QDockWidget* discoveryDock_ = nullptr;
  DiagnosisPanel* diagnosisPanel_ = nullptr;
  QDockWidget* diagnosisDock_ = nullptr;
  RecursivePanel* recursivePanel_ = nullptr;
  QDockWidget* recursiveDock_ = nullptr;
  QMenu* recentMenu_ = nullptr;
  QMenu* viewMenu_ = nullptr;
  PanelDocks* docks_ = nullptr;
  // A log read in the background with its file's SHA-256 (empty when it could not be formed).
  struct ReadLog {
    LogReadResult result;
    std::string sha256;
  };
  QFutureWatcher<ReadLog> reader_;
  QProgressDialog* progress_ = nullptr;
  QString readingPath_;
  LogReadOptions readingOptions_;
  bool readCancelled_ = false;
  qint64 readStartMs_ = 0;
};

}  // namespace flexarm
