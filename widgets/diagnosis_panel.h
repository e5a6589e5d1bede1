#pragma once
// Diagnosis panel (the seed's chapter 7): detects and isolates a fault in k_T, J_a or f_m of
// the open log against a fault-free reference (a log chosen here, or a model of the list).
// "Diagnose" runs runDiagnosisRequest (core/diagnosis/diagnosis_request.h) off the GUI thread
// with progress and Cancel - with a Monte-Carlo calibration of the thresholds first when
// asked. The result is then shown as the window's playhead plays through the log: each
// parameter's recursive estimate against theta_0 with the robust test's threshold band, the
// CUSUM statistics against h, the hypothesis statistics against their level, an alarm
// timeline per test, and the decision table of Section 7.5.2 lighting up with the pattern of
// the moment, the diagnosis statement S, and the verdict with its time once the playhead has
// passed it. A healthy log stays green.
#include <QFutureWatcher>
#include <QWidget>
#include <atomic>
#include <memory>
#include <optional>

#include "core/diagnosis/diagnosis_request.h"
#include "core/session/diagnosis_part.h"
#include "widgets/workspace.h"

class QCPGraph;
class QCheckBox;
class QComboBox;
class QCustomPlot;
class QLabel;
class QProgressBar;
class QPushButton;
class QTableWidget;

namespace flexarm {

class Playhead;
class PlayheadCursor;

class DiagnosisPanel : public QWidget {
  Q_OBJECT
 public:
  explicit DiagnosisPanel(Workspace* workspace, QWidget* parent = nullptr);
  ~DiagnosisPanel() override;

  void setPlayhead(Playhead* playhead);
  // The fault-free log theta_0 is fitted on (read when the diagnosis runs); empty: a model.
  void setReferenceLog(const QString& path);
  QString referenceLogPath() const { return referencePath_; }
  // The reference choices: "Fault-free log", the model list's physical models, nominal
  // structures.
  QComboBox* referenceBox() const { return reference_; }
  QPushButton* runButton() const { return run_; }
  QCheckBox* calibrateBox() const { return calibrate_; }
  QComboBox* windowBox() const { return window_; }
  QTableWidget* decisionTable() const { return table_; }
  QCustomPlot* estimatesPlot() const { return estimates_; }
  QCustomPlot* cusumPlot() const { return cusum_; }
  QCustomPlot* hypothesisPlot() const { return hypothesis_; }
  QCustomPlot* timelinePlot() const { return timeline_; }
  QString verdictText() const;
  QString statementText() const;

  bool isBusy() const { return watcher_.isRunning(); }
  const DiagnosisRun* lastRun() const { return shownRun_ ? shownRun_.get() : nullptr; }
  // What the shown result was asked, as a session stores it (null before the first run).
  std::optional<DiagnosisSessionRequest> sessionRequest(const std::string& referenceLogName) const;
  // Takes over a session's request (reference, options, the calibration's summary) without
  // running, with the summary of its stored result (diagnosisResultJson) when the session
  // has one: its verdict is shown and saved again until "Diagnose" runs it anew.
  void setRequest(const DiagnosisSessionRequest& request, const QString& referencePath,
                  const nlohmann::json& storedResult = nullptr);
  // The stored result taken over with the request; null once the panel ran or cleared.
  const nlohmann::json& storedResult() const { return storedResult_; }
  void clearResult();

 public slots:
  void diagnose();
  void cancel();

 signals:
  void finished();  // a run ended (result, failure or cancel)
  // The verdict shown at the playhead changed: the faulty parameter's model name, or empty.
  void verdictShown(const QString& parameter);

 private:
  // A curve kept whole, shown up to the playhead.
  struct Shown {
    QCPGraph* graph;
    std::vector<double> y;
  };
  struct Outcome {
    std::shared_ptr<DiagnosisRun> run;
    QString error;
    int id = 0;
  };
  void refillReferences();
  void onFinished();
  void buildPlots();
  void showAt(double t);
  void setBusy(bool busy);
  DiagnosisOptions chosenOptions() const;

  Workspace* workspace_;
  QComboBox* reference_;
  QPushButton* chooseLog_;
  QLabel* referenceName_;
  QCheckBox* tests_[5];
  QComboBox* window_;
  QCheckBox* calibrate_;
  QPushButton* run_;
  QPushButton* cancel_;
  QProgressBar* progress_;
  QLabel* stage_;
  QLabel* verdict_;
  QLabel* statement_;
  QLabel* thresholds_;
  QCustomPlot* estimates_;
  QCustomPlot* cusum_;
  QCustomPlot* hypothesis_;
  QCustomPlot* timeline_;
  QTableWidget* table_;
  std::vector<PlayheadCursor*> cursors_;
  Playhead* playhead_ = nullptr;

  QString referencePath_;
  nlohmann::json storedCalibration_;
  std::optional<DiagnosisOptions> storedOptions_;
  std::optional<std::pair<std::string, double>> seedFault_;
  QFutureWatcher<Outcome> watcher_;
  std::shared_ptr<std::atomic<bool>> cancelFlag_;
  std::shared_ptr<std::atomic<double>> progressValue_;
  int runId_ = 0;
  std::shared_ptr<DiagnosisRun> shownRun_;
  std::optional<DiagnosisSessionRequest> request_;
  std::vector<Shown> shown_;
  std::size_t shownSample_ = static_cast<std::size_t>(-1);
  QString shownVerdict_;
  Provenance runData_;  // the data of the run in flight, recorded with its result
  nlohmann::json storedResult_;
};

}  // namespace flexarm
