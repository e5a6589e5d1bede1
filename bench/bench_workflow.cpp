// Whole workflows as a user runs them from the command line, timed end to end (wall clock,
// parallel parts included): discovery of the missing effect on the torque-ripple log
// (`flexarm discover`, three-mass base, every named effect), the discovery loop
// (`flexarm discover --until-none`) on a 12 s, 2 kHz log pair the simulator makes with three
// hidden effects (Coulomb friction, backlash, torque ripple), and the replay of the sample
// session (`flexarm run sample_logs/sample_session.json`: preprocessing, a three-mass fit,
// SPA, discovery on a log pair, LQG). No peer has these workflows, so the rows give FlexArm's
// time and how much faster than real time (the logs' duration over the time) it is; the
// agreement column says whether the result is the known truth.
#include <set>

#include "bench_common.h"
#include "core/io/log_io.h"

using namespace flexarm;
using namespace flexarm::bench;

namespace {

double logSeconds(const std::string& path) {
  const LogReadResult r = readLog(path);
  return r.ok ? r.data.duration() : 0.0;
}

}  // namespace

int main() {
  const std::string src = FLEXARM_SOURCE_DIR;
  const std::string exe = FLEXARM_EXECUTABLE;
  const std::string ripple = src + "/sample_logs/effect_torque_ripple.csv";
  {
    bool ok = true;
    std::string out;
    const double t = medianSeconds(1, [&] {
      out = capture(exe + " discover " + ripple + " --model three-mass --json", &ok);
    }, true);
    Row row;
    row.group = "workflows";
    row.task = "discovery, torque-ripple log";
    const double secs = logSeconds(ripple);
    row.size = std::to_string(static_cast<int>(std::lround(secs))) + " s of log at 2 kHz, 6 effects";
    row.flexarmSeconds = t;
    row.peer = "none (no peer has it)";
    row.extra["times_real_time"] = secs / t;
    std::string effect;
    try {
      const auto j = Json::parse(out.substr(out.find('{')));
      effect = j.value("effect", Json()).is_string() ? j["effect"].get<std::string>() : "none";
    } catch (const std::exception&) {
      ok = false;
    }
    row.agree = ok && effect == "torque_ripple";
    std::ostringstream s;
    s.precision(2);
    s << "names " << (ok ? effect : "nothing (failed)") << ", the log's truth is torque_ripple; "
      << secs / t << "x real time";
    row.agreement = s.str();
    emit(row);
  }
  {
    // The log pair: a three-mass arm (Table 5.7 p6) with three effects, the motor turning at
    // 5 rad/s under a 0.2 rad chirp (estimation) and a 0.2 rad multisine (validation).
    const TempDir tmp("flexarm_bench_loop");
    const std::string dir = tmp.path().string();
    const std::string effects = " --model three-mass --effect coulomb_friction:0.1 --effect backlash:4e-4"
                                " --effect torque_ripple:0.1 --reference-velocity 5 --amplitude 0.2 --duration 12";
    bool ok = true;
    capture(exe + " simulate" + effects + " --excitation chirp --seed 21 --out " + dir +
                "/est.csv && " + exe + " simulate" + effects + " --excitation multisine --seed 22 --out " + dir +
                "/val.csv",
            &ok);
    std::string out;
    const double cpu0 = childCpuSeconds();
    const double t = medianSeconds(1, [&] {
      out = capture(exe + " discover " + dir + "/est.csv --validation-log " + dir +
                        "/val.csv --model three-mass --until-none --json",
                    &ok);
    }, true);
    Row row;
    row.group = "workflows";
    row.task = "discovery loop (--until-none), three hidden effects";
    row.size = "12 s log pair at 2 kHz, 6 candidates";
    row.flexarmSeconds = t;
    row.peer = "none (no peer has it)";
    row.extra["times_real_time"] = 24.0 / t;
    // The process's own CPU seconds: on a shared machine the wall clock also counts the
    // time others were given, and the work is at most this on two free cores.
    const double cpu = childCpuSeconds() - cpu0;
    row.extra["cpu_seconds"] = cpu;
    std::set<std::string> found;
    try {
      const auto j = Json::parse(out.substr(out.find('{')));
      for (const auto& e : j["effects"]) found.insert(e["effect"].get<std::string>());
    } catch (const std::exception&) {
      ok = false;
    }
    const std::set<std::string> truth{"coulomb_friction", "backlash", "torque_ripple"};
    row.agree = ok && found == truth && t < 30.0;
    std::ostringstream s;
    s.precision(3);
    s << "names";
    for (const auto& f : found) s << " " << f;
    if (found.empty()) s << " nothing";
    s << ", the logs' truth is backlash coulomb_friction torque_ripple; " << t << " s (" << cpu << " s of CPU) against the 30 s target";
    row.agreement = s.str();
    emit(row);
  }
  {
    bool ok = true;
    std::string out;
    const double t = medianSeconds(1, [&] {
      out = capture("cd " + src + " && " + exe + " run sample_logs/sample_session.json --json", &ok);
    }, true);
    Row row;
    row.group = "workflows";
    row.task = "sample session replay (flexarm run)";
    const double secs = logSeconds(src + "/sample_logs/three_mass_estimation_chirp.csv") + logSeconds(ripple);
    row.size = std::to_string(static_cast<int>(std::lround(secs))) + " s of logs, 4 parts";
    row.flexarmSeconds = t;
    row.peer = "none (no peer has it)";
    row.extra["times_real_time"] = secs / t;
    row.agree = ok;
    std::ostringstream s;
    s.precision(2);
    s << (ok ? "replayed without a failure" : "the replay failed") << "; " << secs / t << "x real time";
    row.agreement = s.str();
    emit(row);
  }
  return 0;
}
