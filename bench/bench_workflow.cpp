// Whole workflows as a user runs them from the command line, timed end to end (wall clock,
// parallel parts included): discovery of the missing effect on the torque-ripple log
// (`flexarm discover`, three-mass base, every named effect) and the replay of the sample
// session (`flexarm run sample_logs/sample_session.json`: preprocessing, a three-mass fit,
// SPA, discovery on a log pair, LQG). No peer has these workflows, so the rows give FlexArm's
// time and how much faster than real time (the logs' duration over the time) it is; the
// agreement column says whether the result is the known truth.
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
