#pragma once
// Preprocess panel: differentiation, decimation factor and anti-alias filter, detrending;
// amplitude spectra of a channel before and after (log axes, with the new Nyquist frequency
// marked); Apply makes the result the data every later panel uses. The computation runs off
// the GUI thread, with a busy bar and Cancel.
#include <QFutureWatcher>
#include <QWidget>
#include <memory>

#include "core/signal/preprocess.h"
#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QCustomPlot;
class QLabel;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QTimer;

namespace flexarm {

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

 public slots:
  void apply();
  void reset();

 signals:
  void previewReady();

 private:
  struct Outcome {
    std::shared_ptr<IdData> data;
    AmplitudeSpectrum before, after;
    QString error;
    double seconds = 0.0;
  };
  void schedulePreview();
  void onFinished();
  void refillChannels();

  Workspace* workspace_;
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
