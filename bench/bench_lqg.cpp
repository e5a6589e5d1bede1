// One slider move of the LQG panel (chapter 8): redesign (two Riccati equations) plus all plot
// data (Nyquist of F_y G and G_0, |S|, |T|, Bode's integral, the Figure 8.3 steps, pole
// lists), against SciPy (solve_continuous_are, batched frequency responses, the same ZOH step
// simulation: peer_lqg.py) and Octave's control package (care, freqresp, lsim:
// peer_lqg.m) on the same frequency grid. The slider sweeps R2 between the seed's two cases.
// Agreement: max |S| on the grid and the peak arm deviation of the steps for case (ii).
#include <fstream>

#include "bench_common.h"
#include "core/control/lqg_analysis.h"

using namespace flexarm;
using namespace flexarm::bench;

int main() {
  const int reps = repeats(50);
  auto options = [](int i) {
    LqgOptions o = LqgOptions::seedCaseII();
    o.r2(0) = std::pow(10.0, -8.0 + 2.0 * (i % 20) / 19.0);
    return o;
  };
  LqgAnalysisOptions ao;
  ao.taBandwidth = 0.0;  // depends on the plant only, not on the slider
  LqgAnalysis last;
  const double cpp = medianSeconds(reps, [&](int i) { last = analyzeLqg(options(i), ao); });
  const LqgAnalysis caseII = analyzeLqg(options(0), ao);

  TempDir dir("flexarm-bench-lqg");
  const std::string grid = dir.file("grid.txt");
  {
    std::ofstream g(grid);
    g.precision(17);
    for (double w : caseII.loop.frequencies) g << w << "\n";
  }
  const std::string size = std::to_string(caseII.loop.frequencies.size()) + " frequencies, 3001 steps";
  for (const bool octavePeer : {false, true}) {
    Row row;
    row.group = "control";
    row.task = "LQG slider move";
    row.size = size;
    row.flexarmSeconds = cpp;
    row.peer = octavePeer ? "Octave care/freqresp/lsim" : "SciPy CARE + responses";
    std::string why;
    const std::string args = grid + " " + std::to_string(octavePeer ? std::min(reps, 11) : reps);
    const auto peer = runPeer(octavePeer ? octave("peer_lqg.m", args) : python("peer_lqg.py", args), &why);
    const Json p = peerResult(peer, "lqg");
    if (!p.is_null()) {
      row.peerSeconds = p["seconds"].get<double>();
      const double ms = p["max_s"].get<double>(), peak = p["peak_arm"].get<double>();
      row.agree = relDiff(ms, caseII.maxSensitivity) < 1e-3 &&
                  relDiff(peak, caseII.steps.peakArmDeviation) < 1e-3;
      std::ostringstream s;
      s.precision(5);
      s << "max|S| " << caseII.maxSensitivity << " vs " << ms << ", peak " << caseII.steps.peakArmDeviation
        << " vs " << peak;
      row.agreement = s.str();
    } else {
      row.extra["note"] = why;
    }
    emit(row);
  }
  return 0;
}
