// Non-parametric frequency-response estimates of Section 4.3 on 64k samples of a simulated
// resonant system with noise: the ETFE (4.24) smoothed by (4.25) over 16 bins at every DFT
// frequency, and SPA (4.28) with a Hann lag window of width 30 at 128 frequencies, against
// the same formulas in NumPy (rfft and a convolution; covariances by dot products and a
// cosine sum), which is what a SciPy user writes (SciPy has no SPA; scipy.signal.csd is
// Welch's estimator, another one). Agreement: |G| at every frequency.
#include <fstream>

#include "bench_common.h"
#include "core/ident/nonparametric.h"
#include "tests/core/ident/sim_helpers.h"

using namespace flexarm;
using namespace flexarm::bench;

int main() {
  const Eigen::Index n = 65536;
  const double ts = 0.005;
  const Poly one{1.0}, f{1.0, -1.8, 0.95}, b{0.0, 0.5, 0.3};
  const auto d = testing::simulateSystem(one, b, one, Poly{1.0, -0.5}, f, n, 0.2, 5);
  TempDir dir("flexarm-bench-nonparametric");
  {
    std::ofstream out(dir.file("uy.f64"), std::ios::binary);
    out.write(reinterpret_cast<const char*>(d.u.data()), static_cast<std::streamsize>(n * sizeof(double)));
    out.write(reinterpret_cast<const char*>(d.y.data()), static_cast<std::streamsize>(n * sizeof(double)));
  }
  EtfeOptions eo;
  eo.smoothingWidth = 16;
  SpaOptions so;
  so.windowWidth = 30;
  NonparametricEstimate e, s;
  const double tE = medianSeconds(repeats(11), [&] { e = etfe(d.u, d.y, ts, eo); });
  const double tS = medianSeconds(repeats(11), [&] { s = spa(d.u, d.y, ts, so); });
  std::string why;
  const auto peer = runPeer(python("peer_nonparametric.py", dir.file("uy.f64") + " " +
                                                                std::to_string(n) + " " +
                                                                std::to_string(repeats(11))),
                            &why);
  for (const auto* est : {&e, &s}) {
    const bool isEtfe = est == &e;
    Row row;
    row.group = "black-box identification";
    row.task = isEtfe ? "ETFE, 16-bin Hann smoothing" : "SPA, Hann lag window M = 30";
    row.size = samples(n) + ", " + std::to_string(est->response.omega.size()) + " frequencies";
    row.flexarmSeconds = isEtfe ? tE : tS;
    row.peer = isEtfe ? "NumPy rfft + convolve" : "NumPy covariances + cosines";
    const Json p = peerResult(peer, isEtfe ? "etfe" : "spa");
    if (!p.is_null()) {
      row.peerSeconds = p["seconds"].get<double>();
      const auto mag = p["magnitude"].get<std::vector<double>>();
      double worst = mag.size() == est->response.magnitude.size() ? 0.0 : INFINITY;
      for (std::size_t i = 0; std::isfinite(worst) && i < mag.size(); ++i)
        worst = std::max(worst, relDiff(mag[i], est->response.magnitude[i]));
      row.agree = worst < 1e-9;
      std::ostringstream t;
      t.precision(2);
      t << "values: |G| differs by " << worst << " at most";
      row.agreement = t.str();
    } else {
      row.extra["note"] = why;
    }
    emit(row);
  }
  return 0;
}
