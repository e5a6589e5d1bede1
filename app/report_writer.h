#pragma once
// Renders a Report (core/session/report.h) as a document. HTML is self-contained: styles
// inline, plots embedded as PNG data URIs, no external reference. PDF has text laid out by
// QTextDocument and plots drawn as vector graphics (QCustomPlot::toPainter on QPdfWriter
// pages). Both open with the provenance: FlexArm version, session file, every log's SHA-256.
#include <QImage>
#include <QList>
#include <QString>
#include <memory>
#include <string>

#include "core/session/report.h"

class QCustomPlot;

namespace flexarm {

// The plot a report draws for p: its title, the legend in a row of its own between title and
// data (each curve named once), the axes. GUI thread only.
std::unique_ptr<QCustomPlot> reportPlot(const ReportPlot& p);
// Every plot of the report as an image, in order. GUI thread only (QCustomPlot is a widget).
QList<QImage> reportPlotImages(const Report& report);
// The whole report as one HTML document with the plot images embedded as PNG. Any thread:
// the window encodes and writes in the background.
QString reportHtml(const Report& report, const QList<QImage>& plots);
bool writeReportHtml(const Report& report, const QList<QImage>& plots, const QString& path,
                     QString* why);
bool writeReportHtml(const Report& report, const QString& path, QString* why);
bool writeReportPdf(const Report& report, const QString& path, QString* why);

// Writes .pdf or .html by the path's extension. Without a running QApplication (the
// headless `flexarm run`) it makes one on the offscreen platform for the plots.
bool writeReportFile(const Report& report, const std::string& path, std::string* why);

}  // namespace flexarm
