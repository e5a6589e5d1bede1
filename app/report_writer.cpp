#include "app/report_writer.h"

#include <QAbstractTextDocumentLayout>
#include <QApplication>
#include <QBuffer>
#include <QFile>
#include <QFileInfo>
#include <QPageLayout>
#include <QPageSize>
#include <QPdfWriter>
#include <QTextDocument>
#include <algorithm>
#include <cctype>
#include <memory>
#include <qcustomplot.h>

#include "widgets/file_output.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {

constexpr int kPlotWidth = 680;   // logical pixels of a plot (96 dpi)
constexpr int kPlotHeight = 300;

QString esc(const std::string& s) { return QString::fromStdString(s).toHtmlEscaped(); }

const char* kStyle =
    "body{font-family:sans-serif;font-size:10pt;color:#222;max-width:760px;margin:24px auto}"
    "h1{font-size:18pt;margin-bottom:4px}h2{font-size:13pt;margin-top:18px;"
    "border-bottom:1px solid #999}"
    "table{border-collapse:collapse;margin:6px 0}td,th{border:1px solid #bbb;padding:2px 8px}"
    "th{background:#e8eef4;text-align:left}td.num{text-align:right}"
    ".prov{font-size:8pt;color:#444}.warn{color:#a00000}.caption{font-weight:bold;margin-top:8px}";

bool looksNumeric(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+' ||
          c == 'e'))
      return false;
  return true;
}

// "Log", "Reference log", "Log monitored": the log's name without saying "log" twice.
QString logLabel(const std::string& name) {
  QString n = QString::fromStdString(name).trimmed();
  if (n.isEmpty() || n.compare("log", Qt::CaseInsensitive) == 0) return "Log";
  if (!n.contains("log", Qt::CaseInsensitive)) return "Log " + n.toHtmlEscaped();
  n[0] = n[0].toUpper();
  return n.toHtmlEscaped();
}

// A long unbroken string (a SHA-256, a path) in groups of 16 characters that the page may
// wrap between; removing the spaces gives it back.
QString breakable(const std::string& s) {
  QString out;
  const QString q = QString::fromStdString(s);
  for (int i = 0; i < q.size(); i += 16) out += (i ? " " : "") + q.mid(i, 16).toHtmlEscaped();
  return out;
}

// A hexadecimal checksum (SHA-256: 64 digits).
bool isChecksum(const std::string& s) {
  return s.size() >= 32 &&
         std::all_of(s.begin(), s.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
}

// Title block: version, session, logs with checksums, warnings.
QString headerHtml(const Report& r) {
  QString h = QString("<h1>%1</h1><p class=\"prov\">FlexArm %2<br>Session: %3<br>")
                  .arg(esc(r.title), esc(r.flexarmVersion), esc(r.session));
  for (const auto& l : r.logs)
    h += QString("%1: %2%3<br>SHA-256 %4<br>")
             .arg(logLabel(l.name), esc(l.path),
                  l.note.empty() ? QString() : " (" + esc(l.note) + ")", breakable(l.sha256));
  h += "</p>";
  for (const auto& w : r.warnings) h += "<p class=\"warn\">Warning: " + esc(w) + "</p>";
  return h;
}

// Section title, paragraphs and tables (plots are placed by the caller).
QString sectionHtml(const ReportSection& s) {
  QString h = "<h2>" + esc(s.title) + "</h2>";
  for (const auto& p : s.paragraphs) h += "<p>" + esc(p) + "</p>";
  for (const auto& t : s.tables) {
    // A wide table (many columns) in a smaller font, so that it fits the page with every
    // heading, number and name on one line: never squeezed into vertical letters.
    const QString size = t.header.size() > 6 ? "font-size:7.5pt;" : "";
    h += "<p class=\"caption\">" + esc(t.caption) + "</p><table cellspacing=\"0\" cellpadding=\"3\" border=\"1\"><tr>";
    // A heading breaks only between its words ("Interval / low"), never inside one.
    for (const auto& c : t.header)
      h += QString("<th style=\"%1%2\">")
               .arg(c.find(' ') == std::string::npos ? "white-space:nowrap;" : "", size) +
           esc(c) + "</th>";
    h += "</tr>";
    for (const auto& row : t.rows) {
      h += "<tr>";
      for (const auto& c : row) {
        // A number, a single word (an effect or parameter name) or a short label (a unit,
        // "kg m^2") is never broken; a sentence wraps at its spaces.
        // A checksum wraps between its groups of 16 characters.
        const bool checksum = isChecksum(c);
        const bool word = !checksum && (c.find(' ') == std::string::npos || c.size() <= 12);
        const QString style = (word ? "white-space:nowrap;" : "") + size;
        h += QString(looksNumeric(c) ? "<td class=\"num\" align=\"right\" style=\"%1\">"
                                     : "<td style=\"%1\">").arg(style) +
             (checksum ? breakable(c) : esc(c)) + "</td>";
      }
      h += "</tr>";
    }
    h += "</table>";
  }
  return h;
}


QString dataUri(const QImage& image) {
  QByteArray png;
  QBuffer buffer(&png);
  buffer.open(QIODevice::WriteOnly);
  image.save(&buffer, "PNG");
  return "data:image/png;base64," + QString::fromLatin1(png.toBase64());
}

}  // namespace

std::unique_ptr<QCustomPlot> reportPlot(const ReportPlot& p) {
  auto plot = std::make_unique<QCustomPlot>();
  plot->resize(kPlotWidth, kPlotHeight);
  plot->plotLayout()->insertRow(0);
  plot->plotLayout()->addElement(0, 0, new QCPTextElement(plot.get(), QString::fromStdString(p.title),
                                                          QFont("sans", 10, QFont::Bold)));
  static const QColor kColors[] = {QColor(31, 119, 180), QColor(214, 39, 40), QColor(44, 160, 44),
                                   QColor(148, 103, 189)};
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const auto& s = p.series[i];
    // Thousands of points over a page width: thin, slightly transparent lines, so that
    // overlaid curves (measured and simulated) stay apart instead of merging into a band.
    const bool dense = s.x.size() > 2 * static_cast<std::size_t>(kPlotWidth);
    QColor color = kColors[(s.color >= 0 ? static_cast<std::size_t>(s.color) : i) % 4];
    if (dense && p.series.size() > 1) color.setAlpha(190);
    QPen pen(color, dense ? 0.7 : 1.4);
    if (s.dashed) pen.setStyle(Qt::DashLine);
    const QVector<double> x(s.x.begin(), s.x.end()), y(s.y.begin(), s.y.end());
    QCPAbstractPlottable* item = nullptr;
    if (p.parametric) {
      auto* c = new QCPCurve(plot->xAxis, plot->yAxis);
      c->setData(x, y);
      if (x.size() == 1) {  // a single point (e.g. -1 in a Nyquist plot) as a marker
        c->setLineStyle(QCPCurve::lsNone);
        c->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCross, pen.color(), 9));
      }
      item = c;
    } else {
      auto* g = plot->addGraph();
      g->setData(x, y, true);
      item = g;
    }
    item->setName(QString::fromStdString(s.name));
    item->setPen(pen);
    // The legend names each curve once: a nameless series (the second bound of a band) or a
    // repeated name has no entry of its own.
    bool named = !s.name.empty();
    for (std::size_t k = 0; k < i && named; ++k) named = p.series[k].name != s.name;
    if (!named) item->removeFromLegend();
  }
  plot->xAxis->setLabel(QString::fromStdString(p.xLabel));
  plot->yAxis->setLabel(QString::fromStdString(p.yLabel));
  auto logAxis = [](QCPAxis* a) {
    a->setScaleType(QCPAxis::stLogarithmic);
    a->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
    a->setNumberFormat("eb");
    a->setNumberPrecision(0);
  };
  if (p.logX) logAxis(plot->xAxis);
  if (p.logY) logAxis(plot->yAxis);
  // The legend in a row of its own between the title and the data: it covers no curve.
  plot->legend->setVisible(plot->legend->itemCount() > 1);
  plot->legend->setFont(QFont("sans", 8));
  if (plot->legend->visible()) placeLegendAbove(plot.get());
  plot->rescaleAxes();
  if (p.xRange) plot->xAxis->setRange(p.xRange->first, p.xRange->second);
  if (p.yRange) plot->yAxis->setRange(p.yRange->first, p.yRange->second);
  return plot;
}

QList<QImage> reportPlotImages(const Report& report) {
  QList<QImage> images;
  for (const auto& s : report.sections)
    for (const auto& p : s.plots) images.append(reportPlot(p)->toPixmap(kPlotWidth, kPlotHeight, 2.0).toImage());
  return images;
}

QString reportHtml(const Report& report, const QList<QImage>& plots) {
  QString h = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + esc(report.title) +
              "</title><style>" + kStyle + "</style></head><body>\n" + headerHtml(report);
  int next = 0;
  for (const auto& s : report.sections) {
    h += sectionHtml(s) + "\n";
    for (const auto& p : s.plots) {
      if (next >= plots.size()) break;
      h += QString("<p><img alt=\"%1\" width=\"%2\" height=\"%3\" src=\"%4\"></p>\n")
               .arg(esc(p.title))
               .arg(kPlotWidth)
               .arg(kPlotHeight)
               .arg(dataUri(plots[next++]));
    }
  }
  return h + "</body></html>\n";
}

bool writeReportHtml(const Report& report, const QString& path, QString* why) {
  return writeReportHtml(report, reportPlotImages(report), path, why);
}

bool writeReportHtml(const Report& report, const QList<QImage>& plots, const QString& path,
                     QString* why) {
  return writeFileBytes(path, reportHtml(report, plots).toUtf8(), why);
}

bool writeReportPdf(const Report& report, const QString& path, QString* why) {
  // Drawn in memory, then written as every file is (writeFileAtomically): a failure keeps
  // any previous report, and nothing is written through a link planted beside it.
  QByteArray pdf;
  {
    QBuffer buffer(&pdf);
    buffer.open(QIODevice::WriteOnly);
    QPdfWriter writer(&buffer);
    writer.setResolution(96);
    writer.setPageSize(QPageSize(QPageSize::A4));
    writer.setPageMargins(QMarginsF(18, 16, 18, 16), QPageLayout::Millimeter);
    writer.setTitle(QString::fromStdString(report.title));
    writer.setCreator(QString("FlexArm %1").arg(FLEXARM_VERSION));
    QCPPainter painter;
    if (!painter.begin(&writer)) {
      if (why) *why = "cannot draw the report for " + path;
      return false;
    }
    painter.setMode(QCPPainter::pmVectorized);
    painter.setMode(QCPPainter::pmNoCaching);
    const QRect page = writer.pageLayout().paintRectPixels(writer.resolution());
    const double width = page.width(), height = page.height();
    double y = 0.0;
    auto ensure = [&](double h) {
      if (y > 0.0 && y + h > height) {
        writer.newPage();
        y = 0.0;
      }
    };
    // Draws an HTML block, splitting it over pages at the document's own page breaks.
    auto drawHtml = [&](const QString& html) {
      QTextDocument doc;
      doc.documentLayout()->setPaintDevice(&writer);
      doc.setDefaultStyleSheet(kStyle);
      doc.setDefaultFont(QFont("sans", 9));
      doc.setHtml(html);
      doc.setTextWidth(width);
      double docH = doc.size().height();
      double offset = 0.0;
      while (offset < docH) {
        ensure(std::min(docH - offset, height));
        const double room = height - y;
        painter.save();
        painter.translate(0, y - offset);
        doc.drawContents(&painter, QRectF(0, offset, width, std::min(room, docH - offset)));
        painter.restore();
        const double used = std::min(room, docH - offset);
        offset += used;
        y += used;
        if (offset < docH) {
          writer.newPage();
          y = 0.0;
        }
      }
    };
    drawHtml(headerHtml(report));
    for (const auto& s : report.sections) {
      ensure(120);
      drawHtml(sectionHtml(s));
      for (const auto& p : s.plots) {
        const double scale = width / kPlotWidth;
        const double h = kPlotHeight * scale;
        ensure(h + 8);
        auto plot = reportPlot(p);
        painter.save();
        painter.translate(0, y + 4);
        painter.scale(scale, scale);
        plot->toPainter(&painter, kPlotWidth, kPlotHeight);
        painter.restore();
        y += h + 8;
      }
    }
    painter.end();
  }
  return writeFileBytes(path, pdf, why);
}

bool writeReportFile(const Report& report, const std::string& path, std::string* why) {
  std::unique_ptr<QApplication> app;
  if (!QApplication::instance()) {
    qputenv("QT_QPA_PLATFORM", "offscreen");
    static int argc = 1;
    static char name[] = "flexarm";
    static char* argv[] = {name, nullptr};
    app = std::make_unique<QApplication>(argc, argv);
  }
  const QString p = QString::fromStdString(path);
  QString message;
  const bool ok = p.endsWith(".pdf", Qt::CaseInsensitive) ? writeReportPdf(report, p, &message)
                                                          : writeReportHtml(report, p, &message);
  if (!ok && why) *why = message.toStdString();
  return ok;
}

}  // namespace flexarm
