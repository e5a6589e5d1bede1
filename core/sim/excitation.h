#pragma once
// Excitation signals added to the position reference phi_ref (the seed's Figure 5.1): a chirp
// of constant amplitude swept from high to low frequency (Section 5.1: 30 to 0.5 Hz), a
// multisine with equal energy on a frequency grid and random phases (6.50: 2 pi k / 12 rad/s,
// k = 1..360, i.e. 0-60 pi rad/s), and a maximum-length PRBS.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexarm {

enum class ExcitationKind { None, Chirp, Multisine, Prbs };
const char* toString(ExcitationKind k);  // "none", "chirp", "multisine", "prbs"
std::optional<ExcitationKind> excitationKindFromString(std::string_view s);

struct ExcitationOptions {
  ExcitationKind kind = ExcitationKind::Chirp;
  // rad on the motor side. Chirp: sine amplitude; PRBS: +-amplitude; multisine: the same
  // power as a sine of this amplitude (RMS amplitude / sqrt 2), spread equally over the lines.
  double amplitude = 0.05;
  double chirpStartHz = 30.0;  // the sweep starts here ...
  double chirpEndHz = 0.5;     // ... and ends here, linearly in frequency
  double multisinePeriodS = 12.0;  // lines at 2 pi k / period rad/s (6.50)
  int multisineFirstLine = 1;
  int multisineLastLine = 360;
  double prbsClockS = 0.01;  // the PRBS holds each bit this long
  int prbsBits = 10;         // register length (5..12): period 2^bits - 1 clocks
  double taperS = 0.1;       // raised-cosine fade in and out (0: none)

  bool isValid(std::string* why) const;
};

// The excitation at t = k * sampleTime, k = 0..samples-1. Multisine phases and the PRBS start
// state come from seed. Throws std::invalid_argument for invalid options (see isValid), or a
// multisine line above the Nyquist frequency.
std::vector<double> makeExcitation(const ExcitationOptions& options, double sampleTime,
                                   std::size_t samples, std::uint64_t seed);

}  // namespace flexarm
