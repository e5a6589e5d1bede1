#pragma once
// Log panel: every channel of the current data against time in stacked plots sharing the
// time axis. Wheel zooms time, drag pans; a crosshair follows the mouse with a readout of
// time and values; in range mode a drag selects the estimation or validation range, shown
// as shaded regions and listed with their sample counts; in loop mode a drag selects the
// playhead's loop selection. The window's playhead is a red line across every channel; a
// click in a plot moves it, and while playing the time axis pages to keep it in view.
#include <QWidget>
#include <memory>
#include <vector>

#include "core/signal/envelope.h"
#include "widgets/background_refresh.h"

#include "widgets/workspace.h"

class QCustomPlot;
class QCPAxisRect;
class QCPItemRect;
class QCPItemStraightLine;
class QCPLayer;
class QLabel;
class QTableWidget;
class QTableWidgetItem;
class QToolButton;
class QKeyEvent;
class QMouseEvent;
class QWheelEvent;

namespace flexarm {

class Playhead;
class PlayheadCursor;

class LogPanel : public QWidget {
  Q_OBJECT
 public:
  enum class Mode { Navigate, SelectEstimation, SelectValidation, SelectLoop };

  explicit LogPanel(Workspace* workspace, QWidget* parent = nullptr);

  // Follows the window's playhead and moves it on a click.
  void setPlayhead(Playhead* playhead);
  PlayheadCursor* playheadCursor() const { return playheadCursor_; }
  void setMode(Mode m);
  // Z, E, V and L choose the mode. They are keys, not shortcuts: a text field with the focus
  // takes its letters first, and the panel or the window gets the ones nothing used (with the
  // Log panel focused, or window-wide through MainWindow::keyPressEvent). True when used.
  bool handleModeKey(QKeyEvent* e);
  Mode mode() const { return mode_; }
  QCustomPlot* plot() const { return plot_; }
  // Axis rectangle of channel i (top to bottom), for tests and screenshots.
  QCPAxisRect* channelRect(int i) const;
  int channelCount() const { return static_cast<int>(rects_.size()); }
  // Pixel x of time t in the plots.
  double pixelForTime(double t) const;
  QString readoutText() const;
  // Shows the whole log.
  void showAll();
  // The channels' envelopes are being formed for the log shown (its curves follow).
  bool isBusy() const;
  QTableWidget* rangeTable() const { return rangeTable_; }
  // Sets a range from typed times in seconds ("0.5", "12 s"; empty means the log's start or
  // end), exactly as typed when inside the log. False with the reason otherwise.
  bool setRangeText(RangeKind kind, const QString& from, const QString& to, QString* why = nullptr);
  // Zooms to a short window centred on time t with the cursor line there (e.g. a gap of the
  // Preprocess panel's time-stamp report).
  void showAround(double t);

 protected:
  void keyPressEvent(QKeyEvent* e) override;

 private:
  void rebuild();
  void updateRanges();
  // A time of the range table, to the log's resolution.
  QString secondsText(double t) const;
  void onMousePress(QMouseEvent* e);
  void onMouseMove(QMouseEvent* e);
  void onMouseRelease(QMouseEvent* e);
  void syncTimeAxes(QCPAxisRect* source);
  void onRangeEdited(QTableWidgetItem* item);
  // Gives channel c's graph the points to draw for its visible time range.
  void refreshChannel(std::size_t c);
  double timeAtPixel(double x) const;
  void placeRect(QCPItemRect* item, double t0, double t1, bool visible);
  void updateLoopSelection();

  Workspace* workspace_;
  QCustomPlot* plot_;
  QLabel* readout_;
  QTableWidget* rangeTable_;
  QToolButton* navigateButton_;
  QToolButton* estimationButton_;
  QToolButton* validationButton_;
  QToolButton* loopButton_;
  Playhead* playhead_ = nullptr;
  PlayheadCursor* playheadCursor_;
  QCPLayer* overlay_ = nullptr;
  std::vector<QCPAxisRect*> rects_;
  std::vector<QCPItemStraightLine*> cursors_;
  std::vector<QCPItemRect*> estimationRects_, validationRects_, loopRects_;
  // Each channel's envelope, formed off the GUI thread (it grows with the log): empty until
  // drawer_ has applied them for the data shown.
  std::vector<std::shared_ptr<const EnvelopePyramid>> envelopes_;
  BackgroundRefresh* drawer_;
  Mode mode_ = Mode::Navigate;
  bool selecting_ = false;
  double selectStart_ = 0.0;
  bool syncing_ = false;
};

}  // namespace flexarm
