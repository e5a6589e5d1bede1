#include "widgets/plots/pole_zero_plot.h"

#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <qcustomplot.h>

#include "widgets/plots/plot_tools.h"

namespace flexarm {

PoleZeroPlot::PoleZeroPlot(QWidget* parent) : QWidget(parent), plot_(new QCustomPlot(this)) {
  setObjectName("poleZeroPlot");
  plot_->xAxis->setLabel(tr("real [1/s]"));
  plot_->yAxis->setLabel(tr("imaginary [rad/s]"));
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(plot_)->setReset([this] { rescale(); });
  plot_->legend->setVisible(true);
  plot_->legend->setFont(QFont(font().family(), 8));
  placeLegendAbove(plot_);  // never over a pole
  // Few ticks, so that "-2000 -1500 ..." never run into each other in a small plot.
  plot_->xAxis->ticker()->setTickCount(4);
  plot_->yAxis->ticker()->setTickCount(4);
  auto* axis = new QCPItemStraightLine(plot_);
  axis->point1->setCoords(0, 0);
  axis->point2->setCoords(0, 1);
  axis->setPen(QPen(QColor(120, 120, 120), 1, Qt::DashLine));
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(plot_);
  setMinimumSize(240, 200);
}

void PoleZeroPlot::clear() {
  plot_->clearPlottables();
  regions_ = 0;
  plot_->replot();
}

void PoleZeroPlot::addRegions(const QString& label, const QColor& color,
                              const std::vector<std::vector<std::complex<double>>>& boundaries) {
  bool first = true;
  for (const auto& b : boundaries) {
    auto* c = new QCPCurve(plot_->xAxis, plot_->yAxis);
    QVector<double> x, y;
    for (const auto& z : b) {
      x.push_back(z.real());
      y.push_back(z.imag());
    }
    c->setData(x, y);
    QColor fill = color;
    fill.setAlpha(40);
    c->setPen(QPen(color, 1.0));
    c->setBrush(fill);
    c->setName(label);
    if (!first) c->removeFromLegend();
    first = false;
    ++regions_;
  }
  plot_->replot();
}

void PoleZeroPlot::addSet(const QString& name, const QColor& color,
                          const std::vector<std::complex<double>>& poles,
                          const std::vector<std::complex<double>>& zeros) {
  auto add = [&](const std::vector<std::complex<double>>& pts, QCPScatterStyle::ScatterShape shape,
                 const QString& label) {
    auto* g = plot_->addGraph();
    g->setLineStyle(QCPGraph::lsNone);
    g->setScatterStyle(QCPScatterStyle(shape, QPen(color, 2), Qt::NoBrush, 9));
    g->setName(label);
    QVector<double> x, y;
    for (const auto& p : pts) {
      x.push_back(p.real());
      y.push_back(p.imag());
    }
    g->setData(x, y);  // not sorted by real part: keep order, draw scatter only
  };
  add(poles, QCPScatterStyle::ssCross, name + tr(" poles"));
  if (!zeros.empty()) add(zeros, QCPScatterStyle::ssCircle, name + tr(" zeros"));
  rescale();
}

int PoleZeroPlot::pointCount() const {
  int n = 0;
  for (int i = 0; i < plot_->graphCount(); ++i) n += plot_->graph(i)->dataCount();
  return n;
}

void PoleZeroPlot::rescale() {
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  for (int i = 0; i < plot_->graphCount(); ++i)
    for (const auto& d : *plot_->graph(i)->data()) {
      xmin = std::min(xmin, d.key);
      xmax = std::max(xmax, d.key);
      ymin = std::min(ymin, d.value);
      ymax = std::max(ymax, d.value);
    }
  const double padX = std::max(1.0, 0.1 * (xmax - xmin)), padY = std::max(1.0, 0.1 * (ymax - ymin));
  plot_->xAxis->setRange(xmin - padX, xmax + padX);
  plot_->yAxis->setRange(ymin - padY, ymax + padY);
  plot_->replot();
}

}  // namespace flexarm
