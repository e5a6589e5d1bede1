// flexarm run SESSION.json [--log NAME=PATH ...] [--report OUT.pdf|OUT.html] [--json]
#include "app/cli/verb_run.h"

#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "core/session/replay.h"
#include "core/session/session.h"

namespace flexarm::cli {
namespace {

ReportRenderer gRenderer = nullptr;

OptionTable runTable() {
  OptionTable t("flexarm run SESSION.json [--log NAME=PATH ...] [--report OUT.pdf|OUT.html] [--json]",
                "Replays a saved session without a window: reads its logs (checking their SHA-256), applies its "
                "preprocessing and ranges, recomputes every part (models, fits, discovery, the LQG design) and "
                "writes the report. At least one of --report and --json is needed.");
  t.add(textOption("log", "NAME=PATH", "use PATH instead of the session's log NAME, e.g. tomorrow's log of the "
                                       "same experiment",
                   true))
      .add(textOption("report", "FILE", "write the report: .pdf (vector plots) or .html (self-contained, plots "
                                        "embedded as images)"))
      .add(flagOption("json", "print the report's provenance and numbers as JSON"));
  return t;
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

void setReportRenderer(ReportRenderer renderer) { gRenderer = renderer; }
ReportRenderer reportRenderer() { return gRenderer; }

int runRun(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(runTable());
  if (auto rc = parseArguments(args, argv, "run", out, err)) return *rc;
  if (args.positional().size() != 1) {
    err << "flexarm run: expected exactly one SESSION.json\n" << args.table().help();
    return kExitUsage;
  }
  const auto reportPath = args.value("report");
  if (!reportPath && !args.flag("json")) {
    err << "flexarm run: give --report OUT.pdf|OUT.html, --json, or both\n";
    return kExitUsage;
  }
  if (reportPath && !endsWith(*reportPath, ".pdf") && !endsWith(*reportPath, ".html")) {
    err << "flexarm run: --report must name a .pdf or .html file, not '" << *reportPath << "'\n";
    return kExitUsage;
  }
  if (reportPath && !gRenderer) {
    err << "flexarm run: this build has no report rendering (it was built without the GUI); "
           "use --json\n";
    return kExitUsage;
  }
  ReplayOptions options;
  for (const auto& spec : args.values("log")) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
      err << "flexarm run: --log needs NAME=PATH, not '" << spec << "'\n";
      return kExitUsage;
    }
    options.substitutes[spec.substr(0, eq)] = spec.substr(eq + 1);
  }
  const std::string sessionPath = args.positional().front();
  SessionParseResult loaded = loadSession(sessionPath);
  if (!loaded.ok) {
    err << "flexarm run: " << loaded.message << "\n";
    return kExitBadInput;
  }
  ReplayResult r = replaySession(loaded.session, sessionPath, options);
  if (r.termination != Termination::Converged) {
    err << "flexarm run: " << sessionPath << ": " << r.message << "\n";
    return r.badInput ? kExitBadInput : kExitNumerical;
  }
  for (const auto& w : r.report.warnings) err << "flexarm run: warning: " << w << "\n";
  if (reportPath) {
    std::string why;
    if (!gRenderer(r.report, *reportPath, &why)) {
      err << "flexarm run: cannot write the report: " << why << "\n";
      return kExitBadInput;
    }
  }
  if (args.flag("json")) {
    nlohmann::json j = r.report.toJson();
    j["seconds"] = r.seconds;
    if (reportPath) j["report"] = *reportPath;
    out << j.dump(2) << "\n";
  } else {
    out << "wrote " << *reportPath << " (" << r.report.sections.size() << " sections)\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
