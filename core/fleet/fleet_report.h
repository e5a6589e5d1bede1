#pragma once
// The fleet as a report (core/session/report.h, rendered to PDF or HTML by the window build):
// the run, the maintenance suggestion (which axes to service at the next stop), the status of
// every axis, and for every axis that changed its trend over days with the estimates' bands,
// the fitted step or drift, the threshold and the predicted crossing, and the temperature.
#include "core/fleet/engine.h"
#include "core/session/report.h"

namespace flexarm {

Report fleetReport(const FleetRunResult& run, const std::string& manifest, const std::string& store);

// The plot of one parameter of an axis over days (relative change in %, estimates with
// +-2 std bands, the fitted level, the threshold and the predicted crossing for the wear
// parameter); the panel draws the same series.
ReportPlot fleetTrendPlot(const FleetAxisReport& axis, const ParameterSeries& series, double threshold);
// The axis' temperature over days.
ReportPlot fleetTemperaturePlot(const FleetAxisReport& axis);

}  // namespace flexarm
