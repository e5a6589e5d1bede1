#pragma once
// LQG panel (chapter 8 of the seed): the two-mass arm of Table 8.1, or a model of the shared
// list reduced to that form, and the design weights Q1, Q2 (8.17), R1, R2 (8.16) on
// logarithmic sliders. Every move redesigns the regulator and redraws the Nyquist curve of
// F_y G with the -1 point (and the describing-function line -1/Y_f (8.30) when saturation is
// on), |S| (8.36) and |T|, the disturbance steps of Figure 8.3 and the regulator pole map; a
// badge says whether the regulator is stable and how many poles it has in the right half
// plane. A design can be pinned and stays overlaid in every plot, as the seed's
// stable/unstable pair.
#include <QFutureWatcher>
#include <QString>
#include <QWidget>
#include <complex>
#include <memory>
#include <vector>

#include "core/control/lqg_analysis.h"
#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QCPCurve;
class QCPGraph;
class QCustomPlot;
class QGridLayout;
class QLabel;
class QLineEdit;
class QPushButton;
class QSplitter;

namespace flexarm {

class LogSlider;
class PoleZeroPlot;

class LqgPanel : public QWidget {
  Q_OBJECT
 public:
  enum class Preset { CaseI, CaseII, AccelerationFeedback };

  explicit LqgPanel(Workspace* workspace, QWidget* parent = nullptr);
  ~LqgPanel() override;
  // Modest, so that docking the panel does not take width from the other panels; it grows
  // with its dock or window.
  QSize sizeHint() const override { return {560, 600}; }

  // The design variables as the controls show them.
  LqgOptions options() const;
  LqgAnalysisOptions analysisOptions() const;
  // Sets the weights and measurement of a seed design (the plant parameters stay).
  void applyPreset(Preset preset);
  // Shows a whole design (parameters, measurement, weights, saturation limit; 0: none) as a
  // session restores it; `source` says where the parameters came from. Redesigns once.
  void setDesign(const LqgOptions& design, double saturationLimit, const QString& source);
  // Where the parameters come from, in words ("Table 8.1 (seed)", "model: ...").
  QString sourceText() const;
  // The words of the first source, the seed's Table 8.1.
  QString tableSourceText() const;
  // Selects the plant source: 0 is Table 8.1, i > 0 the workspace's model i - 1.
  void selectSource(int index);
  // Keeps the current design overlaid in every plot; unpin removes it.
  void pin();
  void unpin();
  bool hasPinned() const { return pinned_ != nullptr; }

  // What the panel shows.
  const LqgAnalysis* current() const { return current_.get(); }
  const LqgAnalysis* pinned() const { return pinned_.get(); }
  QString badgeText() const;
  QString pinnedBadgeText() const;
  QString summaryText() const;
  QString reductionText() const;
  // Points of the current Nyquist curve as drawn (positive frequencies).
  std::vector<std::complex<double>> nyquistPoints() const;
  LogSlider* weight(const QString& name) const;  // "q1_1".."q1_5", "q2", "r1_1".., "r2_1", "r2_2"
  QCustomPlot* nyquistPlot() const { return nyquist_; }
  QCustomPlot* sensitivityPlot() const { return sensitivity_; }
  QCustomPlot* stepPlot() const { return steps_; }
  PoleZeroPlot* poleMap() const { return poles_; }
  // True from a background redesign's start until its result is drawn.
  bool isComputing() const { return inFlight_; }
  // Seconds the last update took: redesign plus plot data handed to the plots (the drawing
  // itself follows, once per event-loop pass).
  double lastUpdateSeconds() const { return lastCost_; }
  // Updates that took longer than this run off the GUI thread (default 12 ms); 0 sends every
  // update there.
  void setSynchronousBudget(double seconds) { budget_ = seconds; }
  // Zooms the Nyquist plot around -1, or shows the whole curve.
  void zoomNearMinusOne();
  void showWholeNyquist();

 signals:
  void analysed();  // the plots show a new design

 protected:
  // Keeps the controls at their natural width, but at most 40 % of the panel, until the user
  // moves the splitter; the plots stand in two columns when there is room for both, else in
  // one.
  void resizeEvent(QResizeEvent* e) override;
  void showEvent(QShowEvent* e) override;
  bool eventFilter(QObject* watched, QEvent* e) override;

 public:
  // Columns of the plot grid now (1 or 2), and whether the controls side is shown.
  int plotColumns() const { return plotColumns_; }
  bool controlsShown() const;
  void setControlsShown(bool shown);

 private:
  void buildControls(QWidget* box);
  void refreshSources();
  void fillParameters(const TwoMassLqgParameters& p);
  void onParameterEdited();
  void requestUpdate();
  void startBackground();
  void showAnalysis(std::shared_ptr<const LqgAnalysis> a);
  void showFailure(const QString& why);
  void redraw();
  void updateMeasurementControls();
  void arrangePlots(int columns);
  // Chooses controls beside or above the plots for the room there is, then the columns.
  void reflow();

  Workspace* workspace_;
  QComboBox* source_;
  QComboBox* reduction_;
  QLabel* reductionLabel_;
  std::vector<QLineEdit*> params_;
  QCheckBox* acceleration_;
  QCheckBox* saturation_;
  QLineEdit* saturationLimit_;
  std::vector<LogSlider*> weights_;
  QPushButton* pinButton_;
  QPushButton* unpinButton_;
  QLabel* badge_;
  QLabel* pinnedBadge_;
  QLabel* summary_;
  QCustomPlot* nyquist_;
  QCustomPlot* sensitivity_;
  QCustomPlot* steps_;
  PoleZeroPlot* poles_;
  QSplitter* split_ = nullptr;
  QWidget* controls_ = nullptr;
  QWidget* controlsSide_ = nullptr;  // the scroll area around controls_
  QPushButton* controlsButton_ = nullptr;
  QGridLayout* plotGrid_ = nullptr;
  int plotColumns_ = 0;
  bool filtering_ = false;
  bool splitterMoved_ = false;
  TwoMassLqgParameters parameters_;

  std::shared_ptr<const LqgAnalysis> current_, pinned_;
  QString pinnedLabel_;
  QFutureWatcher<std::shared_ptr<const LqgAnalysis>> watcher_;
  bool pending_ = false;
  bool inFlight_ = false;
  double lastCost_ = 0.0;  // s, redesign plus drawing of the last update
  double budget_;
  bool quiet_ = false;     // set while the controls are filled programmatically
};

const char* toString(LqgPanel::Preset p);

}  // namespace flexarm
