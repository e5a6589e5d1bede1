// Output-error fitting speed: FlexArm against scipy.optimize.least_squares on the same
// simulated data and start, in one run. Three problems: a polynomial OE [2 2 1] (4.8), the
// two-mass physical model (3.13) and the three-mass model (3.21) with ZOH simulation, the
// last on closed-loop simulator data (Table 5.7 p6 truth, the chirp of Section 5.1, motor
// velocity by central differences, decimated to the seed's 200 Hz). Prints the time ratio and
// both losses.
//
//   cmake --build BUILD --target bench && BUILD/bench/bench_ident_oe
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <thread>

#include "core/ident/blackbox.h"
#include "core/ident/pem.h"
#include "core/ident/sensitivity.h"
#include "core/ident/nonparametric.h"
#include "core/models/physical_models.h"
#include "core/signal/preprocess.h"
#include "core/sim/closed_loop.h"
#include "tests/core/ident/sim_helpers.h"
#include "tests/core/ident/two_mass_test_model.h"

using namespace flexarm;

namespace {

double secondsOf(const std::function<void()>& f, int repeats) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];  // median
}

std::string field(const std::string& line, const std::string& key) {
  const auto at = line.find("\"" + key + "\":");
  if (at == std::string::npos) return {};
  auto from = at + key.size() + 3;
  while (from < line.size() && line[from] == ' ') ++from;
  const auto to = line.find_first_of(",}", from);
  return line.substr(from, to - from);
}

}  // namespace

int main() {
  const Eigen::Index n = 4000;
  const double ts = 0.005;
  // Polynomial OE data.
  const Poly f{1.0, -1.5, 0.7}, b{0.0, 1.0, 0.5};
  auto poly = testing::simulateSystem({1.0}, b, {1.0}, {1.0}, f, n, 0.5, 1);
  PolynomialModel start = PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 2, 1}, 1.0);
  start.b = {0.0, 0.8, 0.3};
  start.f = {1.0, -1.2, 0.5};
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

  const auto dir = std::filesystem::temp_directory_path() / "flexarm_bench_ident_oe";
  std::filesystem::create_directories(dir);
  {
    std::ofstream d(dir / "data.csv");
    d.precision(17);
    d << "u_poly,y_poly,u_two_mass,y_two_mass\n";
    for (Eigen::Index t = 0; t < n; ++t)
      d << poly.u[t] << "," << poly.y[t] << "," << u2[t] << "," << y2[t] << "\n";
    std::ofstream s(dir / "start.json");
    s.precision(17);
    s << "{\"poly\": [0.8, 0.3, -1.2, 0.5], \"two_mass\": [" << s2[0] << ", " << s2[1] << ", "
      << s2[2] << ", " << s2[3] << ", " << s2[4] << "], \"r\": " << 1.0 / 120.0
      << ", \"ts\": " << ts << ", \"three_mass\": [";
    for (std::size_t i = 0; i < s3.size(); ++i) s << (i ? ", " : "") << s3[i];
    s << "], \"r3\": " << m3->value("r") << ", \"ts3\": " << ts3 << "}\n";
    std::ofstream d3f(dir / "three_mass.csv");
    d3f.precision(17);
    d3f << "u,y\n";
    for (Eigen::Index t = 0; t < u3.size(); ++t) d3f << u3[t] << "," << y3[t] << "\n";
  }

  PolyEstimate rp;
  PolyEstimateOptions po;
  po.relativeTolerance = 1e-12;
  const double tPoly = secondsOf([&] { rp = refinePolynomial(poly.u, poly.y, start, po); }, 7);
  PemResult r2;
  PemOptions pe;
  pe.relativeTolerance = 1e-12;
  const double tPhys = secondsOf([&] { r2 = pem(m0, u2, y2, ts, pe); }, 5);
  PemResult r3;
  const double tThree = secondsOf([&] { r3 = pem(*m3, u3, y3, ts3, pe); }, 3);
  // The loss as SciPy computes it: mean squared error over all samples.
  const double lossPoly = predictionErrors(rp.model, poly.u, poly.y).squaredNorm() / n;
  const double lossPhys = r2.summary.loss;

  const std::string cmd = std::string("/usr/bin/python3 ") + FLEXARM_BENCH_DIR +
                          "/bench_ident_oe.py " + dir.string() + " > " +
                          (dir / "scipy.txt").string();
  if (std::system(cmd.c_str()) != 0) {
    std::cerr << "bench_ident_oe: the SciPy peer failed (" << cmd << ")\n";
    return 1;
  }
  std::ifstream in(dir / "scipy.txt");
  std::string line1, line2, line3;
  std::getline(in, line1);
  std::getline(in, line2);
  std::getline(in, line3);
  const double spPolyT = std::stod(field(line1, "seconds")), spPolyL = std::stod(field(line1, "loss"));
  const double spPhysT = std::stod(field(line2, "seconds")), spPhysL = std::stod(field(line2, "loss"));
  const double spThreeT = std::stod(field(line3, "seconds")), spThreeL = std::stod(field(line3, "loss"));
  std::printf("problem    samples  flexarm_s   scipy_s    ratio  flexarm_loss   scipy_loss  iters\n");
  std::printf("oe[2 2 1]  %7ld  %9.5f  %8.5f  %7.1f  %12.6g  %11.6g  %5d\n", static_cast<long>(n),
              tPoly, spPolyT, spPolyT / tPoly, lossPoly, spPolyL, rp.summary.iterations);
  std::printf("two-mass   %7ld  %9.5f  %8.5f  %7.1f  %12.6g  %11.6g  %5d\n", static_cast<long>(n),
              tPhys, spPhysT, spPhysT / tPhys, lossPhys, spPhysL, r2.summary.iterations);
  std::printf("three-mass %7ld  %9.5f  %8.5f  %7.1f  %12.6g  %11.6g  %5d\n",
              static_cast<long>(u3.size()), tThree, spThreeT, spThreeT / tThree,
              r3.summary.loss, spThreeL, r3.summary.iterations);
  std::printf("(ratio = SciPy seconds / FlexArm seconds; medians of FlexArm repeats; SciPy times\n"
              " the least_squares call only, with finite-difference Jacobians, method 'lm')\n");

  // The seed's Section 5.3.3 study on the two-mass estimate: Table 5.8 limits by interval
  // halving, then 1000 fits from random starts, on every core.
  AttractionOptions ao;
  const auto dom = domainOfAttraction(*r2.model, u2, y2, ts, ao);
  MonteCarloOptions mo;
  mo.runs = 1000;
  const auto mc = monteCarloStarts(*r2.model, u2, y2, ts, dom, mo);
  std::printf("\ndomain of attraction (factor of the estimate), %d fits in %.2f s:\n", dom.fits,
              dom.seconds);
  for (const auto& p : dom.parameters)
    std::printf("  %-4s lower %8.1f %%%s  upper %8.1f %%%s\n", p.name.c_str(), 100 * p.lowerFactor,
                p.lowerOpen ? "+" : " ", 100 * p.upperFactor, p.upperOpen ? "+" : " ");
  std::printf("Monte-Carlo: %s in %.2f s on %u threads (seed: 649 of 1000)\n", mc.message.c_str(),
              mc.seconds, std::max(1u, std::thread::hardware_concurrency()));
  return 0;
}
