#include "core/diagnosis/scenarios.h"

#include <cmath>
#include <stdexcept>

#include "core/sim/random.h"

namespace flexarm {

bool ScenarioOptions::isValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (arms < 1 || arms > 100000) return fail("at least one arm");
  if (!(durationS > 0.0) || !(healthyDurationS >= 0.0) || !(faultTimeLowS > 0.0) || !(faultTimeHighS >= faultTimeLowS) ||
      !(faultTimeHighS < durationS))
    return fail("the fault must step in within the run");
  if (!(truthSpread >= 0.0 && truthSpread < 0.9)) return fail("the truth spread must lie in [0, 0.9)");
  if (!(noiseLow >= 0.0 && noiseHigh >= noiseLow)) return fail("noise scales: 0 <= low <= high");
  if (!(amplitudeLow > 0.0 && amplitudeHigh >= amplitudeLow)) return fail("amplitudes: 0 < low <= high");
  if (excitations.empty()) return fail("at least one excitation kind");
  if (!(rateHz > 0.0)) return fail("the log rate must be > 0");
  if (why) why->clear();
  return true;
}

std::vector<MonteCarloRun> randomScenarios(const PhysicalModel& nominal,
                                           const std::vector<std::string>& monitored,
                                           const ScenarioOptions& o) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("scenarios: " + why);
  Random random(o.seed);
  auto uniform = [&random](double a, double b) { return a + (b - a) * random.uniform(); };
  std::vector<MonteCarloRun> runs;
  for (int arm = 0; arm < o.arms; ++arm) {
    auto copy = nominal.clone();
    auto* plant = dynamic_cast<PhysicalModel*>(copy.get());
    if (!plant) throw std::invalid_argument("scenarios need a physical model");
    for (const auto& p : nominal.parameters())
      if (p.name != "r" && p.value != 0.0) {
        const double v = p.value * uniform(1.0 - o.truthSpread, 1.0 + o.truthSpread);
        plant->setParameter(p.name, std::min(std::max(v, p.lower), p.upper));
      }
    copy.release();
    MonteCarloRun m;
    m.plant = std::shared_ptr<const PhysicalModel>(plant);
    SimulationOptions& s = m.conditions.simulation;
    s.logRateHz = o.rateHz;
    s.durationS = o.durationS;
    s.excitation.kind = o.excitations[static_cast<std::size_t>(random.next() % o.excitations.size())];
    s.excitation.amplitude = uniform(o.amplitudeLow, o.amplitudeHigh);
    m.conditions.note = std::string(toString(s.excitation.kind)) + " excitation";
    m.noiseScale = uniform(o.noiseLow, o.noiseHigh);
    m.referenceSeed = random.next() >> 16;
    m.faultSize = o.faultSize;
    m.durationS = o.durationS;
    for (int fault = -1; fault < static_cast<int>(monitored.size()); ++fault) {
      MonteCarloRun r = m;
      r.fault = fault;
      r.seed = random.next() >> 16;
      r.faultTimeS = uniform(o.faultTimeLowS, o.faultTimeHighS);
      if (fault < 0 && o.healthyDurationS > 0.0) r.durationS = o.healthyDurationS;
      runs.push_back(r);
    }
  }
  return runs;
}

}  // namespace flexarm
