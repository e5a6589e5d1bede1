#pragma once
// Anti-alias filter designs shared by decimation and rational resampling: the Kaiser-window
// linear-phase low-pass FIR (as a discrete design and as the continuous kernel that the
// polyphase resampler samples at any phase) and the order-8 Chebyshev type I low-pass run
// forward and backward.
#include <optional>
#include <string_view>
#include <vector>

namespace flexarm {

enum class AntiAliasFilter {
  Fir,        // linear-phase Kaiser-window FIR, passband to 0.8 of the new Nyquist frequency,
              // stopband from the new Nyquist frequency on, attenuation >= stopbandDb
  Chebyshev,  // order-8 Chebyshev type I (0.05 dB ripple) at 0.8 of the new Nyquist
              // frequency, run forward and backward (zero phase), as MATLAB's decimate
  None,       // plain down-sampling (aliasing!)
};
const char* toString(AntiAliasFilter f);
std::optional<AntiAliasFilter> antiAliasFilterFromString(std::string_view s);

// Kaiser-window low-pass kernel: the ideal low-pass 2 fc sinc(2 fc k) times the Kaiser window
// of half length m, before normalisation. Frequencies in cycles per sample (0..0.5), k in
// samples (any real value; zero outside |k| <= m).
class KaiserLowpass {
 public:
  KaiserLowpass(double passEdge, double stopEdge, double attenuationDb);
  int taps() const { return taps_; }  // odd length of the discrete design
  int halfLength() const { return taps_ / 2; }
  double operator()(double k) const;

 private:
  int taps_;
  double fc_, beta_, m_, i0beta_;
};

// Low-pass FIR taps (odd length, unit DC gain) by the Kaiser window method. Frequencies are
// in cycles per sample (0..0.5).
std::vector<double> designLowpassFir(double passEdge, double stopEdge, double attenuationDb);

// Second-order section b0 + b1 z^-1 + b2 z^-2 over 1 + a1 z^-1 + a2 z^-2.
struct Biquad {
  double b0, b1, b2, a1, a2;
};

// Chebyshev type I low-pass of even order with the given ripple, cutoff in cycles per
// sample, by the bilinear transform of the analog prototype; unit DC gain.
std::vector<Biquad> chebyshevLowpass(int order, double rippleDb, double cutoff);

// Runs the sections over x in place, starting in the steady state of x[0] so that a constant
// passes untouched.
void runBiquads(const std::vector<Biquad>& sections, std::vector<double>& x);

}  // namespace flexarm
