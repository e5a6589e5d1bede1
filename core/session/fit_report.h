#pragma once
// The report section of a fit, one for every front end that reports one (the session part
// "fits" in `flexarm run` and the window's report): the model and how it was estimated, the
// data, the closed-loop method, notes, the parameter table (value +- std, 99 % interval), loss
// and fit % both ways, notches and peaks, the Bode plot with its band, measured against
// simulated output and the residual tests. Its values are {"name", "recomputed", "fit":
// fitResultJson (core/ident/fit_json.h) without the run's time}, so the report's data of a fit
// are the bytes `flexarm fit --json` prints for it, but for "seconds".
#include <string>

#include "core/ident/fit.h"
#include "core/ident/fit_json.h"
#include "core/session/fit_request.h"
#include "core/session/report.h"

namespace flexarm {

// The files of a request's experiments as a fit result names them: the analysed log (logName)
// over the request's estimation range and, with a validation range, again for validation;
// then its more experiments in order.
FitLogNames fitLogNamesOf(const FitRequest& request, const std::string& logName);

// The section of a request's run (run as runFitRequest returned it; request with the ranges it
// ran on). A run that gave no estimate says why in a sentence.
ReportSection fitReportSection(const FitRequest& request, const FitResult& run, const FitLogNames& logs);

// A fit made on other data than the open ones: what it computed then (the request's stored
// numbers), never a recompute; mismatch is the sentence saying how the data differ. Values
// {"name", "recomputed": false, "computed_on", "fit": storedFitToJson}.
ReportSection storedFitReportSection(const FitRequest& request, const std::string& mismatch);

// The non-parametric estimate of a run of FitModelKind::Spa: SPA (4.28) with its band,
// notches and peaks.
ReportSection spaReportSection(const FitResult& spa);

}  // namespace flexarm
