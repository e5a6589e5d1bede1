#pragma once
// A fit result in words, for people: the lines `flexarm fit` prints and the summary the Fit panel
// shows (the same facts as fitResultJson, core/ident/fit_json.h). The panel adds what is its
// own (the name the estimate takes in the model list).
#include <string>
#include <vector>

#include "core/ident/fit.h"
#include "core/ident/fit_json.h"

namespace flexarm {

// `flexarm fit` without --json: how it ended, the data, the method, the parameter table, loss,
// fit % both ways (each experiment's when there are several), the deflection check, warnings,
// notches and peaks; one line each.
std::string fitResultText(const FitResult& fit, const FitLogNames& logs);

// The Fit panel's summary of an estimate named `name`: how and how fast it ended, the method
// and controller, loss, FPE and AIC, fit % both ways (each experiment's, its log's file name,
// when there are several), notches and peaks, the deflection check, implausible values, the
// start and the notes; a sentence each.
std::vector<std::string> fitSummaryLines(const FitResult& fit, const std::string& name, const FitLogNames& logs);

// Frequencies as the summaries list them: "101.5, 160.2 rad/s", or "none".
std::string frequencyList(const std::vector<double>& omega);

}  // namespace flexarm
