#include "core/fleet/plant.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/fleet/manifest.h"
#include "core/io/log_io.h"
#include "core/sim/closed_loop.h"
#include "core/sim/random.h"

namespace flexarm {

namespace {

using nlohmann::json;

struct AxisTruth {
  std::string robot;
  int axis = 0;
  std::string scenario = "healthy";  // healthy, wear, load, fault
  std::string parameter;             // f_m, J_a, k_T
  double startDay = 0.0;             // days after the first log
  double size = 0.0;                 // wear: per day; load, fault: the relative step
  double temperatureOffsetC = 0.0;
  std::map<std::string, double> parameters;  // the healthy arm at T_ref
  double referenceC = 0.0;           // temperature of the first (reference) log
};

std::string twoDigits(int v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%02d", v);
  return buf;
}

}  // namespace

bool FleetSimulationOptions::isValid(std::string* why) const {
  auto fail = [&](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (robots < 1 || robots > 10000) return fail("--robots must lie between 1 and 10000");
  if (axes < 1 || axes > 12) return fail("--axes must lie between 1 and 12");
  if (days < 2 || days > 3650) return fail("--days must lie between 2 and 3650");
  if (static_cast<double>(robots) * axes * days > 1e6) return fail("more than a million logs");
  if (!parseIsoDay(startDate)) return fail("the start date '" + startDate + "' is not YYYY-MM-DD");
  if (!(durationS >= 2.0 && durationS <= 600.0)) return fail("a daily log lasts 2 to 600 s");
  if (!(logRateHz >= 200.0) || std::fmod(2000.0, logRateHz) != 0.0)
    return fail("the log rate must divide the controller's 2000 Hz and be at least 200 Hz");
  if (!(spread >= 0.0 && spread < 0.5)) return fail("the parameter spread must lie in [0, 0.5)");
  if (!(temperatureSwingC >= 0.0 && temperatureSwingC <= 40.0)) return fail("the temperature swing must lie in [0, 40] degC");
  if (!(std::abs(alpha) * (temperatureSwingC + 5.0) < 0.9)) return fail("alpha makes the friction vanish within the swing");
  if (wear < 0 || loads < 0 || faults < 0 || wear + loads + faults > robots * axes)
    return fail("more changed axes (wear, loads, faults) than axes");
  if (!(wearPerDay > 0.0 && wearPerDay < 0.2) || !(loadChange > -0.8 && loadChange < 4.0) ||
      !(faultSize > -0.8 && faultSize < 4.0))
    return fail("the wear rate, load change or fault size is out of range");
  if (!(amplitudeRad > 0.0 && amplitudeRad <= 2.0)) return fail("the amplitude must lie in (0, 2] rad");
  if (jobs < 0) return fail("--jobs must be 0 (one per core) or more");
  return true;
}

FleetSimulationResult simulateFleet(const std::string& dir, const FleetSimulationOptions& o,
                                    const ProgressCallback& progress) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("fleet simulation: " + why);
  const auto begin = std::chrono::steady_clock::now();
  FleetSimulationResult out;
  Random rng(o.seed);
  const auto base = makeModel("three-mass");
  const double day0 = std::floor(*parseIsoDay(o.startDate));

  // The axes, their arms, and which of them change.
  std::vector<AxisTruth> axes;
  for (int r = 1; r <= o.robots; ++r)
    for (int a = 1; a <= o.axes; ++a) {
      AxisTruth t;
      t.robot = "R" + twoDigits(r);
      t.axis = a;
      for (const char* name : {"J_m", "J_a", "k_g", "k_a", "f_m"})
        t.parameters[name] = base->value(name) * (1.0 + o.spread * (2.0 * rng.uniform() - 1.0));
      t.temperatureOffsetC = 2.0 * rng.uniform() - 1.0;
      axes.push_back(t);
    }
  std::vector<std::size_t> order(axes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (std::size_t i = order.size(); i > 1; --i)
    std::swap(order[i - 1], order[static_cast<std::size_t>(rng.uniform() * static_cast<double>(i))]);
  std::size_t next = 0;
  auto assign = [&](int count, const char* scenario, const char* parameter, double size) {
    for (int k = 0; k < count; ++k) {
      AxisTruth& t = axes[order[next++]];
      t.scenario = scenario;
      t.parameter = parameter;
      t.size = size;
      // The change begins in the middle third of the period, at a whole day for the steps.
      const double start = o.days / 3.0 + rng.uniform() * o.days / 3.0;
      t.startDay = std::string(scenario) == "wear" ? start : std::floor(start) + 0.5;
    }
  };
  assign(o.wear, "wear", "f_m", o.wearPerDay);
  assign(o.loads, "load", "J_a", o.loadChange);
  assign(o.faults, "fault", "k_T", o.faultSize);
  std::vector<double> phase(static_cast<std::size_t>(o.robots));
  for (auto& p : phase) p = 7.0 * rng.uniform();

  struct LogJob {
    std::size_t axis;
    int day;
    double temperature;
    std::uint64_t seed;
    FleetEntry entry;
  };
  std::vector<LogJob> jobs;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const std::size_t robot = static_cast<std::size_t>(std::stoi(axes[i].robot.substr(1)) - 1);
    for (int d = 0; d < o.days; ++d) {
      const double wave = std::sin(2.0 * M_PI * (d + phase[robot]) / 7.0);
      const double T = o.temperatureMeanC + axes[i].temperatureOffsetC +
                       std::clamp(0.85 * o.temperatureSwingC * wave + 0.1 * o.temperatureSwingC * rng.normal(),
                                  -o.temperatureSwingC + 1.0, o.temperatureSwingC - 1.0);
      const double T1 = std::round(T * 10.0) / 10.0;  // as the manifest writes it
      if (d == 0) axes[i].referenceC = T1;
      FleetEntry e;
      e.robot = axes[i].robot;
      e.axis = axes[i].axis;
      e.day = day0 + d + 0.25;
      e.time = isoFromDay(e.day);
      e.log = e.robot + "/ax" + std::to_string(e.axis) + "/" + e.time.substr(0, 10) + ".csv";
      e.temperatureC = T1;
      e.reference = d == 0;
      jobs.push_back({i, d, T1, rng.next(), e});
    }
  }

  std::error_code ec;
  std::atomic<std::size_t> cursor{0}, done{0};
  std::atomic<bool> stop{false};
  std::mutex m;
  std::string failure;
  auto work = [&](unsigned) {
    for (std::size_t k; !stop && (k = cursor++) < jobs.size();) {
      const LogJob& j = jobs[k];
      const AxisTruth& t = axes[j.axis];
      auto model = makeModel("three-mass");
      for (const auto& [name, v] : t.parameters) model->setParameter(name, v);
      const double sinceStart = j.day - t.startDay;
      double fm = t.parameters.at("f_m") * (1.0 + o.alpha * (j.temperature - t.referenceC));
      if (t.scenario == "wear" && sinceStart > 0.0) fm *= 1.0 + t.size * sinceStart;
      model->setParameter("f_m", fm);
      if (t.scenario == "load" && sinceStart > 0.0) model->setParameter("J_a", t.parameters.at("J_a") * (1.0 + t.size));
      if (t.scenario == "fault" && sinceStart > 0.0) model->setParameter("k_T", base->value("k_T") * (1.0 + t.size));
      SimulationOptions so;
      so.excitation.kind = ExcitationKind::Multisine;
      so.excitation.amplitude = o.amplitudeRad;
      so.durationS = o.durationS;
      so.logRateHz = o.logRateHz;
      so.seed = j.seed;
      SimulationResult r;
      try {
        r = simulateClosedLoop(*model, {}, so);
      } catch (const std::exception& e) {
        r.message = e.what();
      }
      std::string err;
      bool ok = r.termination == Termination::Converged;
      if (ok) {
        r.data.setMeta("description", "daily test routine of " + t.robot + " axis " + std::to_string(t.axis) +
                                          " (simulated plant)");
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.1f", j.temperature);
        r.data.setMeta("temperature_c", buf);
        const std::filesystem::path path = std::filesystem::path(dir) / j.entry.log;
        std::error_code e2;
        std::filesystem::create_directories(path.parent_path(), e2);
        ReadError we;
        ok = writeFlexArmCsv(r.data, path.string(), &we);
        if (!ok) err = we.toString();
      } else {
        err = j.entry.log + ": " + r.message;
      }
      if (!ok) {
        std::lock_guard<std::mutex> lock(m);
        if (failure.empty()) failure = err;
        stop = true;
      }
      const std::size_t n = ++done;
      if (reportProgress(progress, static_cast<double>(n) / static_cast<double>(jobs.size()), "simulate")) stop = true;
    }
  };
  const unsigned threads = o.jobs > 0 ? static_cast<unsigned>(o.jobs) : std::max(1u, std::thread::hardware_concurrency());
  {
    std::vector<std::thread> pool;
    for (unsigned k = 1; k < threads; ++k) pool.emplace_back(work, k);
    work(0);
    for (auto& t : pool) t.join();
  }
  auto finish = [&](Termination t, std::string message) {
    out.termination = t;
    out.message = std::move(message);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    return out;
  };
  if (!failure.empty()) return finish(Termination::Failed, failure);
  if (stop) return finish(Termination::Cancelled, "cancelled");

  std::vector<FleetEntry> entries;
  for (const auto& j : jobs) entries.push_back(j.entry);
  out.manifest = (std::filesystem::path(dir) / "manifest.csv").string();
  out.truth = (std::filesystem::path(dir) / "truth.json").string();
  json ax = json::array();
  for (const auto& t : axes) {
    json a = {{"robot", t.robot}, {"axis", t.axis}, {"scenario", t.scenario},
              {"parameter", t.scenario == "healthy" ? json(nullptr) : json(t.parameter)},
              {"reference_temperature_c", t.referenceC}, {"parameters", t.parameters}};
    if (t.scenario != "healthy") {
      a["start_day"] = t.startDay;
      a["start"] = isoFromDay(day0 + t.startDay);
      a[t.scenario == "wear" ? "per_day" : "step"] = t.size;
    }
    ax.push_back(a);
  }
  const json truth = {{"generator", "FlexArm simulator (flexarm simulate --fleet)"},
                      {"model", "three-mass (Table 5.7 p6), parameters within +-" + std::to_string(o.spread)},
                      {"robots", o.robots}, {"axes_per_robot", o.axes}, {"days", o.days}, {"seed", o.seed},
                      {"start", isoFromDay(day0)}, {"duration_s", o.durationS}, {"log_rate_hz", o.logRateHz},
                      {"excitation", {{"kind", "multisine"}, {"amplitude_rad", o.amplitudeRad}}},
                      {"temperature", {{"mean_c", o.temperatureMeanC}, {"swing_c", o.temperatureSwingC},
                                       {"period_days", 7}, {"alpha_per_degc", o.alpha},
                                       {"model", "f_m = f_m0 (1 + alpha (T - T_ref)), T_ref the first log's"}}},
                      {"axes", ax}};
  if (!writeFileAtomically(out.manifest, fleetManifestText(entries), &why) ||
      !writeFileAtomically(out.truth, truth.dump(2) + "\n", &why))
    return finish(Termination::Failed, why);
  out.logs = static_cast<int>(jobs.size());
  return finish(Termination::Converged, "wrote " + std::to_string(jobs.size()) + " logs of " +
                                            std::to_string(axes.size()) + " axes over " + std::to_string(o.days) +
                                            " days, " + out.manifest + " and " + out.truth);
}

}  // namespace flexarm
