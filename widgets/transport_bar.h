#pragma once
// The transport bar of the window's playhead: Play/Pause, step back and forward, a scrub
// slider over the log, the time (typed or read), the speed (x0.1 ... x100) and loop over the
// selection (dragged in the Log panel's loop mode). Keyboard: Space plays or pauses, Left and
// Right step one frame (Shift: one second, Ctrl: one sample), Home and End go to the ends, Up
// and Down change the speed.
#include <QWidget>
#include <vector>

class QComboBox;
class QDoubleSpinBox;
class QKeyEvent;
class QLabel;
class QSlider;
class QToolButton;

namespace flexarm {

class Playhead;

class TransportBar : public QWidget {
  Q_OBJECT
 public:
  explicit TransportBar(Playhead* playhead, QWidget* parent = nullptr);

  // The speeds offered, slowest first.
  static const std::vector<double>& speeds();
  // Acts on a playhead key (see above); false when the key is not one. The main window calls
  // it for keys no focused widget took, so lists, sliders and text fields keep their arrows.
  static bool handleKey(Playhead* playhead, QKeyEvent* e);

  QToolButton* playButton() const { return play_; }
  QSlider* slider() const { return slider_; }
  QComboBox* speedCombo() const { return speed_; }
  QString timeText() const;

 private:
  void onTime(double t);
  void onSpan();
  void onSelection();

  Playhead* playhead_;
  QToolButton* play_;
  QToolButton* back_;
  QToolButton* forward_;
  QSlider* slider_;
  QDoubleSpinBox* time_;
  QLabel* total_;
  QComboBox* speed_;
  QToolButton* loop_;
  QLabel* selection_;
  QToolButton* clearSelection_;
  bool updating_ = false;
};

}  // namespace flexarm
