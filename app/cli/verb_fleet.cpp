// flexarm fleet MANIFEST --db FLEET.sqlite [--engine local|slurm] [--jobs N] [--model M]
//               [--report fleet.pdf|html] [--json]
// flexarm fleet --task CHUNK.json --out RESULT.json      (one Slurm array task)
// flexarm simulate --fleet DIR --robots N --days D ...    (the simulated plant)
#include "core/common/text.h"
#include "app/cli/verb_fleet.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>
#include <unistd.h>

#include "app/cli/verb_run.h"
#include "core/fleet/engine.h"
#include "core/fleet/fleet_report.h"
#include "core/fleet/plant.h"

namespace flexarm::cli {
namespace {

const char* kFleetHelp =
    "Usage: flexarm fleet MANIFEST --db FLEET.sqlite [--engine local|slurm] [--jobs N]\n"
    "                     [--model three-mass] [--report fleet.pdf|fleet.html] [--json]\n\n"
    "Monitors every robot's axes over days. MANIFEST (# flexarm-fleet: 1; columns robot, axis,\n"
    "time, log, temperature_c, role) lists the daily logs; each axis' reference is the log with\n"
    "role 'reference', else its earliest. Every log the store does not hold yet (by the SHA-256\n"
    "of its bytes and of its reference) is diagnosed against its axis' reference as `flexarm\n"
    "diagnose` does (chapters 6-7: recursive estimates of k_T, J_a, f_m, the tests, the verdict)\n"
    "and stored in FLEET.sqlite, in batches, so a run that is stopped keeps what it stored and a\n"
    "rerun only adds what is new. Then each axis' trend: a step (a fault in k_T, J_a or f_m) or\n"
    "a drift (wear: f_m rising), f_m compared at the reference log's temperature, with the day\n"
    "it began, the slope per day with its 99 % interval and the days until the threshold.\n\n"
    "Options:\n"
    "  --db FILE             the store (SQLite, created when absent; on a local disk)\n"
    "  --engine E            local (default): threads on this machine; slurm: a Slurm job array\n"
    "  --jobs N              local threads (default: one per core)\n"
    "  --model M             the physical model (default three-mass)\n"
    "  --threshold F         relative rise of f_m that calls for service (default 0.2)\n"
    "  --next-stop DAYS      axes reaching the threshold within DAYS are to be serviced at the\n"
    "                        next stop (default 14)\n"
    "  --alpha A             f_m's relative change per degC, when known (default: estimated from\n"
    "                        each axis' healthy logs)\n"
    "  --limit N             analyse at most N new logs in this run (N >= 1)\n"
    "  --max-rows N          refuse a manifest of more than N rows (default 500000)\n"
    "  --allow-logs-outside  read logs outside the manifest's folder too (by default a row\n"
    "                        naming ../x, /etc/... or a link leading out is refused)\n"
    "  --report FILE         write the fleet report (.pdf or .html)\n"
    "  --json                print the result as JSON\n\n"
    "Slurm (--engine slurm): the logs go out in chunks, one array task each, run as\n"
    "`flexarm fleet --task CHUNK.json --out RESULT.json` on the nodes; results come back as\n"
    "files and this process alone writes the store. The chunks' folder must be visible to the\n"
    "nodes at the same path, and so must the logs and this flexarm.\n"
    "  --slurm-dir DIR       folder for chunks and results (default FLEET.sqlite.slurm)\n"
    "  --logs-per-task N     logs per array task (default 64)\n"
    "  --max-tasks N         tasks running at once (the array's %N; default: no limit)\n"
    "  --sbatch-arg ARG      passed to sbatch (repeatable), e.g. --sbatch-arg=--partition=night\n"
    "  --slurm-timeout S     cancel the array after S seconds (default 21600)\n"
    "  --flexarm PATH        the flexarm the tasks run (default: this one)\n\n"
    "JSON: axes [{robot, axis, status (healthy, drift, fault), parameter, since, trend,\n"
    "days_to_threshold, evidence, suggestion}], maintenance (the axes to service at the next\n"
    "stop), analysed, skipped, failed, failures [{robot, axis, time, log, message}], seconds.\n"
    "Exit status 0 also when some logs failed (they are listed); 3 for an unreadable manifest.\n";

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string selfExecutable() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("flexarm") : p.string();
}

std::string axisLine(const FleetAxisReport& a) {
  const auto& t = a.trend;
  std::string s = a.robot + " axis " + std::to_string(a.axis) + ": " + t.status;
  if (!t.parameter.empty()) s += " in " + t.parameter;
  s += " (" + std::to_string(a.logs) + " logs). " + t.evidence;
  if (t.status != "healthy") s += " Suggestion: " + t.suggestion + ".";
  return s;
}

}  // namespace

int runFleet(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args({"json", "help", "allow-logs-outside"},
                 {"db", "engine", "jobs", "model", "threshold", "next-stop", "alpha", "limit", "max-rows", "report", "task",
                  "out", "slurm-dir", "logs-per-task", "max-tasks", "sbatch-arg", "slurm-timeout", "flexarm"});
  const std::string pre = "flexarm fleet: ";
  auto usage = [&](const std::string& why) {
    err << pre << why << "\n(flexarm fleet --help explains the options)\n";
    return kExitUsage;
  };
  if (!args.parse(argv)) return usage(args.error());
  if (args.flag("help")) {
    out << kFleetHelp;
    return kExitOk;
  }
  std::string why;
  if (auto task = args.value("task")) {
    const auto result = args.value("out");
    if (!result) return usage("--task needs --out RESULT.json");
    if (!runFleetTask(*task, *result, &why)) {
      err << pre << why << "\n";
      return kExitBadInput;
    }
    return kExitOk;
  }
  if (args.positional().size() != 1) return usage("expected exactly one MANIFEST");
  const auto db = args.value("db");
  if (!db) return usage("--db FLEET.sqlite is required");
  const auto reportPath = args.value("report");
  if (reportPath && !endsWith(*reportPath, ".pdf") && !endsWith(*reportPath, ".html"))
    return usage("--report must name a .pdf or .html file, not " + inQuotes(*reportPath));
  if (reportPath && !reportRenderer())
    return usage("this build has no report rendering (it was built without the GUI); use --json");

  FleetOptions o;
  if (auto e = args.value("engine")) {
    auto engine = fleetEngineFromString(*e);
    if (!engine) return usage("--engine must be local or slurm, not " + inQuotes(*e));
    o.engine = *engine;
  }
  int logsPerTask = o.slurm.logsPerTask, maxTasks = 0;
  ManifestReadOptions readOptions;
  readOptions.allowLogsOutside = args.flag("allow-logs-outside");
  int maxRows = static_cast<int>(readOptions.maxRows);
  if (!args.integer("jobs", o.jobs, 0, 1024) || !args.integer("limit", o.limit, 1, 1 << 30) ||
      !args.integer("max-rows", maxRows, 1, 100000000) ||
      !args.integer("logs-per-task", logsPerTask, 1, 1000000) || !args.integer("max-tasks", maxTasks, 0, 1000000) ||
      !args.number("threshold", o.trend.threshold, 1e-3, 10.0) ||
      !args.number("next-stop", o.trend.nextStopDays, 0.0, 3650.0) ||
      !args.number("slurm-timeout", o.slurm.timeoutS, 1.0, 30 * 86400.0))
    return usage(args.error());
  readOptions.maxRows = static_cast<std::size_t>(maxRows);
  o.slurm.logsPerTask = logsPerTask;
  o.slurm.maxTasksAtOnce = maxTasks;
  if (auto a = args.value("alpha")) {
    FrictionTemperatureModel m;
    if (!args.number("alpha", m.alpha)) return usage(args.error());
    o.trend.temperature = m;  // T_ref: set per axis from its reference log
  }
  if (auto m = args.value("model")) o.analysis.model = *m;
  o.slurm.executable = args.value("flexarm").value_or(selfExecutable());
  if (auto d = args.value("slurm-dir")) o.slurm.workDir = *d;
  o.slurm.sbatchArguments = args.values("sbatch-arg");
  if (!o.isValid(&why)) return usage(why);

  ManifestError merr;
  const auto manifest = readFleetManifest(args.positional()[0], &merr, readOptions);
  if (!manifest) {
    err << pre << merr.toString() << "\n";
    return kExitBadInput;
  }
  auto store = FleetStore::open(*db, true, &why);
  if (!store) {
    err << pre << why << "\n";
    return kExitBadInput;
  }
  if (const auto model = store->meta("model"); model && *model != o.analysis.model)
    return usage(*db + " holds " + *model + " analyses; give --model " + *model + " or another --db");
  const FleetRunResult run = flexarm::runFleet(*manifest, *store, o);
  if (run.termination != Termination::Converged) {
    err << pre << run.message << "\n";
    return kExitNumerical;
  }
  if (reportPath) {
    const Report report = fleetReport(run, manifest->path, *db);
    if (!reportRenderer()(report, *reportPath, &why)) {
      err << pre << why << "\n";
      return kExitBadInput;
    }
  }
  if (args.flag("json")) {
    auto j = fleetRunJson(run);
    j["logs_outside_allowed"] = readOptions.allowLogsOutside;
    out << j.dump(2) << "\n";
  } else {
    out << run.message << " in " << run.seconds << " s (" << toString(run.engine) << " engine).\n";
    if (readOptions.allowLogsOutside) out << "Logs outside the manifest's folder were allowed (--allow-logs-outside).\n";
    for (std::size_t i = 0; i < std::min(run.failures.size(), kListedFailures); ++i)
      out << "failed: " << run.failures[i].log << ": " << run.failures[i].message << "\n";
    if (run.failures.size() > kListedFailures)
      out << "... and " << run.failures.size() - kListedFailures << " more failures (--json counts them)\n";
    for (const auto& a : run.axes) out << axisLine(a) << "\n";
  }
  return kExitOk;
}

int runSimulateFleet(ArgParser& args, std::ostream& out, std::ostream& err) {
  auto usage = [&](const std::string& why) {
    err << "flexarm simulate: " << why << "\n(flexarm simulate --help explains the options)\n";
    return kExitUsage;
  };
  FleetSimulationOptions o;
  long seed = 1;
  if (!args.integer("robots", o.robots, 1, 10000) || !args.integer("axes", o.axes, 1, 12) ||
      !args.integer("days", o.days, 2, 3650) || !args.integer("seed", seed) ||
      !args.integer("wear", o.wear, 0, 1000000) || !args.integer("loads", o.loads, 0, 1000000) ||
      !args.integer("faults", o.faults, 0, 1000000) || !args.integer("jobs", o.jobs, 0, 1024) ||
      !args.number("duration", o.durationS) || !args.number("rate", o.logRateHz) ||
      !args.number("alpha", o.alpha) || !args.number("temperature-swing", o.temperatureSwingC) ||
      !args.number("amplitude", o.amplitudeRad))
    return usage(args.error());
  if (seed < 0) return usage("--seed must be >= 0");
  o.seed = static_cast<std::uint64_t>(seed);
  if (auto s = args.value("start")) o.startDate = *s;
  std::string why;
  if (!o.isValid(&why)) return usage(why);
  const auto r = simulateFleet(*args.value("fleet"), o);
  if (r.termination != Termination::Converged) {
    err << "flexarm simulate: " << r.message << "\n";
    return kExitBadInput;
  }
  if (args.flag("json"))
    out << nlohmann::json{{"manifest", r.manifest}, {"truth", r.truth}, {"logs", r.logs}, {"seconds", r.seconds}}.dump(2)
        << "\n";
  else
    out << r.message << "\n";
  return kExitOk;
}

}  // namespace flexarm::cli

namespace flexarm::cli {

const char* kSimulateFleetHelp =
    "\nA simulated plant (--fleet DIR): robots whose axes each log a daily test routine\n"
    "(multisine, --amplitude 0.2 rad, --duration 12 s at --rate 1000 Hz) for --days days, with\n"
    "DIR/manifest.csv (the fleet manifest) and DIR/truth.json (what happened to each axis):\n"
    "  --fleet DIR           write the plant here (with --robots, --days; no --out)\n"
    "  --robots N, --axes N  robots, and axes per robot (default 4 and 1)\n"
    "  --days D              daily logs per axis (default 30); --start YYYY-MM-DD the first\n"
    "  --wear N              axes whose f_m rises 2 %/day from a day in the middle third (1)\n"
    "  --loads N             axes whose J_a steps up 25 % (a heavier load) (1)\n"
    "  --faults N            axes whose k_T steps up 20 % (1)\n"
    "  --temperature-swing C the cell's temperature swings +-C degC about 25 weekly (10)\n"
    "  --alpha A             f_m's relative change per degC (0.01)\n"
    "  --seed N, --jobs N    random seed; threads (default one per core)\n";

}  // namespace flexarm::cli
