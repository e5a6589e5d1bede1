// Subspace identification (core/ident/subspace.h): FlexArm's N4SID against the textbook one a
// NumPy user writes (peer_subspace.py: the combined algorithm of Van Overschee and De Moor
// through the state sequences, the Kalman gain from the Riccati equation), on simulated
// flexible arms of known order, at the order and horizon FlexArm chose. Agreement: the
// resonance frequencies (rad/s of the complex poles, within 1 %) and the one-step prediction
// loss (within 5 %); the order FlexArm chose against the truth is printed beside.
#include <fstream>
#include <iomanip>

#include "bench_common.h"
#include "core/ident/subspace.h"
#include "tests/core/ident/subspace_logs.h"

using namespace flexarm;
using namespace flexarm::bench;

int main() {
  TempDir dir("flexarm-bench-subspace");
  struct Problem {
    std::string name, task;
    testing::ArmLog log;
    SubspaceEstimate estimate;
    double seconds = 0.0;
  };
  std::vector<Problem> problems;
  for (int masses : {2, 3})
    for (Eigen::Index n : {Eigen::Index(4000), Eigen::Index(16000)}) {
      Problem p;
      p.name = std::to_string(masses) + "mass" + std::to_string(n);
      p.task = "N4SID, " + std::to_string(masses) + "-mass arm (order " + std::to_string(2 * masses - 1) + ")";
      p.log = testing::armLog(masses, false, 7u + static_cast<unsigned>(masses), n);
      problems.push_back(std::move(p));
    }
  std::string list;
  for (auto& p : problems) {
    SubspaceOptions o;
    o.method = SubspaceMethod::N4sid;
    o.maxOrder = 8;
    p.seconds = medianSeconds(repeats(5), [&] { p.estimate = subspaceEstimate(p.log.u, p.log.y, 0.005, o); });
    Json j;
    j["name"] = p.name;
    j["order"] = p.estimate.chosenOrder;
    j["horizon"] = p.estimate.horizon;
    j["sample_time"] = 0.005;
    j["u"] = std::vector<double>(p.log.u.data(), p.log.u.data() + p.log.u.size());
    j["y"] = std::vector<double>(p.log.y.data(), p.log.y.data() + p.log.y.size());
    std::ofstream(dir.file(p.name + ".json")) << std::setprecision(17) << j.dump();
    list += " " + dir.file(p.name + ".json");
  }
  std::string why;
  const auto peer = runPeer(python("peer_subspace.py", std::to_string(repeats(3)) + list), &why);
  for (const auto& p : problems) {
    Row row;
    row.group = "subspace identification";
    row.task = p.task;
    row.size = samples(static_cast<long>(p.log.u.size()));
    row.flexarmSeconds = p.seconds;
    row.peer = "NumPy N4SID (Van Overschee-De Moor)";
    const Json r = peerResult(peer, p.name);
    if (r.is_null() || !p.estimate.ok) {
      row.extra["note"] = p.estimate.ok ? "the peer did not run: " + why : "FlexArm: " + p.estimate.message;
      emit(row);
      continue;
    }
    row.peerSeconds = r["seconds"].get<double>();
    const auto w = testing::resonances(p.estimate.model.A, 0.005, true);
    const auto pw = r["resonances"].get<std::vector<double>>();
    double worst = w.size() == pw.size() ? 0.0 : INFINITY;
    for (std::size_t i = 0; i < w.size() && i < pw.size(); ++i) worst = std::max(worst, relDiff(w[i], pw[i]));
    const double loss = p.estimate.model.noiseVariance, peerLoss = r["loss"].get<double>();
    row.agree = worst < 0.01 && relDiff(loss, peerLoss) < 0.05;
    std::ostringstream s;
    s.precision(3);
    s << "order " << p.estimate.chosenOrder << " (truth " << p.log.order << "), resonances " << worst * 100
      << " % apart, loss " << loss << " vs " << peerLoss;
    row.agreement = s.str();
    emit(row);
  }
  return 0;
}
