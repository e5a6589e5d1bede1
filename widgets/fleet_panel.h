#pragma once
// Fleet panel: the plant at a glance from a fleet store (core/fleet): a sortable grid of every
// robot's axes with the status of each monitored parameter in colour (green: steady, orange:
// drifting, red: stepped), and for the axis chosen the trend of a parameter over days - the
// logs' estimates with +-2 std bands, the fitted level, the log's temperature on the right
// axis, the threshold and the predicted crossing - with the evidence in words. A click on a
// day's estimate asks the window to open that day's log with its diagnosis against the axis'
// reference (logRequested). "Run manifest..." runs a manifest into the store off the GUI
// thread (core/fleet/engine.h's runFleet, as `flexarm fleet` does) with progress and Cancel.
#include <QFutureWatcher>
#include <QWidget>
#include <atomic>
#include <memory>
#include <vector>

#include "core/fleet/engine.h"

class QComboBox;
class QCustomPlot;
class QLabel;
class QProgressBar;
class QPushButton;
class QTableWidget;

namespace flexarm {

class FleetPanel : public QWidget {
  Q_OBJECT
 public:
  explicit FleetPanel(QWidget* parent = nullptr);
  ~FleetPanel() override;

  // Reads the store's axes and trends (read only); false with a sentence shown in the panel.
  bool openStore(const QString& path);
  // Runs a manifest into the store (the open one, or path) in the background.
  void runManifest(const QString& manifest, const QString& store);
  void cancel();
  bool isBusy() const { return watcher_.isRunning(); }

  QTableWidget* grid() const { return grid_; }
  QCustomPlot* trendPlot() const { return plot_; }
  QComboBox* parameterBox() const { return parameter_; }
  QString evidenceText() const;
  const std::vector<FleetAxisReport>& axes() const { return axes_; }
  // The axis shown in the trend plot (index into axes()), -1 when none.
  int currentAxis() const { return current_; }
  void showAxis(int index, const QString& parameter = {});
  // Emits logRequested for the day's log nearest to plot position x (days on the plot's axis).
  bool requestLogAt(double x);

 signals:
  // Open `log` and diagnose it against `reference` with `model` (a structure's nominal name).
  void logRequested(const QString& log, const QString& reference, const QString& model);
  void storeOpened();
  void runFinished(bool ok, const QString& message);

 protected:
  void showEvent(QShowEvent* event) override;

 private:
  void fillGrid();
  void plotTrend();
  void onRunFinished();

  QString storePath_;
  std::string model_ = "three-mass";
  std::vector<FleetAxisReport> axes_;
  int current_ = -1;
  double firstDay_ = 0.0;
  QLabel* storeLabel_ = nullptr;
  QLabel* summary_ = nullptr;
  QPushButton* open_ = nullptr;
  QPushButton* run_ = nullptr;
  QPushButton* cancel_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QTableWidget* grid_ = nullptr;
  QComboBox* parameter_ = nullptr;
  QCustomPlot* plot_ = nullptr;
  QLabel* evidence_ = nullptr;
  QFutureWatcher<FleetRunResult> watcher_;
  std::shared_ptr<std::atomic<bool>> cancelFlag_;
  std::shared_ptr<std::atomic<double>> progressValue_;
};

}  // namespace flexarm
