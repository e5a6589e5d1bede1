#pragma once
// Discovery panel: finds the effects the chosen base model misses (core/discovery). "Find
// missing effect" runs one search, "Find all" the loop (find, add, refit everything, find
// again until none), off the GUI thread with progress and Cancel (a cancelled loop keeps the
// steps it finished). The panel shows the ladder of the gap shrinking step by step (held-out
// residual RMS and fit % of the base and after each effect), and for the chosen step its
// candidates table, verdict, evidence and confirmation, the residual in time and frequency
// (with the model's resonances) and the measured, before and after simulations overlaid;
// "Add to model" puts the final model (every effect found) in the model list (undoable).
#include <QFutureWatcher>
#include <QWidget>
#include <atomic>
#include <memory>

#include "core/discovery/discovery.h"
#include "core/session/discovery_part.h"
#include "widgets/workspace.h"

class QComboBox;
class QCustomPlot;
class QLabel;
class QProgressBar;
class QPushButton;
class QTableWidget;

namespace flexarm {

class Playhead;
class PlayheadCursor;

class DiscoveryPanel : public QWidget {
  Q_OBJECT
 public:
  explicit DiscoveryPanel(Workspace* workspace, QWidget* parent = nullptr);
  ~DiscoveryPanel() override;

  bool isBusy() const { return watcher_.isRunning(); }
  bool hasResult() const { return result_ != nullptr; }
  const DiscoveryResult* result() const { return result_.get(); }
  // Base models offered: the model list's entries with a gear spring, then nominal structures.
  QComboBox* baseModelBox() const { return base_; }
  QPushButton* findButton() const { return find_; }
  QPushButton* findAllButton() const { return findAll_; }
  QCustomPlot* ladderPlot() const { return ladder_; }
  // The steps of the shown result (the base's round, then one per effect found); choosing one
  // shows its candidates, evidence and overlay.
  QComboBox* stepBox() const { return step_; }
  void selectStep(int step);
  QPushButton* addButton() const { return add_; }
  QTableWidget* candidatesTable() const { return table_; }
  QString verdictText() const;
  QString evidenceText() const;
  QString comparisonText() const;
  QString stageText() const;
  QCustomPlot* residualTimePlot() const { return residualTime_; }
  QCustomPlot* residualSpectrumPlot() const { return residualSpectrum_; }
  QCustomPlot* overlayPlot() const { return overlay_; }
  // Shows the window's playhead in the plots over time; a click there moves it.
  void setPlayhead(Playhead* playhead);
  DiscoveryOptions& options() { return options_; }
  // What the shown result was asked (base, data ranges, options); null before the first
  // result.
  const DiscoveryRequest* lastRequest() const { return request_ ? &*request_ : nullptr; }
  // Shows a stored result (a session's summary: verdict, evidence, candidates and scores,
  // no traces) without running anything; a run in progress is cancelled and its result
  // dropped. "Find missing effect" recomputes it with the plots.
  void showStored(const DiscoveryRequest& request, const DiscoveryResult& summary);
  // Forgets the result (and drops a run in progress): the panel as before its first run.
  void clearResult();

 public slots:
  void findMissingEffect();
  void findAllEffects();
  void cancel();
  // Adds the augmented model to the model list (undoable) and shows the gap shrink.
  void addToModel();

 signals:
  void finished();  // a run ended (result, failure or cancel)
  void modelAdded(int index);

 private:
  struct Outcome {
    std::shared_ptr<DiscoveryResult> result;
    QString error;
    int run = 0;  // the run it answers
  };
  void refillModels();
  void run(int maxEffects);
  void onFinished();
  void showResult();
  void showLadder();
  void showStep();
  void showOverlay();
  void showComparison();  // fit % and residual RMS before (and after adding) in words
  void clearPlots();
  std::unique_ptr<PhysicalModel> chosenBase(std::vector<Effect>* effects) const;

  Workspace* workspace_;
  QComboBox* base_;
  QPushButton* find_;
  QPushButton* findAll_;
  QPushButton* cancel_;
  QPushButton* add_;
  QProgressBar* progress_;
  QLabel* stage_;
  QLabel* verdict_;
  QLabel* evidence_;
  QLabel* where_;
  QLabel* comparison_;
  QTableWidget* table_;
  QComboBox* step_;
  QCustomPlot* ladder_;
  QCustomPlot* residualTime_;
  QCustomPlot* residualSpectrum_;
  QCustomPlot* overlay_;
  PlayheadCursor* residualCursor_;
  PlayheadCursor* overlayCursor_;
  QFutureWatcher<Outcome> watcher_;
  std::shared_ptr<std::atomic<bool>> cancelFlag_;
  std::shared_ptr<DiscoveryResult> result_;
  DiscoveryOptions options_;
  std::optional<DiscoveryRequest> request_, pendingRequest_;
  Provenance pendingData_;  // the data of the run in flight, recorded with its result
  int run_ = 0;  // increases with every run started and every stored result shown
  QString baseName_;
  bool added_ = false;
};

}  // namespace flexarm
