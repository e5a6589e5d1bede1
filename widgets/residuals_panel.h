#pragma once
// Residuals panel: the correlation tests of a model from the shared list on the estimation
// or validation data, as SITB's resid: autocorrelation of the residuals and their
// cross-correlation with the input for lags up to M, each with its 99 % bounds, and the
// verdicts of the whiteness and independence tests. The residuals are computed off the GUI
// thread.
#include <QWidget>

#include "core/ident/residuals.h"
#include "widgets/workspace.h"

class QComboBox;
class QCustomPlot;
class QLabel;
class QSpinBox;

namespace flexarm {

class BackgroundRefresh;

class ResidualsPanel : public QWidget {
  Q_OBJECT
 public:
  explicit ResidualsPanel(Workspace* workspace, QWidget* parent = nullptr);

  void selectModel(int index);
  void setRangeKind(RangeKind kind);
  void setMaxLag(int lags);
  // The analysis shown (empty lags when there is none).
  const ResidualAnalysis& analysis() const { return analysis_; }
  QString verdictText() const;
  QCustomPlot* autoPlot() const { return auto_; }
  QCustomPlot* crossPlot() const { return cross_; }
  // Computing in the background: analysis() and the plots still show the previous state.
  bool isBusy() const;

 public slots:
  void refresh();

 private:
  void refillList();

  Workspace* workspace_;
  QComboBox* model_;
  QComboBox* range_;
  QSpinBox* lags_;
  QCustomPlot* auto_;
  QCustomPlot* cross_;
  QLabel* verdict_;
  ResidualAnalysis analysis_;
  bool filling_ = false;
  BackgroundRefresh* worker_;
};

}  // namespace flexarm
