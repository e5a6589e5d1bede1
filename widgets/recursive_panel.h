#pragma once
// Recursive panel (the seed's chapter 6): the physical parameters estimated sample by sample,
// animated as the log plays. The engineer picks the nominal model (an entry of the model list,
// e.g. a fit, or a structure's defaults), the parameters to track, the algorithm and its design
// variables and the start offset, and presses Play: the window's playhead plays the log and the
// estimator (on a thread of its own, RecursiveRunner) computes up to the playhead's time; each
// parameter's estimate draws with its +-3 sigma band and the nominal value as a line, the
// prediction error below and P's diagonal on a log axis. Scrubbing back shows the estimates up
// to that time; "Run again" restarts with changed settings, the previous run overlaid dashed.
// The runs are what a session stores (part "recursive").
#include <QElapsedTimer>
#include <QPointer>
#include <QWidget>
#include <memory>
#include <optional>
#include <vector>

#include "core/session/recursive_part.h"
#include "widgets/recursive_runner.h"
#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QCPAxisRect;
class QCPGraph;
class QCustomPlot;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QProgressBar;
class QPushButton;
class QSpinBox;

namespace flexarm {

class Playhead;
class PlayheadCursor;

class RecursivePanel : public QWidget {
  Q_OBJECT
 public:
  explicit RecursivePanel(Workspace* workspace, QWidget* parent = nullptr);
  ~RecursivePanel() override;

  void setPlayhead(Playhead* playhead);

  // The request the controls describe now.
  RecursiveRequest request() const;
  // Sets the controls from a request (a session's); runs nothing.
  void setRequest(const RecursiveRequest& request);
  // Says what a session stored of the last run (its end and final estimates) under the
  // controls, until a run of the panel's own replaces it.
  void showStored(const QString& summary);

  // One run: what was asked and what it computed so far (every row, also past the playhead).
  struct Run {
    int id = 0;
    RecursiveRequest request;
    std::vector<RecursiveParameter> parameters;
    RecursiveTrajectory rows;
    double reached = 0.0, start = 0.0, end = 0.0, sampleTime = 0.0;
    bool finished = false;
    std::shared_ptr<const RecursiveResult> result;
    QString failure;
  };
  const Run* currentRun() const { return current_ ? &*current_ : nullptr; }
  const Run* previousRun() const { return previous_ ? &*previous_ : nullptr; }
  // The runs a session stores: the previous one (if overlaid) and the current one.
  std::vector<const Run*> runs() const;
  // Forgets every run (a session without the part, a new log).
  void clearRuns();

  // Rows of the current run drawn now (those at or before the playhead's time).
  std::size_t shownRows() const { return shown_; }
  // Plot frames drawn per second while playing, over the last second.
  double framesPerSecond() const { return fps_; }
  QString statusText() const;

  QComboBox* modelBox() const { return model_; }
  QComboBox* algorithmBox() const { return algorithm_; }
  QComboBox* trackingBox() const { return tracking_; }
  QDoubleSpinBox* lambdaBox() const { return lambda_; }
  QLineEdit* r1Edit() const { return r1_; }
  QDoubleSpinBox* startBox() const { return startOffset_; }
  QListWidget* parameterList() const { return parameters_; }
  QCheckBox* overlayBox() const { return overlay_; }
  QPushButton* playButton() const { return play_; }
  QPushButton* runAgainButton() const { return again_; }
  QPushButton* cancelButton() const { return cancel_; }
  QProgressBar* progressBar() const { return progress_; }
  QCustomPlot* plot() const { return plot_; }

 public slots:
  // Starts a run with the controls' settings if none is ready, and plays the log from where
  // the playhead is (from the start when the run is new).
  void play();
  // Starts a new run with the controls' settings from the log's start and plays it; the
  // current run becomes the dashed overlay when "overlay" is on.
  void runAgain();
  // Stops the estimator where it is (the run keeps what it computed, termination cancelled)
  // and pauses the playhead.
  void cancel();

 signals:
  void runFinished();  // the current run processed every sample, or stopped

 private:
  void refillModels();
  void refillParameters();
  std::shared_ptr<const PhysicalModel> chosenModel() const;
  void startRun();
  void onChunk(RecursiveRunner::Chunk chunk);
  void onTime(double t);
  void buildPlot();
  // Draws the current run's rows up to time t (adds or removes points), the overlay whole.
  void showUpTo(double t);
  void showChanges(double t);
  void drawOverlay();
  void updateHold();
  void frameDrawn();
  void showProgress();
  void buildLegend();

  Workspace* workspace_;
  QPointer<Playhead> playhead_;  // the window owns it (and may delete it first)
  QComboBox* model_;
  QComboBox* algorithm_;
  QComboBox* gradient_;
  QDoubleSpinBox* lambda_;
  QLineEdit* r1_;
  QDoubleSpinBox* r2_;
  QDoubleSpinBox* mu_;
  QDoubleSpinBox* startOffset_;
  QSpinBox* decimation_;
  QComboBox* tracking_;
  // What a session's request said beyond the controls (the highest rate of the default
  // decimation, what lambda and R1 are given per): kept for the next run.
  double maxRateHz_ = 2000.0, designSampleTime_ = 0.005;
  // The change times of the bank drawn so far (vertical lines in every estimate's rect).
  std::size_t changesShown_ = 0;
  QCheckBox* inverse_;
  QListWidget* parameters_;
  QCheckBox* overlay_;
  QPushButton* play_;
  QPushButton* again_;
  QPushButton* cancel_;
  QProgressBar* progress_;
  QLabel* status_;
  QCustomPlot* plot_;
  PlayheadCursor* cursor_;

  RecursiveRunner runner_;
  int nextRun_ = 0;
  std::optional<Run> current_, previous_;
  // Graphs per parameter of the current run: estimate, lower and upper band; the overlay's
  // estimates; the prediction error; P's diagonal.
  struct ParameterGraphs {
    QCPAxisRect* rect = nullptr;
    QCPGraph *estimate = nullptr, *lower = nullptr, *upper = nullptr, *previous = nullptr;
    QCPGraph* p = nullptr;
    double lo = 0.0, hi = 0.0;  // value range shown
  };
  std::vector<ParameterGraphs> graphs_;
  QCPGraph* epsilon_ = nullptr;
  QCPAxisRect* epsilonRect_ = nullptr;
  QCPAxisRect* pRect_ = nullptr;
  std::size_t shown_ = 0;
  bool holding_ = false;
  QElapsedTimer fpsClock_;
  int fpsFrames_ = 0;
  double fps_ = 0.0;
};

}  // namespace flexarm
