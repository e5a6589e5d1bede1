#pragma once
// The window's playhead in a time plot: a vertical line at the playhead's time in every axis
// rect of a QCustomPlot whose bottom axis is the log's time (seconds), and a click (a press
// and release without a drag) in such a rect moves the playhead there. The line sits on its
// own buffered layer, so following the playhead redraws only that layer.
#include <QObject>
#include <QPoint>
#include <QPointer>
#include <vector>

#include "widgets/playhead.h"

class QCustomPlot;
class QCPItemStraightLine;
class QMouseEvent;

namespace flexarm {

class PlayheadCursor : public QObject {
  Q_OBJECT
 public:
  explicit PlayheadCursor(QCustomPlot* plot, QObject* parent = nullptr);

  void setPlayhead(Playhead* playhead);
  Playhead* playhead() const { return playhead_; }
  // (Re)creates the lines, one per axis rect of the plot; call after the plot's axis rects
  // were rebuilt or its items cleared.
  void attach();
  // While playing, page the time axes so that the playhead stays in view.
  void setFollow(bool on) { follow_ = on; }
  // The time the lines show and whether one lies inside its plot's visible time range.
  double shownTime() const { return shown_; }
  bool isInView() const;

 private:
  void onTime(double t);
  void onPress(QMouseEvent* e);
  void onRelease(QMouseEvent* e);

  QCustomPlot* plot_;
  QPointer<Playhead> playhead_;
  std::vector<QPointer<QCPItemStraightLine>> lines_;
  QMetaObject::Connection timeConnection_;
  QPoint pressAt_;
  bool pressed_ = false;
  bool follow_ = false;
  double shown_ = 0.0;
};

}  // namespace flexarm
