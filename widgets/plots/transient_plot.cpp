#include "widgets/plots/transient_plot.h"

#include <QVBoxLayout>
#include <qcustomplot.h>

#include "widgets/plots/plot_tools.h"

namespace flexarm {

TransientPlot::TransientPlot(QWidget* parent) : QWidget(parent), plot_(new QCustomPlot(this)) {
  setObjectName("transientPlot");
  plot_->setObjectName("transientCustomPlot");
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(plot_);
  plot_->xAxis->setLabel(tr("Time (s)"));
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(plot_);
  setKind(TransientKind::Step);
}

void TransientPlot::setKind(TransientKind kind) {
  plot_->yAxis->setLabel(kind == TransientKind::Step ? tr("Step response (output per unit input)")
                                                     : tr("Impulse response (output per unit area)"));
}

void TransientPlot::clear() {
  plot_->clearGraphs();
  plot_->legend->clearItems();
  curves_ = 0;
  plot_->replot();
}

void TransientPlot::addCurve(const QString& name, const QColor& color, const TransientResponse& r) {
  const QVector<double> t(r.time.begin(), r.time.end());
  if (r.hasBand()) {
    auto* lo = plot_->addGraph();
    auto* hi = plot_->addGraph();
    lo->setData(t, QVector<double>(r.lower.begin(), r.lower.end()), true);
    hi->setData(t, QVector<double>(r.upper.begin(), r.upper.end()), true);
    QColor fill = color;
    fill.setAlpha(60);
    for (auto* g : {lo, hi}) {
      g->setPen(QPen(fill, 1.0));
      g->removeFromLegend();
      g->setName(name + tr(" band"));
    }
    hi->setBrush(fill);
    hi->setChannelFillGraph(lo);
  }
  auto* g = plot_->addGraph();
  g->setName(r.hasBand() ? tr("%1 (%2 % band)").arg(name).arg(100.0 * r.level, 0, 'g', 4) : name);
  g->setPen(QPen(color, 1.6));
  g->setData(t, QVector<double>(r.value.begin(), r.value.end()), true);
  ++curves_;
  showLegendAbove(plot_);
}

void TransientPlot::rescale() {
  plot_->rescaleAxes();
  plot_->yAxis->scaleRange(1.1);
  plot_->replot();
}

bool TransientPlot::exportTo(const QString& path, QString* why) const {
  return PlotTools::of(plot_)->exportTo(path, why);
}

}  // namespace flexarm
