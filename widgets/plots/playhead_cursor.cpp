#include "widgets/plots/playhead_cursor.h"

#include <QMouseEvent>
#include <qcustomplot.h>

#include "widgets/playhead.h"

namespace flexarm {
namespace {
constexpr int kClickSlopPixels = 4;  // a press and release closer than this is a click
const QColor kPlayheadColor(200, 30, 30);
}  // namespace

PlayheadCursor::PlayheadCursor(QCustomPlot* plot, QObject* parent)
    : QObject(parent), plot_(plot) {
  connect(plot_, &QCustomPlot::mousePress, this, &PlayheadCursor::onPress);
  connect(plot_, &QCustomPlot::mouseRelease, this, &PlayheadCursor::onRelease);
}

void PlayheadCursor::setPlayhead(Playhead* playhead) {
  if (timeConnection_) disconnect(timeConnection_);
  playhead_ = playhead;
  if (playhead_)
    timeConnection_ = connect(playhead_, &Playhead::timeChanged, this, &PlayheadCursor::onTime);
  attach();
}

void PlayheadCursor::attach() {
  for (auto& line : lines_)
    if (line) plot_->removeItem(line);
  lines_.clear();
  if (!playhead_) return;
  if (!plot_->layer("playhead")) {
    plot_->addLayer("playhead", plot_->layer(plot_->layerCount() - 1), QCustomPlot::limAbove);
    plot_->layer("playhead")->setMode(QCPLayer::lmBuffered);
  }
  for (QCPAxisRect* rect : plot_->axisRects()) {
    QCPAxis* x = rect->axis(QCPAxis::atBottom);
    QCPAxis* y = rect->axis(QCPAxis::atLeft);
    auto* line = new QCPItemStraightLine(plot_);
    line->setLayer("playhead");
    line->setClipAxisRect(rect);
    line->setSelectable(false);
    for (auto* p : {line->point1, line->point2}) {
      p->setAxes(x, y);
      p->setAxisRect(rect);
      p->setTypeX(QCPItemPosition::ptPlotCoords);
      p->setTypeY(QCPItemPosition::ptAxisRectRatio);
    }
    line->setPen(QPen(kPlayheadColor, 1.5));
    lines_.emplace_back(line);
  }
  onTime(playhead_->time());
}

bool PlayheadCursor::isInView() const {
  for (const auto& line : lines_)
    if (line && line->visible() && line->clipAxisRect() &&
        line->clipAxisRect()->axis(QCPAxis::atBottom)->range().contains(shown_))
      return true;
  return false;
}

void PlayheadCursor::onTime(double t) {
  shown_ = t;
  const bool has = playhead_ && playhead_->hasSpan();
  for (auto& line : lines_) {
    if (!line) continue;
    line->point1->setCoords(t, 0);
    line->point2->setCoords(t, 1);
    line->setVisible(has);
  }
  if (follow_ && has && playhead_->isPlaying() && !lines_.empty() && lines_.front()) {
    // Page the time axes so that the playhead enters at the left of the next page.
    QCPAxis* x = lines_.front()->clipAxisRect()->axis(QCPAxis::atBottom);
    const QCPRange r = x->range();
    if (!r.contains(t)) {
      const double lower = t - 0.05 * r.size();
      for (QCPAxisRect* rect : plot_->axisRects())
        rect->axis(QCPAxis::atBottom)->setRange(lower, lower + r.size());
      plot_->replot(QCustomPlot::rpQueuedReplot);
      return;
    }
  }
  if (QCPLayer* layer = plot_->layer("playhead")) layer->replot();
}

void PlayheadCursor::onPress(QMouseEvent* e) {
  pressed_ = e->button() == Qt::LeftButton;
  pressAt_ = e->position().toPoint();
}

void PlayheadCursor::onRelease(QMouseEvent* e) {
  if (!pressed_ || !playhead_ || e->button() != Qt::LeftButton) return;
  pressed_ = false;
  const QPoint p = e->position().toPoint();
  if ((p - pressAt_).manhattanLength() > kClickSlopPixels) return;  // a drag
  for (const auto& line : lines_) {
    if (!line || !line->clipAxisRect()) continue;
    QCPAxisRect* rect = line->clipAxisRect();
    if (rect->rect().contains(p)) {
      playhead_->setTime(rect->axis(QCPAxis::atBottom)->pixelToCoord(p.x()));
      return;
    }
  }
}

}  // namespace flexarm
