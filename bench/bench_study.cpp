// The Monte-Carlo study of the seed's Section 5.3.3: fits of the two-mass model (3.13) from
// random starts (FlexArm's monteCarloStarts on every core) against the same fits with
// scipy.optimize.least_squares in a multiprocessing pool of as many processes. SciPy takes
// seconds per fit, so the peer runs the first few starts and its time is scaled to all of
// them (the row says so). Agreement: the loss of every start both ran, and success or not.
#include <fstream>
#include <thread>

#include "bench_common.h"
#include "core/ident/sensitivity.h"
#include "tests/core/ident/sim_helpers.h"
#include "tests/core/ident/two_mass_test_model.h"

using namespace flexarm;
using namespace flexarm::bench;

int main() {
  const Eigen::Index n = 4000;
  const double ts = 0.005;
  std::mt19937 rng(2);
  const Eigen::VectorXd u = testing::whiteNoise(n, 1.0, rng);
  const Eigen::VectorXd clean = testing::rk4Simulate(testing::TwoMassTestModel().stateSpace(), u, ts);
  const double sd = std::sqrt((clean.array() - clean.mean()).square().mean());
  const Eigen::VectorXd y = clean + testing::whiteNoise(n, 0.05 * sd, rng);
  const PemResult est = pem(testing::TwoMassTestModel(), u, y, ts);

  // Starts between 0.3 and 3 times the estimate (a region of the size of Table 5.8's).
  AttractionResult region;
  region.referenceLoss = est.summary.loss;
  for (const char* name : {"J_m", "J_a", "f_m", "k", "d"}) {
    ParameterAttraction p;
    p.name = name;
    p.lowerFactor = 0.3;
    p.upperFactor = 3.0;
    region.parameters.push_back(p);
  }
  MonteCarloOptions mo;
  mo.runs = quick() ? 20 : 200;
  mo.regionFraction = 1.0;
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  MonteCarloResult mc;
  const double t = medianSeconds(1, [&] { mc = monteCarloStarts(*est.model, u, y, ts, region, mo); }, true);

  // The same starts as monteCarloStarts draws them (same generator, same order).
  std::mt19937 draw(mo.seed);
  std::vector<std::vector<double>> starts(mo.runs);
  for (auto& s : starts)
    for (const auto& pa : region.parameters) {
      const double f = mo.regionFraction;
      std::uniform_real_distribution<double> ud(1.0 + f * (pa.lowerFactor - 1.0),
                                                1.0 + f * (pa.upperFactor - 1.0));
      s.push_back(est.model->parameters()[est.model->indexOf(pa.name)].value * ud(draw));
    }
  const int peerRuns = static_cast<int>(2 * threads);
  TempDir dir("flexarm-bench-study");
  {
    std::ofstream d(dir.file("data.csv"));
    d.precision(17);
    d << "u,y\n";
    for (Eigen::Index i = 0; i < n; ++i) d << u[i] << "," << y[i] << "\n";
    Json j;
    j["starts"] = std::vector<std::vector<double>>(starts.begin(), starts.begin() + peerRuns);
    j["r"] = 1.0 / 120.0;
    j["ts"] = ts;
    j["processes"] = threads;
    std::ofstream(dir.file("starts.json")) << j.dump();
  }
  Row row;
  row.group = "physical identification";
  row.task = "Monte-Carlo study, two-mass";
  row.size = std::to_string(mo.runs) + " fits x " + std::to_string(n) + " samples";
  row.flexarmSeconds = t;
  row.peer = "SciPy least_squares, " + std::to_string(threads) + " processes";
  row.extra["flexarm_successes"] = mc.successes;
  std::string why;
  const auto peer = runPeer(python("peer_study.py", dir.path().string()), &why);
  const Json p = peerResult(peer, "study");
  if (!p.is_null()) {
    // The peer timed peerRuns fits; scaled to all of them.
    row.peerSeconds = p["seconds"].get<double>() * mo.runs / peerRuns;
    row.extra["peer_fits_timed"] = peerRuns;
    const auto losses = p["losses"].get<std::vector<double>>();
    int same = 0;
    double worst = 0.0;
    for (int i = 0; i < peerRuns && i < static_cast<int>(losses.size()); ++i) {
      const bool mine = mc.success[i];
      const bool theirs = losses[i] < (1.0 + mo.successTolerance) * est.summary.loss;
      if (mine == theirs) ++same;
      if (mine && theirs) worst = std::max(worst, relDiff(mc.losses[i], losses[i]));
    }
    row.agree = same == peerRuns && worst < 1e-3;
    std::ostringstream s;
    s << "successes " << mc.successes << " of " << mo.runs << "; first " << peerRuns
      << " starts: same verdict in " << same << ", losses within ";
    s.precision(1);
    s << std::scientific << worst << " (peer time scaled from " << peerRuns << " fits)";
    row.agreement = s.str();
  } else {
    row.extra["note"] = why;
  }
  emit(row);
  return 0;
}
