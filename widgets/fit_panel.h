#pragma once
// Fit panel: a black-box structure with its orders (4.8) or a physical model (from the shared
// model list or a fresh structure) with its free parameters and the named effects switched on
// for it (nonlinear grey-box estimation; a list model brings its own, e.g. discovery's
// augmented model), their parameters free or fixed; the workspace's estimation and
// validation ranges; options (decimation, noise model, starts, iterations). Estimate runs the
// prediction-error fit off the GUI thread with progress and Cancel and shows the results as
// the seed's Tables 5.1 and 5.3-5.7: value +- std and the 99 % interval of every parameter,
// loss, FPE, fit % (5.2) on the estimation and validation data, notch and peak frequencies.
// The estimate joins the shared model list. The sensitivity study of Section 5.3.3 (domain
// of attraction, Table 5.8, then Monte-Carlo starts) runs on the latest physical estimate.
#include <QFutureWatcher>
#include <QWidget>
#include <atomic>
#include <memory>

#include "core/ident/fit.h"
#include "core/ident/fit_experiments.h"
#include "core/ident/sensitivity.h"
#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QLabel;
class QListWidget;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QLineEdit;
class QTableWidget;
class QTimer;

namespace flexarm {

class FitPanel : public QWidget {
  Q_OBJECT
 public:
  explicit FitPanel(Workspace* workspace, QWidget* parent = nullptr);

  // The model to fit: "arx", "armax", "oe", "bj", a physical structure name ("three-mass")
  // or "list:N" for entry N of the shared model list. False when there is no such choice.
  bool setModelChoice(const QString& key);
  QString modelChoice() const;
  void setOrders(const PolyOrders& orders);
  // Physical models: the named effects (coulomb_friction, nonlinear_spring, backlash,
  // input_delay, torque_ripple) switched on for the fit; their parameters join the free
  // parameter list as "NAME (effect)", the first of each checked. A model from the list starts
  // with its own effects and their values.
  void setEffects(const QStringList& names);
  QStringList effects() const;
  // Physical models: exactly these parameters are estimated (effect parameters as listed,
  // e.g. "beta (nonlinear_spring)").
  void setFreeParameters(const QStringList& names);
  QStringList freeParameters() const;
  void setDecimation(int factor);
  void setNoiseModel(NoiseModel m);
  // Output-error fits of closed-loop logs (with a reference channel): auto, two-stage, direct
  // or indirect.
  void setClosedLoopMethod(ClosedLoopChoice m);
  void setStarts(int randomStarts);
  // More experiments besides the workspace's ranges: "FILE@A:B, FILE2, val: FILE3@A:B"
  // (fit_experiments.h), read inside the background fit; each one's fit % is listed.
  void setMoreExperiments(const QString& text);
  QString moreExperiments() const;

  bool isBusy() const { return watcher_.isRunning() || study_.isRunning(); }
  QTableWidget* resultsTable() const { return table_; }
  QString summaryText() const;
  // Index in the shared model list of the latest estimate (-1 before the first).
  int lastModelIndex() const { return lastIndex_; }
  // Shows a stored fit as a session keeps it (the request's choices in the controls, its
  // parameter table and numbers in the results) without estimating; modelIndex is its
  // estimate in the model list. Its data become the panel's result record ("fit").
  void showStored(const FitRequest& request, int modelIndex);
  // Shows no result (a session without fits).
  void clearResult();
  QTableWidget* studyTable() const { return studyTable_; }
  QString studyText() const;
  void setStudyRuns(int runs);

 protected:
  // Keeps the summary as tall as its wrapped text at the width it has.
  bool eventFilter(QObject* watched, QEvent* event) override;

 public slots:
  void estimate();
  // Runs a stored fit again (its model, start values, free parameters and options) on the
  // open data with the workspace's ranges, off the GUI thread with progress and Cancel; the
  // estimate joins the list under a new name, the stored one stays as it was. False when
  // busy or the request cannot run on these data (the summary says why).
  bool recompute(const FitRequest& request);
  void runStudy();
  void cancel();

 signals:
  void estimated(bool ok);
  void studyFinished(bool ok);

 private:
  struct Outcome {
    QString error, name;
    FitResult result;
    std::shared_ptr<FitRequest> request;  // what was asked, kept with the estimate
  };
  // What the sensitivity study works on: the latest physical estimate and its estimation data.
  struct StudyInput {
    std::shared_ptr<const ParametricModel> estimate;
    Eigen::VectorXd u, y;
    double sampleTime = 0;
  };
  struct StudyOutcome {
    AttractionResult attraction;
    MonteCarloResult monteCarlo;
    QString error;
  };
  std::optional<FitOptions> options(QString* name, std::vector<ExperimentSource>* more);
  void refillModels();
  void refillParameters();
  void refillEffectParameters();
  std::vector<FitEffect> chosenEffects() const;
  // The start model's own effects (a list entry's), else none.
  std::vector<Effect> startEffects() const;
  void updateControls();
  // The order spin boxes by the order of (4.8) they set.
  std::vector<std::pair<PolyOrder, QSpinBox*>> orderSpins() const;
  void onFinished();
  void onStudyFinished();
  void fillTable(const std::vector<FitParameter>& parameters);
  void setSummary(const QString& text);
  void fitSummaryHeight();
  // Sets the controls to what a request asked.
  void setChoices(const FitRequest& request);
  // The result shown was of other data than the open ones (Workspace::resultWithdrawn).
  void withdraw();
  void showRanges();
  // Runs the fit pipeline on options in the background; name is the model's base name.
  // The more experiments are read there, off the GUI thread.
  void start(const FitOptions& options, const QString& name, const std::vector<ExperimentSource>& more);
  void chooseExperimentFiles();
  void startProgress();
  ProgressCallback progressCallback() const;

  Workspace* workspace_;
  QComboBox* model_;
  QSpinBox* na_;
  QSpinBox* nb_;
  QSpinBox* nc_;
  QSpinBox* nd_;
  QSpinBox* nf_;
  QSpinBox* nk_;
  QListWidget* free_;
  QLineEdit* startsBounds_;  // start values P=V and bounds P=LO:HI (FitOptions)
  QLineEdit* more_;          // more experiments (fit_experiments.h)
  QPushButton* moreBrowse_;
  QWidget* effectsBox_;
  std::vector<std::pair<EffectKind, QCheckBox*>> effectChecks_;
  QLabel* ranges_;
  QSpinBox* decimation_;
  QComboBox* noise_;
  QComboBox* closedLoop_;
  QSpinBox* starts_;
  QSpinBox* iterations_;
  QPushButton* estimate_;
  QPushButton* cancel_;
  QProgressBar* progress_;
  QTableWidget* table_;
  QLabel* summary_;
  QSpinBox* studyRuns_;
  QPushButton* study_button_;
  QTableWidget* studyTable_;
  QLabel* studySummary_;
  QTimer* poll_;
  QFutureWatcher<Outcome> watcher_;
  QFutureWatcher<StudyOutcome> study_;
  std::shared_ptr<std::atomic<int>> permille_;
  std::shared_ptr<std::atomic<bool>> abort_;
  StudyInput last_;  // the latest physical estimate (for the study)
  int lastIndex_ = -1;
  QString lastName_;  // of the estimate shown
};

}  // namespace flexarm
