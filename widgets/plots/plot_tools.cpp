#include "widgets/plots/plot_tools.h"

#include <QAction>
#include <QApplication>
#include <QBuffer>
#include <QClipboard>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QMenu>
#include <QMessageBox>
#include <QPdfWriter>
#include <QSvgGenerator>
#include <QTextStream>
#include <cmath>
#include <qcustomplot.h>

#include "widgets/file_output.h"

namespace flexarm {
namespace {

constexpr const char* kProperty = "flexarmPlotTools";

QString csvField(QString s) {
  s.replace('\n', ' ');
  if (s.contains(',') || s.contains('"')) s = '"' + s.replace('"', "\"\"") + '"';
  return s;
}

QString axisName(const QCPAxis* a) { return a ? QString(a->label()).replace('\n', ' ') : QString(); }

}  // namespace

PlotTools::PlotTools(QCustomPlot* plot) : QObject(plot), plot_(plot) {
  plot->setProperty(kProperty, QVariant::fromValue<QObject*>(this));
  connect(plot, &QCustomPlot::mouseDoubleClick, this, [this](QMouseEvent* e) {
    if (e->button() == Qt::LeftButton) resetZoom();
  });
  plot->setContextMenuPolicy(Qt::CustomContextMenu);
  connect(plot, &QWidget::customContextMenuRequested, this, [this](const QPoint& at) {
    QMenu* menu = createMenu(plot_);
    menu->setAttribute(Qt::WA_DeleteOnClose);
    menu->popup(plot_->mapToGlobal(at));
  });
  if (plot->toolTip().isEmpty())
    plot->setToolTip(tr("Wheel zooms, drag pans, double click resets the zoom; right click "
                        "to export or copy the data"));
}

PlotTools* PlotTools::install(QCustomPlot* plot) {
  if (PlotTools* t = of(plot)) return t;
  return new PlotTools(plot);
}

PlotTools* PlotTools::of(const QCustomPlot* plot) {
  return plot ? qobject_cast<PlotTools*>(plot->property(kProperty).value<QObject*>()) : nullptr;
}

void PlotTools::resetZoom() {
  if (reset_) {
    reset_();
  } else {
    for (QCPAxisRect* rect : plot_->axisRects())
      for (QCPAxis* axis : rect->axes())
        if (!axis->plottables().isEmpty()) axis->rescale(true);
  }
  plot_->replot();
}

void PlotTools::limitAxis(QCPAxis* axis, std::function<std::pair<double, double>()> limits) {
  if (!axis || !limits) return;
  connect(axis, QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged), this,
          [axis, limits](const QCPRange& r) {
            const auto [lowest, highest] = limits();
            if (!(highest > lowest)) return;
            QCPRange fixed = r;
            if (r.size() >= highest - lowest) {
              fixed = QCPRange(lowest, highest);
            } else if (r.lower < lowest) {
              fixed = QCPRange(lowest, lowest + r.size());
            } else if (r.upper > highest) {
              fixed = QCPRange(highest - r.size(), highest);
            }
            if (fixed.lower != r.lower || fixed.upper != r.upper) axis->setRange(fixed);
          });
}

void PlotTools::limitAxisToData(QCPAxis* axis) {
  limitAxis(axis, [axis]() -> std::pair<double, double> {
    bool any = false;
    QCPRange span;
    for (QCPAbstractPlottable* p : axis->plottables()) {
      bool found = false;
      const QCPRange r = p->keyAxis() == axis ? p->getKeyRange(found) : p->getValueRange(found);
      if (!found) continue;
      span = any ? QCPRange(std::min(span.lower, r.lower), std::max(span.upper, r.upper)) : r;
      any = true;
    }
    return any ? std::pair{span.lower, span.upper} : std::pair{0.0, 0.0};
  });
}

QMenu* PlotTools::createMenu(QWidget* parent) {
  auto* menu = new QMenu(parent);
  menu->setObjectName("plotContextMenu");
  menu->addAction(tr("Reset zoom"), this, &PlotTools::resetZoom)->setObjectName("resetZoom");
  menu->addSeparator();
  menu->addAction(tr("Export image or data (PNG, SVG, PDF, CSV)..."), this, &PlotTools::exportDialog)
      ->setObjectName("exportPlot");
  menu->addAction(tr("Copy data"), this, &PlotTools::copyData)->setObjectName("copyData");
  return menu;
}

QString PlotTools::dataAsCsv() const {
  QString out;
  QTextStream s(&out);
  s << "series,x,y,x axis,y axis\n";
  s.setRealNumberPrecision(10);
  for (int i = 0; i < plot_->plottableCount(); ++i) {
    QCPAbstractPlottable* p = plot_->plottable(i);
    const QString name = csvField(p->name().isEmpty() ? tr("series %1").arg(i + 1) : p->name());
    const QString axes = csvField(axisName(p->keyAxis())) + ',' + csvField(axisName(p->valueAxis()));
    auto row = [&](double x, double y) {
      if (std::isfinite(x) && std::isfinite(y)) s << name << ',' << x << ',' << y << ',' << axes << '\n';
    };
    if (auto* g = qobject_cast<QCPGraph*>(p)) {
      for (const auto& d : *g->data()) row(d.key, d.value);
    } else if (auto* c = qobject_cast<QCPCurve*>(p)) {
      for (const auto& d : *c->data()) row(d.key, d.value);
    } else if (auto* b = qobject_cast<QCPBars*>(p)) {
      for (const auto& d : *b->data()) row(d.key, d.value);
    }
  }
  return out;
}

bool PlotTools::exportTo(const QString& path, QString* why) const {
  const QString ext = QFileInfo(path).suffix().toLower();
  const int w = std::max(plot_->width(), 800), h = std::max(plot_->height(), 600);
  // Drawn or encoded in memory, then written as every file is (widgets/file_output.h).
  QByteArray bytes;
  QBuffer buffer(&bytes);
  buffer.open(QIODevice::WriteOnly);
  auto draw = [&](QPaintDevice* device) {
    QCPPainter painter;
    if (!painter.begin(device)) return false;
    painter.setMode(QCPPainter::pmVectorized);
    painter.setMode(QCPPainter::pmNoCaching);
    plot_->toPainter(&painter, w, h);
    return painter.end();
  };
  bool ok = false;
  if (ext == "png") {
    ok = plot_->toPixmap(w, h).toImage().save(&buffer, "PNG");
  } else if (ext == "pdf") {
    QPdfWriter pdf(&buffer);
    pdf.setCreator("FlexArm plot");
    pdf.setResolution(72);
    pdf.setPageLayout(QPageLayout(QPageSize(QSize(w, h), QString(), QPageSize::ExactMatch),
                                  QPageLayout::Portrait, QMarginsF(0, 0, 0, 0)));
    ok = draw(&pdf);
  } else if (ext == "svg") {
    QSvgGenerator svg;
    svg.setOutputDevice(&buffer);
    svg.setSize(QSize(w, h));
    svg.setViewBox(QRect(0, 0, w, h));
    svg.setTitle("FlexArm plot");
    ok = draw(&svg);
  } else if (ext == "csv") {
    bytes = dataAsCsv().toUtf8();
    ok = true;
  } else {
    if (why) *why = tr("unknown format '%1': use .png, .svg, .pdf or .csv").arg(ext);
    return false;
  }
  buffer.close();
  if (!ok) {
    if (why) *why = tr("could not draw the plot for %1").arg(path);
    return false;
  }
  return writeFileBytes(path, bytes, why);
}

void PlotTools::exportDialog() {
  QString selected;
  const QString path = QFileDialog::getSaveFileName(
      plot_, tr("Export plot"), plot_->objectName() + ".png",
      tr("PNG image (*.png);;SVG drawing (*.svg);;PDF (*.pdf);;CSV data (*.csv)"), &selected);
  if (path.isEmpty()) return;
  QString why;
  if (!exportTo(path, &why))
    QMessageBox::warning(plot_, tr("Export failed"), why);
}

void PlotTools::copyData() const { QApplication::clipboard()->setText(dataAsCsv()); }

void keepRectsTall(QCustomPlot* plot, int perRect) {
  const int rects = static_cast<int>(plot->axisRects().size());
  // What is not a rect (title, legend rows, the last time axis' labels) on top.
  plot->setMinimumHeight(std::max(1, rects) * perRect + 40);
}

void showLegendAbove(QCustomPlot* plot) {
  QCPLegend* legend = plot->legend;
  if (!legend) return;
  const bool entries = legend->itemCount() > 0;
  auto* grid = qobject_cast<QCPLayoutGrid*>(legend->layout());
  if (entries && !grid) placeLegendAbove(plot);
  if (!entries && grid) {
    grid->take(legend);
    grid->simplify();
  }
  legend->setVisible(entries);
}

void placeLegendAbove(QCustomPlot* plot, QCPAxisRect* rect) {
  QCPLegend* legend = plot->legend;
  if (!rect) rect = plot->axisRect();
  if (!legend || !rect) return;
  if (auto* inset = qobject_cast<QCPLayoutInset*>(legend->layout())) inset->take(legend);
  if (auto* grid = qobject_cast<QCPLayoutGrid*>(legend->layout())) {
    grid->take(legend);
    grid->simplify();
  }
  QCPLayoutGrid* layout = plot->plotLayout();
  int row = -1, column = 0;
  for (int r = 0; r < layout->rowCount() && row < 0; ++r)
    for (int c = 0; c < layout->columnCount(); ++c)
      if (layout->element(r, c) == rect) {
        row = r;
        column = c;
        break;
      }
  if (row < 0) return;
  layout->insertRow(row);
  layout->addElement(row, column, legend);
  layout->setRowStretchFactor(row, 0.001);
  legend->setFillOrder(QCPLayoutGrid::foColumnsFirst);
  legend->setWrap(4);
  legend->setMargins(QMargins(4, 2, 4, 2));
  legend->setMinimumMargins(QMargins(0, 0, 0, 0));
  legend->setBorderPen(Qt::NoPen);
  legend->setBrush(Qt::NoBrush);
  legend->setMaximumSize(QWIDGETSIZE_MAX, QWIDGETSIZE_MAX);
}

}  // namespace flexarm
