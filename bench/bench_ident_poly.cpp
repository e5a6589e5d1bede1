// Black-box identification (4.8): FlexArm against what a SciPy or Octave user writes instead,
// on the same simulated data. ARX [4 4 1] by least squares (4.16) against numpy.linalg.lstsq
// on the same regressors and Octave's arx (control package); ARMAX, OE and Box-Jenkins by
// prediction error (4.17)-(4.21) from the same start against scipy.optimize.least_squares
// ('lm') on the same errors (4.5) (lfilter, the same first samples left out); OE [2 2 1] at
// 1x, 4x and 16x data. Agreement: the loss V_N (4.6) and the parameters.
#include <fstream>

#include "bench_common.h"
#include "core/ident/blackbox.h"
#include "tests/core/ident/sim_helpers.h"

using namespace flexarm;
using namespace flexarm::bench;

namespace {

struct Problem {
  std::string name;   // peer's key
  std::string task;
  int scale = 0;
  PolynomialModel start;
  testing::SimData data;
};

void writeProblem(const Problem& p, const std::string& path) {
  std::ofstream out(path);
  out.precision(17);
  const auto& o = p.start.orders;
  Json j;
  j["structure"] = toString(p.start.structure);
  j["orders"] = {o.na, o.nb, o.nc, o.nd, o.nf, o.nk};
  const Eigen::VectorXd th = p.start.parameterVector();
  j["start"] = std::vector<double>(th.data(), th.data() + th.size());
  j["u"] = std::vector<double>(p.data.u.data(), p.data.u.data() + p.data.u.size());
  j["y"] = std::vector<double>(p.data.y.data(), p.data.y.data() + p.data.y.size());
  out << j.dump();
}

// The largest difference between two parameter vectors relative to the largest parameter.
double parameterDifference(const Eigen::VectorXd& a, const std::vector<double>& b) {
  if (static_cast<std::size_t>(a.size()) != b.size()) return INFINITY;
  double d = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[static_cast<std::size_t>(i)]));
  return d / std::max(1e-300, a.cwiseAbs().maxCoeff());
}

void agreement(Row& row, double loss, const Eigen::VectorXd& theta, const Json& peer) {
  const double peerLoss = peer["loss"].get<double>();
  const double dp = parameterDifference(theta, peer["theta"].get<std::vector<double>>());
  row.extra["flexarm_loss"] = loss;
  row.extra["peer_loss"] = peerLoss;
  // Two searches of one criterion agree when neither found a clearly lower loss.
  row.agree = relDiff(loss, peerLoss) < 1e-6 && dp < 1e-4;
  std::ostringstream s;
  s.precision(6);
  s << "loss " << loss << " vs " << peerLoss;
  s.precision(1);
  s << ", parameters " << std::scientific << dp;
  row.agreement = s.str();
}

PolynomialModel perturbed(PolyStructure s, const PolyOrders& o, const Poly& a, const Poly& b,
                          const Poly& c, const Poly& d, const Poly& f, double factor) {
  PolynomialModel m = PolynomialModel::zero(s, o, 1.0);
  auto scale = [&](Poly& to, const Poly& from, std::size_t first) {
    for (std::size_t k = first; k < to.size() && k < from.size(); ++k) to[k] = from[k] * factor;
  };
  scale(m.a, a, 1);
  scale(m.b, b, static_cast<std::size_t>(o.nk));
  scale(m.c, c, 1);
  scale(m.d, d, 1);
  scale(m.f, f, 1);
  return m;
}

}  // namespace

int main() {
  TempDir dir("flexarm-bench-poly");
  const Eigen::Index n = 4000;
  std::vector<Problem> problems;
  const Poly one{1.0};
  const Poly f{1.0, -1.5, 0.7}, b{0.0, 1.0, 0.5}, c{1.0, -0.5, 0.2}, d{1.0, -0.9, 0.2};
  for (int scale : {1, 4, 16}) {
    Problem p;
    p.name = "oe" + std::to_string(scale);
    p.task = "OE [2 2 1]";
    p.scale = scale;
    p.data = testing::simulateSystem(one, b, one, one, f, n * scale, 0.5, 1);
    p.start = PolynomialModel::zero(PolyStructure::Oe, {0, 2, 0, 0, 2, 1}, 1.0);
    p.start.b = {0.0, 0.8, 0.3};
    p.start.f = {1.0, -1.2, 0.5};
    problems.push_back(p);
  }
  {
    Problem p;
    p.name = "armax";
    p.task = "ARMAX [2 2 2 1]";
    p.data = testing::simulateSystem(f, b, c, one, one, n, 0.5, 2);
    p.start = perturbed(PolyStructure::Armax, {2, 2, 2, 0, 0, 1}, f, b, c, one, one, 0.8);
    problems.push_back(p);
  }
  {
    Problem p;
    p.name = "bj";
    p.task = "BJ [2 2 2 2 1]";
    p.data = testing::simulateSystem(one, b, c, d, f, n, 0.5, 3);
    p.start = perturbed(PolyStructure::Bj, {0, 2, 2, 2, 2, 1}, one, b, c, d, f, 0.8);
    problems.push_back(p);
  }
  // ARX [4 4 1] of a fourth-order system with equation-error noise (A y = B u + e).
  const Poly a4 = polyMultiply(f, Poly{1.0, -1.2, 0.5});
  const Poly b4{0.0, 0.5, 0.3, 0.2, 0.1};
  const testing::SimData arxData = testing::simulateSystem(a4, b4, one, one, one, n, 0.1, 4);
  Problem arxProblem;
  arxProblem.name = "arx";
  arxProblem.data = arxData;
  arxProblem.start = PolynomialModel::zero(PolyStructure::Arx, {4, 4, 0, 0, 0, 1}, 1.0);

  std::string list;
  for (const auto& p : problems) {
    writeProblem(p, dir.file(p.name + ".json"));
    list += " " + dir.file(p.name + ".json");
  }
  writeProblem(arxProblem, dir.file("arx.json"));
  std::string why;
  const auto peer = runPeer(python("peer_ident_poly.py", std::to_string(repeats(5)) + " " +
                                                             dir.file("arx.json") + list),
                            &why);
  std::string octaveWhy;
  const auto octavePeer = runPeer(
      octave("peer_arx.m", dir.file("arx.json") + " " + std::to_string(repeats(11))), &octaveWhy);

  // ARX: FlexArm against NumPy and Octave.
  PolyEstimate ra;
  const double tArx = medianSeconds(repeats(21), [&] { ra = arx(arxData.u, arxData.y, 4, 4, 1); });
  const Eigen::VectorXd thArx = ra.model.parameterVector();
  for (const auto* results : {&peer, &octavePeer}) {
    Row row;
    row.group = "black-box identification";
    row.task = "ARX [4 4 1]";
    row.size = samples(n);
    row.flexarmSeconds = tArx;
    row.peer = results == &peer ? "numpy.linalg.lstsq" : "Octave arx";
    const Json p = peerResult(*results, "arx");
    if (!p.is_null()) {
      row.peerSeconds = p["seconds"].get<double>();
      agreement(row, ra.summary.loss, thArx, p);
    } else {
      row.extra["note"] = results == &peer ? why : octaveWhy;
    }
    emit(row);
  }

  for (const auto& p : problems) {
    PolyEstimateOptions po;
    po.relativeTolerance = 1e-12;
    PolyEstimate r;
    Row row;
    row.group = "black-box identification";
    row.task = p.task;
    row.size = samples(static_cast<long>(p.data.y.size()));
    row.scale = p.scale;
    row.flexarmSeconds = medianSeconds(repeats(p.scale > 4 ? 5 : 11),
                                       [&] { r = refinePolynomial(p.data.u, p.data.y, p.start, po); });
    row.extra["iterations"] = r.summary.iterations;
    row.peer = "SciPy least_squares";
    const Json pr = peerResult(peer, p.name);
    if (!pr.is_null()) {
      row.peerSeconds = pr["seconds"].get<double>();
      agreement(row, r.summary.loss, r.model.parameterVector(), pr);
      row.extra["peer_nfev"] = pr["nfev"];
    } else {
      row.extra["note"] = why;
    }
    emit(row);
  }
  return 0;
}
