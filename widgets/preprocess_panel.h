#pragma once
// Preprocess panel: resampling onto a uniform grid (rate, method for irregular time stamps,
// longest gap to bridge, and the time-stamp report of jitter, gaps, duplicates and
// reversals, whose rows show their place in the Log panel), differentiation, decimation
// factor and anti-alias filter, detrending; amplitude spectra of a channel before and after
// (log axes, with the new Nyquist frequency marked); Apply makes the result the data every
// later panel uses. The computation runs off the GUI thread, with a busy bar and Cancel.
#include <QFutureWatcher>
#include <QWidget>
#include <memory>

#include "core/signal/preprocess.h"
#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QCustomPlot;
class QDoubleSpinBox;
class QGroupBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QTimer;

namespace flexarm {

class TimingTable;

class PreprocessPanel : public QWidget {
  Q_OBJECT
 public:
  explicit PreprocessPanel(Workspace* workspace, QWidget* parent = nullptr);

  PreprocessOptions options() const;
  void setOptions(const PreprocessOptions& o);
  // Starts computing the preview now (normally debounced after a control changes).
  void preview();
  bool isBusy() const { return watcher_.isRunning(); }
  bool hasPreview() const { return result_ != nullptr; }
  QCustomPlot* plot() const { return plot_; }
  TimingTable* timingTable() const { return timing_; }
  QString summaryText() const;

 public slots:
  void apply();
  void reset();

 signals:
  void previewReady();  // also when it failed (hasPreview() is then false)
  // A row of the time-stamp report was chosen: the Log panel shows this time.
  void timeSelected(double seconds);

 private:
  struct Outcome {
    std::shared_ptr<IdData> data;
    AmplitudeSpectrum before, after;
    std::vector<TimingReport> timing;
    QString error, resampling, unit;
    double seconds = 0.0;
    double binHz = 0.0;  // frequency resolution of both spectra
  };
  void schedulePreview();
  void onFinished();
  void refillChannels();
  void onLogChanged();
  // Fills the time-stamp report; with nothing to list, a line says the stamps are regular.
  void showTiming(const std::vector<TimingReport>& reports);

  Workspace* workspace_;
  QGroupBox* resample_;
  QDoubleSpinBox* rate_;
  QComboBox* method_;
  QDoubleSpinBox* maxGap_;
  TimingTable* timing_;
  QLabel* timingLabel_ = nullptr;
  QCheckBox* differentiate_;
  QSpinBox* factor_;
  QComboBox* filter_;
  QComboBox* detrend_;
  QComboBox* channel_;
  QCustomPlot* plot_;
  QLabel* summary_;
  QProgressBar* busy_;
  QPushButton* cancel_;
  QPushButton* apply_;
  QPushButton* reset_;
  QTimer* debounce_;
  QFutureWatcher<Outcome> watcher_;
  std::shared_ptr<IdData> result_;
  PreprocessOptions resultOptions_;
  int generation_ = 0;
  int running_ = -1;
};

}  // namespace flexarm
