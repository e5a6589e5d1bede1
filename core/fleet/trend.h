#pragma once
// One axis over days: the per-log estimates of k_T, J_a and f_m (relative to the axis'
// theta_0) as series in time, and what changed in them. A step is a fault (k_T: the motor or
// its drive; J_a: a load change; f_m: a sudden friction change), a drift is wear (f_m rising
// day by day). Gearbox friction moves with temperature more than with wear, so f_m is brought
// to the reference log's temperature first with f_m = f_m0 (1 + alpha (T - T_ref)), alpha
// estimated from the axis' healthy logs (core/diagnosis/friction_temperature.h) or given.
//
// A step is the split of the series into two levels with the largest t statistic; a drift is
// the hinge y = a + b max(0, t - t0) with the smallest residual; each is scanned over every
// possible start and called only when it stands out of the axis' own log-to-log scatter by a
// margin that the scan over starts cannot reach by chance (TrendOptions).
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis/friction_temperature.h"
#include "core/fleet/log_analysis.h"

namespace flexarm {

struct TrendPoint {
  double day = 0.0;                   // days since the epoch
  std::optional<double> temperatureC;
  std::string verdict = "none";       // the log's own chapter-7 verdict
  std::vector<FleetEstimate> estimates;
};

struct TrendOptions {
  std::vector<std::string> parameters = {"k_T", "J_a", "f_m"};
  std::string wearParameter = "f_m";  // the one whose drift is wear
  // A step must exceed stepZ standard errors of the difference of the two levels and be at
  // least minStep (relative) to be a fault.
  double stepZ = 6.0;
  double minStep = 0.05;
  // A drift's slope must exceed driftZ standard errors, and the rise since it began minStep.
  double driftZ = 5.0;
  // Relative rise of the wear parameter (at the reference temperature) that calls for service:
  // the 20 % of the seed's faults (chapter 7).
  double threshold = 0.2;
  // Axes whose threshold falls within this many days are to be serviced at the next stop.
  double nextStopDays = 14.0;
  int minLogs = 6;   // logs an axis needs before its trend is judged
  int minAfter = 2;  // logs after a step's or a drift's start before it is called
  // The friction temperature coefficient, when known; else estimated from healthy logs.
  std::optional<FrictionTemperatureModel> temperature;
  bool isValid(std::string* why) const;
};

// One parameter of an axis over days; values relative to theta_0 (value / theta_0 - 1), the
// wear parameter at the reference temperature.
struct ParameterSeries {
  std::string name;
  double reference = 0.0;                // theta_0, model units
  std::vector<double> day, value, std;   // relative
  std::vector<double> raw;               // the estimates as the logs gave them, model units
  std::vector<std::optional<double>> temperatureC;
  double scatter = 0.0;                  // log-to-log std, relative
  std::string kind = "none";             // none, step, drift
  std::optional<double> since;           // day the change began (the first log showing a step)
  double size = 0.0;                     // step: the change of level, relative
  double z = 0.0;                        // the change in standard errors
  double slope = 0.0, slopeLow = 0.0, slopeHigh = 0.0;  // drift: relative per day, 99 %
  double level = 0.0;                    // the fitted value at the last log, relative
  double levelSe = 0.0;                  // its standard error (drift: with alpha's at that log)
  double quantile = 2.5758;              // of the 99 % intervals (Student's t of the scatter)
  std::vector<double> fitted;            // the fitted levels at each day, relative
};

struct AxisTrend {
  std::string status = "healthy";        // healthy, drift, fault
  std::string parameter;                 // the changed parameter (empty when healthy)
  std::optional<double> since;           // day the change began
  std::optional<double> slopePerDay, slopeLow, slopeHigh;  // relative per day (drift), 99 %
  std::optional<double> stepSize;        // relative (fault)
  std::optional<double> daysToThreshold, daysLow, daysHigh;  // from the last log; 99 %
  std::optional<double> crossingDay;
  double threshold = 0.0;
  double lastDay = 0.0;
  int logs = 0;
  std::string evidence;                  // sentences: what was found and how sure
  std::string suggestion;                // what to do at the next maintenance stop
  std::string caveat;                    // what the sizes are of (set when something changed)
  bool serviceAtNextStop = false;
  FrictionTemperatureFit temperature;    // alpha as used (estimated or given)
  std::optional<double> referenceTemperatureC;
  std::vector<ParameterSeries> series;   // options.parameters order
  const ParameterSeries* find(const std::string& name) const;
};

// The trend of one axis from its analysed logs (any order; the reference log among them).
// Throws std::invalid_argument for invalid options.
AxisTrend analyseAxisTrend(const std::vector<TrendPoint>& points,
                           std::optional<double> referenceTemperatureC, const TrendOptions& options);

}  // namespace flexarm
