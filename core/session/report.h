#pragma once
// A report as data: sections of paragraphs, tables and plots with the numbers behind them.
// The replay fills it without Qt; the window and `flexarm run` render it to HTML or PDF
// (app/report_writer.h), and `flexarm run --json` prints toJson(), so the numbers in the
// document and in the JSON are the same values.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace flexarm {

struct ReportTable {
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct ReportSeries {
  std::string name;
  std::vector<double> x, y;
  bool dashed = false;
  int color = -1;  // palette index; -1: by the series' position (bounds share a colour)
};

struct ReportPlot {
  std::string title, xLabel, yLabel;
  bool logX = false, logY = false;
  std::vector<ReportSeries> series;
  // Series are curves in the plane (x need not increase), e.g. a Nyquist curve.
  bool parametric = false;
  // Axis ranges to show; unset: every point.
  std::optional<std::pair<double, double>> xRange = std::nullopt, yRange = std::nullopt;
};

struct ReportSection {
  std::string title;
  std::vector<std::string> paragraphs;
  std::vector<ReportTable> tables;
  std::vector<ReportPlot> plots;
  nlohmann::json values = nlohmann::json::object();  // the section's numbers for --json
};

struct ReportLog {
  std::string name, path, sha256;
  std::string note;  // e.g. "substituted" or "changed since the session was saved"
};

struct Report {
  std::string title = "FlexArm report";
  std::string flexarmVersion;
  std::string session;  // the session file
  std::vector<ReportLog> logs;
  std::vector<std::string> warnings;
  std::vector<ReportSection> sections;

  // Provenance, warnings and every section's title and values (no plot data).
  nlohmann::json toJson() const;
};

// Keeps at most n points of a series, evenly strided, for plots.
void thinSeries(std::vector<double>& x, std::vector<double>& y, std::size_t n);

// Fixed-point text with `decimals` digits, as reports print fit % ("87.31").
std::string formatFixed(double v, int decimals);
// Text with `digits` significant digits, as reports print parameters ("0.005347").
std::string formatSignificant(double v, int digits = 4);

}  // namespace flexarm
