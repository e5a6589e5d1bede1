#pragma once
// The everyday controls every plot shares, implemented once: a double click resets the zoom,
// the right-click menu resets the zoom, exports the plot as PNG, SVG or PDF, exports its
// data as CSV and copies the data to the clipboard; an axis can be kept inside limits while
// panning and zooming (time never runs below the log's start). Install it on every
// QCustomPlot: PlotTools::install(plot).
#include <QObject>
#include <QString>
#include <QStringList>
#include <functional>
#include <utility>

class QCustomPlot;
class QCPAxis;
class QCPAxisRect;
class QMenu;
class QWidget;

namespace flexarm {

class PlotTools : public QObject {
  Q_OBJECT
 public:
  // Installs the tools on plot (owned by it) or returns the ones already there.
  static PlotTools* install(QCustomPlot* plot);
  // The tools installed on plot, or nullptr.
  static PlotTools* of(const QCustomPlot* plot);

  // What "reset zoom" does; by default every axis is rescaled to its visible data.
  void setReset(std::function<void()> reset) { reset_ = std::move(reset); }
  void resetZoom();
  // Keeps axis inside the range limits() returns (asked at each change; an empty range means
  // no limit) while panning and zooming: a pan stops at the limit, a zoom out wider than the
  // limits shows exactly the limits.
  void limitAxis(QCPAxis* axis, std::function<std::pair<double, double>()> limits);
  // Keeps axis inside the key span of the plottables drawn on it (time never before the
  // first sample).
  void limitAxisToData(QCPAxis* axis);
  // The right-click menu (caller owns it): reset zoom, export PNG/SVG/PDF, export CSV, copy.
  QMenu* createMenu(QWidget* parent);
  // Every graph and curve as CSV: series, x, y, one row a point; the header names the axes.
  QString dataAsCsv() const;
  // Writes the plot as PNG, SVG or PDF, or its data as CSV, chosen by the extension; false
  // with a reason otherwise.
  bool exportTo(const QString& path, QString* why = nullptr) const;
  // Suffixes exportTo understands.
  static QStringList exportSuffixes() { return {"png", "svg", "pdf", "csv"}; }

 private:
  explicit PlotTools(QCustomPlot* plot);
  void exportDialog();
  void copyData() const;

  QCustomPlot* plot_;
  std::function<void()> reset_;
};

// Keeps every axis rect of the plot at least perRect pixels tall, so that stacked rects keep
// their labels apart: the plot asks for that much height (a panel that scrolls then scrolls
// instead of squeezing them). Call after the rects are laid out.
void keepRectsTall(QCustomPlot* plot, int perRect);

// Shows the legend in its own row above the data (placeLegendAbove) while it has entries;
// without entries it leaves the layout (an empty legend row would narrow the whole plot).
void showLegendAbove(QCustomPlot* plot);

// Places the plot's legend outside its data: in its own row above axis rect `rect` (the
// default rect when null), entries side by side, so no curve is hidden under it.
void placeLegendAbove(QCustomPlot* plot, QCPAxisRect* rect = nullptr);

}  // namespace flexarm
