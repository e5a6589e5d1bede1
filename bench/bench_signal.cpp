// Preprocessing a 2 kHz robot log as the seed does (Section 5.2), at 1x, 4x and 16x data
// (16x: ten minutes): motor velocity by central differences against numpy.gradient, and
// decimation by ten of the three channels (linear-phase FIR, zero phase) against
// scipy.signal.decimate (FIR, zero_phase) and Octave's decimate (signal package, FIR).
// On the ten-minute log, rate changes by rational factors (the resampling step: 2000 -> 1500,
// 2000 -> 250 and, of the same numbers taken as a 1 kHz log, 1000 -> 2000 Hz) against
// scipy.signal.resample_poly.
// Agreement: the derivative to rounding; the resampled signals within the filters' difference
// (the peers' FIRs are shorter and have less stopband attenuation), as RMS of the difference
// relative to the RMS of the signal; the decimated signals after FlexArm's output is given the
// response of the peer's own filter (relativeRmsThroughFilter says why).
#include <complex>
#include <fstream>

#include "bench_common.h"
#include "core/common/fft.h"
#include "bench_data.h"
#include "core/signal/preprocess.h"
#include "core/signal/uniform_grid.h"

using namespace flexarm;
using namespace flexarm::bench;

namespace {

const char* const kChannels[] = {columns::kTorqueRef, columns::kMotorAngle, columns::kAngleRef};

// Writes the three channels as raw doubles (channel after channel) for the peers.
void writeRaw(const IdData& d, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  for (const char* name : kChannels) {
    const auto& v = d.channel(name)->values;
    out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(double)));
  }
}

std::vector<double> readRaw(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto bytes = static_cast<std::size_t>(in.tellg());
  std::vector<double> v(bytes / sizeof(double));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(double)));
  return v;
}

// The largest over channels of relative(m, t, n), where m is one of FlexArm's channels and t
// the peer's same channel in `theirs` (the channels one after another, each as long as mine
// or, a grid that ends one sample later or earlier, one sample longer or shorter) and n the
// samples both have; infinite when the shapes do not match.
template <class Relative>
double worstChannel(const std::vector<std::vector<double>>& mine, const std::vector<double>& theirs,
                    Relative relative) {
  if (mine.empty() || theirs.size() % mine.size() != 0) return INFINITY;
  const std::size_t each = theirs.size() / mine.size();
  double worst = 0.0;
  std::size_t at = 0;
  for (const auto& m : mine) {
    if (each + 1 < m.size() || m.size() + 1 < each) return INFINITY;
    worst = std::max(worst, relative(m, theirs.data() + at, std::min(m.size(), each)));
    at += each;
  }
  return worst;
}

// Largest over channels of RMS(mine - theirs) / RMS(mine), ignoring `skip` samples at each
// end (where the peers' edge handling differs).
double relativeRms(const std::vector<std::vector<double>>& mine, const std::vector<double>& theirs,
                   std::size_t skip) {
  return worstChannel(mine, theirs, [&](const std::vector<double>& m, const double* t, std::size_t n) {
    double d2 = 0.0, s2 = 0.0;
    for (std::size_t i = skip; i + skip < n; ++i) {
      d2 += (m[i] - t[i]) * (m[i] - t[i]);
      s2 += m[i] * m[i];
    }
    return std::sqrt(d2 / std::max(s2, 1e-300));
  });
}

// The peers' decimation filters are short windowed FIRs whose passband is not flat: Octave's
// fir1(30, 1/10) is 3 % down at 24.5 Hz (the ten-minute log's chirp reaches it) and 33 % at
// 80 Hz; SciPy's 201-tap Hamming FIR ripples by 0.2 %. FlexArm's output matches the ideal
// decimation (the reference channel, which has nothing above 25 Hz, taken every tenth sample)
// within 3e-6 of its RMS. So the raw difference measures the peer's passband, not whether the
// decimation is right. This measures the rest: FlexArm's output is given the frequency
// response of the peer's own filter (zero phase, as its delay is removed), H(f) =
// sum_j taps[j] cos(2 pi f (j - (N - 1) / 2)) at f of the input rate, and compared with the
// peer's output over the whole band of the output (0 to its Nyquist frequency), away from the
// ends: the samples from `skip` to n - `skip`, with a Tukey window of `taper` samples each
// side so the DFT's wrap-around does not show. What stays is what the peer lets through its
// stopband and aliases (Octave's filter passes the 211 Hz torque component at -48 dB), a wrong
// delay or kept sample, a wrong gain, or a missing anti-alias filter (which leaves the 211 Hz
// component at full size: 14 % of the torque's RMS).
// Largest over channels of RMS(theirs - H mine) / RMS(mine); `theirs` as in relativeRms.
double relativeRmsThroughFilter(const std::vector<std::vector<double>>& mine, const std::vector<double>& theirs,
                                const std::vector<double>& taps, int factor, std::size_t skip, std::size_t taper) {
  if (taps.empty()) return INFINITY;
  return worstChannel(mine, theirs, [&](const std::vector<double>& m, const double* t, std::size_t n) {
    if (n < 2 * (skip + taper) + 2) return static_cast<double>(INFINITY);
    const std::size_t len = n - 2 * skip;
    std::vector<double> a(len), b(len);
    for (std::size_t i = 0; i < len; ++i) {
      const std::size_t fromEnd = std::min(i, len - 1 - i);
      const double w = fromEnd >= taper ? 1.0 : 0.5 - 0.5 * std::cos(M_PI * static_cast<double>(fromEnd) / static_cast<double>(taper));
      a[i] = w * m[skip + i];
      b[i] = w * t[skip + i];
    }
    const std::size_t bins = len / 2 + 1;
    std::vector<std::complex<double>> A(bins), B(bins);
    realDft(a.data(), static_cast<int>(len), A.data());
    realDft(b.data(), static_cast<int>(len), B.data());
    const double centre = 0.5 * static_cast<double>(taps.size() - 1);
    double d2 = 0.0, s2 = 0.0;
    for (std::size_t k = 0; k < bins; ++k) {
      const double f = static_cast<double>(k) / static_cast<double>(len) / factor;  // cycles per input sample
      double h = 0.0;
      for (std::size_t j = 0; j < taps.size(); ++j) h += taps[j] * std::cos(2 * M_PI * f * (static_cast<double>(j) - centre));
      const double weight = k == 0 || 2 * k == len ? 1.0 : 2.0;  // the bins a real signal's DFT folds
      d2 += weight * std::norm(B[k] - h * A[k]);
      s2 += weight * std::norm(A[k]);
    }
    return std::sqrt(d2 / std::max(s2, 1e-300));
  });
}

std::string percent(const std::string& what, double rel) {
  std::ostringstream s;
  s.precision(2);
  s << what << " " << 100.0 * rel << " % of RMS";
  return s.str();
}

std::vector<std::vector<double>> channelsOf(const IdData& d) {
  std::vector<std::vector<double>> out;
  for (const char* name : kChannels) out.push_back(d.channel(name)->values);
  return out;
}

// The ten-minute log (or the same numbers taken at another rate) to a new rate through the
// resampling step, against scipy.signal.resample_poly with the same factors.
void resampleRow(const TempDir& dir, const IdData& log, const std::string& raw, double fromHz, double toHz,
                 int up, int down, int reps) {
  IdData in = log;
  in.sampleTime = 1.0 / fromHz;
  UniformGridOptions o;
  o.rateHz = toHz;
  UniformGridResult res;
  Row r;
  r.group = "preprocess";
  r.task = "resample " + std::to_string(static_cast<int>(fromHz)) + " -> " + std::to_string(static_cast<int>(toHz)) + " Hz";
  r.size = std::to_string(in.samples() / 1000) + "k samples x 3";
  r.flexarmSeconds = medianSeconds(reps, [&] { res = resampleToUniform(in, o); }, true);
  r.peer = "scipy.signal.resample_poly";
  if (res.termination != Termination::Converged) {
    r.extra["note"] = res.message;
    emit(r);
    return;
  }
  std::string why;
  const std::string out = dir.file("resampled.f64");
  const auto peer = runPeer(python("peer_signal.py", "resample " + raw + " " + out + " " + std::to_string(reps) + " " +
                                                         std::to_string(in.samples()) + " " + std::to_string(up) +
                                                         " " + std::to_string(down)),
                            &why);
  if (!peer.empty()) {
    r.peerSeconds = peer[0]["seconds"].get<double>();
    // Within 0.5 % of the RMS away from the ends: FlexArm's FIR passes to 0.8 of the lower
    // Nyquist frequency within 1e-4 and stops 80 dB; SciPy's (Kaiser, beta 5) is shorter.
    const double rel = relativeRms(channelsOf(res.data), readRaw(out), 2000);
    r.agree = rel < 5e-3;
    r.agreement = percent("values (up " + std::to_string(up) + ", down " + std::to_string(down) + "): differ by", rel);
  } else {
    r.extra["note"] = why;
  }
  emit(r);
}

}  // namespace

int main() {
  TempDir dir("flexarm-bench-signal");
  const int factor = 10;
  for (int scale : {1, 4, 16}) {
    const IdData log = syntheticLog(kLogUnit * scale);
    const std::string raw = dir.file("in" + std::to_string(scale) + ".f64");
    writeRaw(log, raw);
    const long n = static_cast<long>(log.samples());
    const std::string size = std::to_string(n / 1000) + "k samples x 3";
    const int reps = repeats(scale == 16 ? 5 : 11);

    // Differentiation of the motor angle.
    const auto& angle = log.channel(columns::kMotorAngle)->values;
    std::vector<double> vel;
    Row d;
    d.group = "preprocess";
    d.task = "differentiate";
    d.size = std::to_string(n / 1000) + "k samples";
    d.scale = scale;
    d.flexarmSeconds = medianSeconds(reps, [&] { vel = differentiate(angle, log.sampleTime); });
    d.peer = "numpy.gradient";
    std::string why;
    const std::string velFile = dir.file("vel.f64");
    auto peer = runPeer(python("peer_signal.py", "gradient " + raw + " " + velFile + " " +
                                                     std::to_string(reps) + " " + std::to_string(n)),
                        &why);
    if (!peer.empty()) {
      d.peerSeconds = peer[0]["seconds"].get<double>();
      const double rel = relativeRms({vel}, readRaw(velFile), 0);
      d.agree = rel < 1e-12;
      d.agreement = percent("values: differ by", rel);
    } else {
      d.extra["note"] = why;
    }
    emit(d);

    // Decimation of the three channels.
    DecimateOptions o;
    o.factor = factor;
    IdData dec;
    const double tDec = medianSeconds(reps, [&] { dec = decimate(log, o); });
    const std::vector<std::vector<double>> mine = channelsOf(dec);
    writeRaw(dec, dir.file("dec-flexarm" + std::to_string(scale) + ".f64"));  // kept with FLEXARM_BENCH_KEEP=1
    for (const bool octavePeer : {false, true}) {
      const std::string out =
          dir.file(std::string(octavePeer ? "dec-octave" : "dec-scipy") + std::to_string(scale) + ".f64");
      Row r;
      r.group = "preprocess";
      r.task = "decimate x10 (FIR)";
      r.size = size;
      r.scale = scale;
      r.flexarmSeconds = tDec;
      r.peer = octavePeer ? "Octave decimate" : "scipy.signal.decimate";
      const std::string args = raw + " " + out + " " + std::to_string(octavePeer ? std::min(reps, 3) : reps) +
                               " " + std::to_string(n) + " " + std::to_string(factor);
      peer = runPeer(octavePeer ? octave("peer_decimate.m", args)
                                : python("peer_signal.py", "decimate " + args),
                     &why);
      if (!peer.empty()) {
        r.peerSeconds = peer[0]["seconds"].get<double>();
        const std::vector<double> theirs = readRaw(out), taps = readRaw(out + ".taps");
        const double plain = relativeRms(mine, theirs, 20);
        const double rel = relativeRmsThroughFilter(mine, theirs, taps, factor, 20, 200);
        // 0.1 % of the RMS: Octave's filter lets the 211 Hz torque component through at
        // -48 dB (0.035 % of the torque's RMS once aliased); a decimation that keeps the wrong
        // samples, has the wrong gain or no anti-alias filter differs by percents.
        r.agree = rel < 1e-3;
        std::ostringstream text;
        text.precision(2);
        text << "values through the peer's own filter response (" << taps.size() << "-tap "
             << (octavePeer ? "fir1, its causal delay of 15 samples removed" : "Hamming FIR")
             << ", applied to FlexArm's output; whole output band, 20 samples at each end left out): differ by "
             << 100.0 * rel << " % of RMS; without it " << 100.0 * plain << " % (the peer's passband "
             << (octavePeer ? "droop" : "ripple") << ")";
        r.agreement = text.str();
        r.extra["differ_raw"] = plain;
        r.extra["differ_through_peer_filter"] = rel;
      } else {
        r.extra["note"] = why;
      }
      emit(r);
    }
    if (scale == 16) {
      resampleRow(dir, log, raw, 2000.0, 1500.0, 3, 4, reps);
      resampleRow(dir, log, raw, 2000.0, 250.0, 1, 8, reps);
      resampleRow(dir, log, raw, 1000.0, 2000.0, 2, 1, reps);
    }
  }
  return 0;
}
