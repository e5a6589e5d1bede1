#pragma once
// Compare panel: the measured output against the output simulated by several models of the
// shared list on the validation range (or the estimation range), each with its fit % (5.2),
// as the seed's Figure 5.11; on a log with an arm-side encoder, below it the measured deflection
// r phi_m - phi_a against each physical model's. Simulation starts at the log's first sample, so no start-up
// transient enters the fit. Simulating runs off the GUI thread; the curves are drawn through
// their min/max envelope for the visible time range.
#include <QWidget>
#include <vector>

#include "widgets/workspace.h"

class QComboBox;
class QCustomPlot;
class QLabel;
class QListWidget;
class QSpinBox;

namespace flexarm {

class Playhead;
class BackgroundRefresh;
struct CompareOutcome;  // what simulating the models gave (compare_panel.cpp)
class PlayheadCursor;

class ComparePanel : public QWidget {
  Q_OBJECT
 public:
  explicit ComparePanel(Workspace* workspace, QWidget* parent = nullptr);

  void setModelShown(int index, bool shown);
  void setRangeKind(RangeKind kind);
  // 0: the models' simulations (the default); k >= 1: their k-step predictions y(t | t - k),
  // as MATLAB's compare(data, model, k) (a black-box model's noise model predicts).
  void setHorizon(int samples);
  // Fit % of each checked model in list order (NaN where it could not be simulated).
  // Each checked model's fit % on the range shown: the seed's (5.2) and the NRMSE fit.
  std::vector<double> fits() const { return fits_; }
  std::vector<double> fitsNrmse() const { return fitsNrmse_; }
  QString fitText() const;
  QCustomPlot* plot() const { return plot_; }
  // The measured deflection r phi_m - phi_a and each physical model's, below the output; shown
  // only on a log with an arm-side encoder (arm_angle_rad). Its curves: one per model, then
  // the measured one.
  QCustomPlot* deflectionPlot() const { return deflection_; }
  int deflectionCurves() const { return deflectionCurves_; }
  // Shows the window's playhead in the plot; a click there moves it.
  void setPlayhead(Playhead* playhead);
  PlayheadCursor* playheadCursor() const { return cursor_; }
  // Simulating in the background: fits() and the plot still show the previous state.
  bool isBusy() const;

 public slots:
  void refresh();

 private:
  void refillList();
  void showOutcome(const CompareOutcome& out);

  Workspace* workspace_;
  QListWidget* models_;
  QComboBox* range_;
  QSpinBox* horizon_;
  QCustomPlot* plot_;
  QLabel* fit_;
  PlayheadCursor* cursor_;
  QCustomPlot* deflection_;
  int deflectionCurves_ = 0;
  std::vector<double> fits_, fitsNrmse_;
  BackgroundRefresh* worker_;
};

}  // namespace flexarm
