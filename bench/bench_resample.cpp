// Decimation and rational resampling of a 10-minute, 2 kHz, three-channel log: FlexArm
// against SciPy (bench/peer_resample.py) on the same numbers in one run, medians of repeats.
// Prints one JSON line per task on stdout:
//   {"task", "size", "flexarm_s", "peer", "peer_s", "agree", "flexarm_cpu_s", "peer_cpu_s"}
// Times are medians of 7 runs: wall clock (FlexArm uses every core, SciPy one) and, as the
// machine may be shared, processor time of the whole process.
// agree: away from the ends (where the filters meet the padding), every output of FlexArm lies
// within 5e-3 of the channel's peak of SciPy's. Their anti-alias filters differ: FlexArm's FIR
// passes to 0.8 of the new Nyquist frequency within 1e-4 and stops 80 dB; SciPy's decimate FIR
// (201 Hamming taps) is itself off the ideal by 3e-3 on this log's chirp, resample_poly (Kaiser,
// beta 5) by 5e-4.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <ctime>
#include <unistd.h>

#include "core/signal/preprocess.h"

using namespace flexarm;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kRepeats = 7;

double processSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The log of bench_log: reference chirp, motor angle, torque with a 211 Hz component.
IdData makeLog(double rate, std::size_t n) {
  IdData d;
  d.sampleTime = 1.0 / rate;
  std::vector<double> angle(n), torque(n), ref(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * 0.0005;  // the content of a 2 kHz log
    ref[i] = 0.05 * std::sin(2 * kPi * (0.5 + 0.02 * t) * t);
    angle[i] = ref[i] + 1e-4 * std::sin(2 * kPi * 17 * t);
    torque[i] = 0.1 * std::cos(2 * kPi * 3.1 * t) + 0.01 * std::sin(2 * kPi * 211 * t);
  }
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, angle});
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, torque});
  d.setChannel({columns::kAngleRef, "", ChannelRole::Reference, ref});
  d.setMeta("sample_rate_hz", std::to_string(static_cast<int>(rate)));
  return d;
}

struct Task {
  std::string name, label, peer;
  double rate;  // of the input
  std::function<IdData(const IdData&)> run;
};

bool agree(const IdData& ours, const std::vector<double>& peer, std::size_t skip, double* worstOut) {
  const std::size_t channels = ours.channels.size();
  if (channels == 0 || peer.size() % channels != 0) return false;
  const std::size_t m = peer.size() / channels;
  const std::size_t n = std::min(m, ours.samples());
  double worst = 0.0;
  for (std::size_t c = 0; c < channels; ++c) {
    double peak = 0.0, diff = 0.0;
    for (std::size_t k = skip; k + skip < n; ++k) {
      peak = std::max(peak, std::abs(peer[c * m + k]));
      diff = std::max(diff, std::abs(ours.channels[c].values[k] - peer[c * m + k]));
    }
    worst = std::max(worst, diff / std::max(peak, 1e-300));
  }
  *worstOut = worst;
  return worst <= 5e-3;
}

}  // namespace

int main() {
  namespace fs = std::filesystem;
  const std::size_t n = 2000 * 600;
  std::string dirTemplate = (fs::temp_directory_path() / "flexarm_bench_resample_XXXXXX").string();
  if (!mkdtemp(dirTemplate.data())) return 1;
  const fs::path dir = dirTemplate;

  auto resampleTo = [](double rate) {
    return [rate](const IdData& d) {
      UniformGridOptions o;
      o.rateHz = rate;
      return resampleToUniform(d, o).data;
    };
  };
  const std::vector<Task> tasks = {
      {"decimate10", "decimate x10 (FIR, zero phase), 2000 -> 200 Hz",
       "scipy.signal.decimate(ftype='fir', zero_phase=True)", 2000.0,
       [](const IdData& d) {
         DecimateOptions o;
         o.factor = 10;
         return decimate(d, o);
       }},
      {"resample_3_4", "resample 2000 -> 1500 Hz", "scipy.signal.resample_poly(up=3, down=4)", 2000.0, resampleTo(1500)},
      {"resample_2_1", "resample 1000 -> 2000 Hz", "scipy.signal.resample_poly(up=2, down=1)", 1000.0, resampleTo(2000)},
  };

  // The input for the peer: the same numbers, channel after channel.
  const IdData data2k = makeLog(2000.0, n);
  {
    std::ofstream out(dir / "data.f64", std::ios::binary);
    for (const auto& c : data2k.channels)
      out.write(reinterpret_cast<const char*>(c.values.data()), static_cast<std::streamsize>(c.values.size() * sizeof(double)));
  }
  std::map<std::string, double> flexSeconds, flexCpu;
  std::map<std::string, IdData> results;
  for (const auto& task : tasks) {
    IdData input = data2k;
    input.sampleTime = 1.0 / task.rate;
    input.setMeta("sample_rate_hz", std::to_string(static_cast<int>(task.rate)));
    std::vector<double> times, cpu;
    for (int r = 0; r < kRepeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = processSeconds();
      IdData y = task.run(input);
      cpu.push_back(processSeconds() - c0);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      if (r == 0) results[task.name] = std::move(y);
    }
    flexSeconds[task.name] = median(times);
    flexCpu[task.name] = median(cpu);
  }

  const std::string cmd = std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR + "/peer_resample.py " +
                          (dir / "data.f64").string() + " 3 " + std::to_string(n) + " " + dir.string() + " " +
                          std::to_string(kRepeats);
  std::map<std::string, double> peerSeconds, peerCpu;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char name[64];
    double s = 0.0, c = 0.0;
    while (std::fscanf(p, "%63s %lf %lf", name, &s, &c) == 3) {
      peerSeconds[name] = s;
      peerCpu[name] = c;
    }
    pclose(p);
  }
  int status = 0;
  for (const auto& task : tasks) {
    nlohmann::json row = {{"task", task.label},
                          {"size", std::to_string(n) + " samples x 3 channels"},
                          {"flexarm_s", flexSeconds[task.name]},
                          {"peer", task.peer}};
    const auto it = peerSeconds.find(task.name);
    if (it == peerSeconds.end()) {
      row["peer_s"] = nullptr;
      row["agree"] = nullptr;
      std::fprintf(stderr, "%s: the peer did not run (python3-scipy installed?)\n", task.label.c_str());
      status = 1;
    } else {
      std::vector<double> peer(fs::file_size(dir / (task.name + ".f64")) / sizeof(double));
      std::ifstream in(dir / (task.name + ".f64"), std::ios::binary);
      in.read(reinterpret_cast<char*>(peer.data()), static_cast<std::streamsize>(peer.size() * sizeof(double)));
      double worst = 0.0;
      const bool same = agree(results[task.name], peer, 2000, &worst);
      row["peer_s"] = it->second;
      row["agree"] = same;
      row["flexarm_cpu_s"] = flexCpu[task.name];
      row["peer_cpu_s"] = peerCpu[task.name];
      std::fprintf(stderr,
                   "%-48s FlexArm %.4f s, SciPy %.4f s, ratio %.1fx (processor time %.1fx), "
                   "largest difference %.1e of the peak\n",
                   task.label.c_str(), flexSeconds[task.name], it->second, it->second / flexSeconds[task.name],
                   peerCpu[task.name] / flexCpu[task.name], worst);
    }
    std::printf("%s\n", row.dump().c_str());
  }
  if (!std::getenv("FLEXARM_BENCH_KEEP")) fs::remove_all(dir);
  return status;
}
