#pragma once
// Bode panel: any models of the shared list overlaid on one Bode plot, each with its shaded
// confidence band where the model has a covariance (99 % by default, level adjustable; the
// Gauss approximation of Section 4.4.3), and the non-parametric ETFE (4.24) and SPA (4.28)
// estimates of the estimation data as points; or, chosen by View, their step or impulse
// responses with the same bands carried to the response. Click near a peak or notch to read it; click a
// legend entry to hide a curve; export as PNG, PDF or SVG.
#include <QWidget>
#include <vector>

#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QStackedWidget;
class QLabel;
class QListWidget;
class QPushButton;
class QSpinBox;

namespace flexarm {

class BackgroundRefresh;

class BodePlot;
class TransientPlot;

class BodePanel : public QWidget {
  Q_OBJECT
 public:
  explicit BodePanel(Workspace* workspace, QWidget* parent = nullptr);

  BodePlot* plot() const { return plot_; }
  TransientPlot* transientPlot() const { return transient_; }
  // What is drawn: 0 the Bode plot, 1 the step responses, 2 the impulse responses, each model
  // with its band (core/ident/transient.h).
  void setView(int view);
  int view() const;
  // Shows or hides model N of the shared list.
  void setModelShown(int index, bool shown);
  void setLevel(double level);
  void setNonparametricShown(bool spa, bool etfe);
  // Names of the curves drawn and whether each has a band, in plot order.
  QStringList curveNames() const { return names_; }
  bool curveHasBand(int curve) const;
  QString noteText() const;
  // Computing in the background: the curves and notes still show the previous state.
  bool isBusy() const;
  bool exportTo(const QString& path, QString* why = nullptr) const;

 public slots:
  void refresh();

 private:
  void refillList();
  void exportDialog();

  Workspace* workspace_;
  QListWidget* models_;
  QDoubleSpinBox* level_;
  QCheckBox* spa_;
  QCheckBox* etfe_;
  QSpinBox* window_;
  QPushButton* export_;
  QComboBox* view_;
  QStackedWidget* stack_;
  BodePlot* plot_;
  TransientPlot* transient_;
  QLabel* note_;
  QStringList names_;
  std::vector<bool> bands_;
  bool filling_ = false;
  BackgroundRefresh* worker_;
};

}  // namespace flexarm
