// Physical-model output-error fitting (5.7): FlexArm against scipy.optimize.least_squares
// ('lm', finite-difference Jacobian, the same ZOH simulation) on the same simulated data and
// start, in one run: the two-mass model (3.13) on 4000 samples with 5 % output noise, and the
// three-mass model (3.21) on closed-loop simulator data (Table 5.7 p6 truth, the chirp of
// Section 5.1, motor velocity by central differences, decimated to the seed's 200 Hz).
// Agreement: the losses V_N (4.6) of both estimates.
#include <fstream>

#include "bench_common.h"
#include "core/ident/nonparametric.h"
#include "core/ident/pem.h"
#include "core/models/physical_models.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"
#include "tests/core/ident/sim_helpers.h"
#include "tests/core/ident/two_mass_test_model.h"

using namespace flexarm;

using namespace flexarm::bench;

namespace {

void agreement(Row& row, double loss, const Json& peer) {
  const double peerLoss = peer["loss"].get<double>();
  row.extra["flexarm_loss"] = loss;
  row.extra["peer_loss"] = peerLoss;
  // Agree: neither search found a loss more than 0.1 % below the other's.
  row.agree = relDiff(loss, peerLoss) < 1e-3;
  row.agreement = versus("loss", loss, peerLoss, 6);
}

}  // namespace

int main() {
  const Eigen::Index n = 4000;
  const double ts = 0.005;
  // Two-mass data: RK4 with held input, 5 % output noise.
  std::mt19937 rng(2);
  const Eigen::VectorXd u2 = testing::whiteNoise(n, 1.0, rng);
  const Eigen::VectorXd clean = testing::rk4Simulate(testing::TwoMassTestModel().stateSpace(), u2, ts);
  const double sd = std::sqrt((clean.array() - clean.mean()).square().mean());
  const Eigen::VectorXd y2 = clean + testing::whiteNoise(n, 0.05 * sd, rng);
  testing::TwoMassTestModel m0;
  const std::vector<double> s2{9e-4 * 1.2, 12.0 * 0.85, 0.1 * 1.3, 1.5e5 * 1.1, 70.0 * 1.5};
  const char* names[] = {"J_m", "J_a", "f_m", "k", "d"};
  for (int i = 0; i < 5; ++i) m0.setParameter(names[i], s2[i]);

  // Three-mass data: the closed loop of Figure 5.1 around the p6 truth, decimated by ten.
  SimulationOptions so;
  so.durationS = 18.0;
  so.seed = 1;
  const auto sim = simulateClosedLoop(*makeModel("three-mass"), {}, so);
  DecimateOptions dec;
  dec.factor = 10;
  const IdData d3 = decimate(addDerivative(sim.data), dec);
  Eigen::VectorXd u3, y3;
  inputOutput(d3, u3, y3);
  u3.array() -= u3.mean();
  y3.array() -= y3.mean();
  const double ts3 = d3.sampleTime;
  auto m3 = makeModel("three-mass");
  const char* names3[] = {"J_m", "J_g", "J_a", "f_m", "k_g", "k_a", "d_g", "d_a"};
  const double factors3[] = {1.2, 0.8, 1.15, 1.3, 0.85, 1.1, 0.8, 1.25};
  std::vector<double> s3;
  for (int i = 0; i < 8; ++i) {
    s3.push_back(m3->value(names3[i]) * factors3[i]);
    m3->setParameter(names3[i], s3.back());
  }

  TempDir dir("flexarm-bench-physical");
  {
    std::ofstream d(dir.file("data.csv"));
    d.precision(17);
    d << "u_two_mass,y_two_mass\n";
    for (Eigen::Index t = 0; t < n; ++t) d << u2[t] << "," << y2[t] << "\n";
    std::ofstream s(dir.file("start.json"));
    s.precision(17);
    s << "{\"two_mass\": [" << s2[0] << ", " << s2[1] << ", " << s2[2] << ", " << s2[3] << ", "
      << s2[4] << "], \"r\": " << 1.0 / 120.0 << ", \"ts\": " << ts << ", \"three_mass\": [";
    for (std::size_t i = 0; i < s3.size(); ++i) s << (i ? ", " : "") << s3[i];
    s << "], \"r3\": " << m3->value("r") << ", \"ts3\": " << ts3 << "}\n";
    std::ofstream d3f(dir.file("three_mass.csv"));
    d3f.precision(17);
    d3f << "u,y\n";
    for (Eigen::Index t = 0; t < u3.size(); ++t) d3f << u3[t] << "," << y3[t] << "\n";
  }

  PemOptions pe;
  pe.relativeTolerance = 1e-12;
  PemResult r2, r3;
  const double tTwo = medianSeconds(repeats(5), [&] { r2 = pem(m0, u2, y2, ts, pe); });
  const double tThree = medianSeconds(repeats(3), [&] { r3 = pem(*m3, u3, y3, ts3, pe); });

  std::string why;
  const auto peer = runPeer(python("peer_ident_physical.py", dir.path().string()), &why);
  struct Case {
    const char* name;
    const char* task;
    long samples;
    double seconds;
    const PemResult* result;
  };
  for (const Case& c : {Case{"two-mass", "two-mass OE (5 parameters)", static_cast<long>(n), tTwo, &r2},
                        Case{"three-mass", "three-mass OE (8 parameters)", static_cast<long>(u3.size()), tThree, &r3}}) {
    Row row;
    row.group = "physical identification";
    row.task = c.task;
    row.size = samples(c.samples);
    row.flexarmSeconds = c.seconds;
    row.peer = "SciPy least_squares";
    row.extra["iterations"] = c.result->summary.iterations;
    const Json p = peerResult(peer, c.name);
    if (!p.is_null()) {
      row.peerSeconds = p["seconds"].get<double>();
      row.extra["peer_nfev"] = p["nfev"];
      agreement(row, c.result->summary.loss, p);
    } else {
      row.extra["note"] = why;
    }
    emit(row);
  }
  return 0;
}
