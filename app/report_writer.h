#pragma once
// Renders a Report (core/session/report.h) as a document. HTML is self-contained: styles
// inline, plots embedded as PNG data URIs, no external reference. PDF has text laid out by
// QTextDocument and plots drawn as vector graphics (QCustomPlot::toPainter on QPdfWriter
// pages). Both open with the provenance: FlexArm version, session file, every log's SHA-256.
#include <QString>
#include <string>

#include "core/session/report.h"

namespace flexarm {

// The whole report as one HTML document.
QString reportHtml(const Report& report);
bool writeReportHtml(const Report& report, const QString& path, QString* why);
bool writeReportPdf(const Report& report, const QString& path, QString* why);

// Writes .pdf or .html by the path's extension. Without a running QApplication (the
// headless `flexarm run`) it makes one on the offscreen platform for the plots.
bool writeReportFile(const Report& report, const std::string& path, std::string* why);

}  // namespace flexarm
