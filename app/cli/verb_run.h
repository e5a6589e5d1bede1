#pragma once
// `flexarm run`: replays a session headless and writes its report. Rendering a report to
// PDF or HTML needs Qt, so the window build installs the renderer (app/report_writer.h);
// a build without the GUI replays and prints --json but refuses --report.
#include <string>

#include "core/session/report.h"

namespace flexarm::cli {

// Writes report to path; the extension (.pdf or .html) picks the format. False with why.
using ReportRenderer = bool (*)(const Report& report, const std::string& path, std::string* why);
void setReportRenderer(ReportRenderer renderer);
// The renderer installed (nullptr in a build without the GUI): other verbs' --report.
ReportRenderer reportRenderer();

}  // namespace flexarm::cli
