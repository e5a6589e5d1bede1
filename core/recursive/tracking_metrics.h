#pragma once
// How well a recursive estimate follows a parameter whose truth is known (a simulated log):
// the measures the tracking options (RecursiveTracking) are compared by on steps and slow
// ramps (the seed's 9.2).
#include <cstddef>
#include <functional>

#include "core/recursive/rpem.h"

namespace flexarm {

struct TrackingMetrics {
  // Time from the moment the truth passed halfway between its value before and after the
  // change until the estimate passed it too (s); infinity when it never did. Without a
  // change: 0.
  double delayS = 0.0;
  // RMS of estimate / truth - 1 over the samples from `from` on.
  double rmsError = 0.0;
  // Excursions: how often the estimate left the band of +-band (relative) around the truth
  // while the truth had not yet moved (the false alarms of a plain threshold at that band).
  int excursions = 0;
};

// theta: the estimate's trajectory of one parameter; truth(t): its true value (theta's form).
// change: the truth's value before (before) and after (after) a change, with before == after
// for none. Throws std::invalid_argument when the lengths differ.
TrackingMetrics trackingMetrics(const std::vector<double>& time, const std::vector<double>& theta,
                                const std::function<double(double)>& truth, double before,
                                double after, double from, double band);

}  // namespace flexarm
