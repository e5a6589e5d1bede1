#pragma once
// Model panel: choose a physical structure, edit its parameters in a table with units
// (undoable), mark them free or fixed, switch nonlinear effects on, and see the Bode plot,
// pole-zero map and notch/peak frequencies follow every edit. "Simulate against log" runs
// the model (with its effects) on the loaded log's torque reference off the GUI thread and
// overlays measured and simulated motor velocity with the fit % (5.2).
#include <QFutureWatcher>
#include <QWidget>
#include <vector>

#include "core/signal/envelope.h"
#include "widgets/workspace.h"

class QComboBox;
class QCustomPlot;
class QLabel;
class QPushButton;
class QTableWidget;

namespace flexarm {

class BodePlot;
class Playhead;
class PlayheadCursor;
class PoleZeroPlot;

class ModelPanel : public QWidget {
  Q_OBJECT
 public:
  explicit ModelPanel(Workspace* workspace, QWidget* parent = nullptr);

  int currentIndex() const { return current_; }
  void selectModel(int index);
  // Adds a model of the given structure with its defaults to the list and selects it.
  int newModel(const QString& structure);
  // Edits through the same path as the table (undoable); false with a reason when refused.
  bool setParameter(const QString& name, double value, QString* why = nullptr);
  bool setEffect(EffectKind kind, bool on, double firstValue = std::nan(""));
  void simulateAgainstLog();
  bool isSimulating() const { return simulation_.isRunning(); }
  double lastFitPercent() const { return lastFit_; }
  QString frequencyText() const;
  BodePlot* bode() const { return bode_; }
  PoleZeroPlot* poleZero() const { return poleZero_; }
  // Shows the window's playhead in the simulation plot; a click there moves it.
  void setPlayhead(Playhead* playhead);

 signals:
  void simulationFinished(double fitPercent);

 private:
  struct SimOutcome {
    // The measured and simulated output as min/max envelopes (drawn for the visible range).
    std::shared_ptr<const EnvelopePyramid> measured, simulated;
    double startTime = 0.0, sampleTime = 1.0;
    double lo = 0.0, hi = 0.0;  // of both curves
    double fit = 0.0;
    QString error;
  };
  void refreshList();
  void refreshModel();
  void onParameterEdited(int row, int column);
  void onEffectEdited(int row, int column);
  void onSimulated();

  Workspace* workspace_;
  QComboBox* list_;
  QComboBox* structure_;
  QTableWidget* params_;
  QTableWidget* effects_;
  BodePlot* bode_;
  PoleZeroPlot* poleZero_;
  QLabel* frequencies_;
  QLabel* description_;
  QPushButton* simulate_;
  QCustomPlot* compare_;
  QLabel* fit_;
  PlayheadCursor* cursor_;
  QFutureWatcher<SimOutcome> simulation_;
  int current_ = -1;
  bool filling_ = false;
  double lastFit_ = std::nan("");
};

}  // namespace flexarm
