#include "widgets/plots/envelope_graph.h"

#include <algorithm>
#include <cmath>
#include <qcustomplot.h>

namespace flexarm {

std::size_t envelopePointBudget(int pixels) {
  return static_cast<std::size_t>(2 * std::max(pixels, 800));
}

void setDenseDrawing(QCPGraph* graph, bool dense) {
  // A pen wider than one pixel makes the raster engine stroke the polyline as a polygon:
  // for thousands of near-vertical segments that took half a second per replot. A one-pixel
  // pen takes the fast cosmetic path; at two points per pixel column antialiasing adds
  // nothing to the picture either.
  graph->setAntialiased(!dense);
  if (dense && graph->pen().widthF() > 1.0) {
    QPen pen = graph->pen();
    pen.setWidthF(1.0);
    graph->setPen(pen);
  }
}

EnvelopeGraph::EnvelopeGraph(QCPGraph* graph, std::shared_ptr<const EnvelopePyramid> envelope,
                             double startTime, double sampleTime)
    : QObject(graph), graph_(graph), envelope_(std::move(envelope)), startTime_(startTime),
      sampleTime_(sampleTime) {
  connect(graph_->keyAxis(), QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged), this,
          [this](const QCPRange&) { refresh(); });
  refresh();
}

void EnvelopeGraph::refresh() {
  const std::size_t n = envelope_->size();
  if (n == 0 || !(sampleTime_ > 0.0)) {
    graph_->data()->clear();
    return;
  }
  const QCPRange r = graph_->keyAxis()->range();
  auto index = [&](double t) {
    const double i = std::floor((t - startTime_) / sampleTime_);
    return static_cast<std::size_t>(std::clamp(i, 0.0, static_cast<double>(n)));
  };
  // One sample beyond each side, so the curve runs to the plot's edges.
  const std::size_t first = index(r.lower) > 0 ? index(r.lower) - 1 : 0;
  const std::size_t last = std::min(n, index(r.upper) + 2);
  static thread_local std::vector<double> position, value;
  const int pixels = graph_->keyAxis()->axisRect()->width();
  envelope_->visiblePoints(first, last, envelopePointBudget(pixels), position, value);
  setDenseDrawing(graph_, position.size() >= static_cast<std::size_t>(pixels));
  QVector<QCPGraphData> points(static_cast<int>(position.size()));
  for (std::size_t i = 0; i < position.size(); ++i)
    points[static_cast<int>(i)] = QCPGraphData(startTime_ + position[i] * sampleTime_, value[i]);
  graph_->data()->set(points, true);
}

}  // namespace flexarm
