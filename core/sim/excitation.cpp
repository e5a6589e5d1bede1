#include "core/sim/excitation.h"

#include <cmath>
#include <stdexcept>

#include "core/sim/random.h"

namespace flexarm {

const char* toString(ExcitationKind k) {
  switch (k) {
    case ExcitationKind::None: return "none";
    case ExcitationKind::Chirp: return "chirp";
    case ExcitationKind::Multisine: return "multisine";
    case ExcitationKind::Prbs: return "prbs";
  }
  return "none";
}

std::optional<ExcitationKind> excitationKindFromString(std::string_view s) {
  for (ExcitationKind k : {ExcitationKind::None, ExcitationKind::Chirp,
                           ExcitationKind::Multisine, ExcitationKind::Prbs})
    if (s == toString(k)) return k;
  return std::nullopt;
}

bool ExcitationOptions::isValid(std::string* why) const {
  auto fail = [why](const char* s) {
    if (why) *why = s;
    return false;
  };
  if (!(amplitude >= 0.0) || !std::isfinite(amplitude)) return fail("amplitude must be >= 0");
  if (kind == ExcitationKind::Chirp && !(chirpStartHz > 0.0 && chirpEndHz > 0.0))
    return fail("chirp frequencies must be > 0");
  if (kind == ExcitationKind::Multisine &&
      !(multisinePeriodS > 0.0 && multisineFirstLine >= 1 &&
        multisineLastLine >= multisineFirstLine))
    return fail("multisine needs a period > 0 and lines 1 <= first <= last");
  if (kind == ExcitationKind::Prbs && !(prbsClockS > 0.0 && prbsBits >= 5 && prbsBits <= 12))
    return fail("PRBS needs a clock period > 0 and 5..12 register bits");
  if (!(taperS >= 0.0)) return fail("taper must be >= 0");
  if (why) why->clear();
  return true;
}

namespace {

// Feedback taps of maximum-length Fibonacci LFSRs shifting right, bits 5..12: for the
// polynomial x^n + ... + x^k + ... + 1 the taps are bit 0 and bits n - k.
std::uint32_t prbsTaps(int bits) {
  switch (bits) {
    case 5: return 0x5;    // x^5 + x^3 + 1
    case 6: return 0x3;    // x^6 + x^5 + 1
    case 7: return 0x3;    // x^7 + x^6 + 1
    case 8: return 0x1d;   // x^8 + x^6 + x^5 + x^4 + 1
    case 9: return 0x11;   // x^9 + x^5 + 1
    case 10: return 0x9;   // x^10 + x^7 + 1
    case 11: return 0x5;   // x^11 + x^9 + 1
    default: return 0x107; // x^12 + x^11 + x^10 + x^4 + 1
  }
}

int parity(std::uint32_t v) {
  int p = 0;
  while (v) {
    p ^= 1;
    v &= v - 1;
  }
  return p;
}

}  // namespace

std::vector<double> makeExcitation(const ExcitationOptions& o, double Ts, std::size_t n,
                                   std::uint64_t seed) {
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("excitation: " + why);
  if (!(Ts > 0.0)) throw std::invalid_argument("excitation: the sample time must be > 0");
  std::vector<double> x(n, 0.0);
  Random rng(seed);
  const double duration = static_cast<double>(n) * Ts;
  switch (o.kind) {
    case ExcitationKind::None: break;
    case ExcitationKind::Chirp: {
      const double f0 = o.chirpStartHz, f1 = o.chirpEndHz;
      for (std::size_t k = 0; k < n; ++k) {
        const double t = static_cast<double>(k) * Ts;
        x[k] = o.amplitude * std::sin(2.0 * M_PI * (f0 * t + (f1 - f0) * t * t / (2.0 * duration)));
      }
      break;
    }
    case ExcitationKind::Multisine: {
      const int lines = o.multisineLastLine - o.multisineFirstLine + 1;
      const double w0 = 2.0 * M_PI / o.multisinePeriodS;
      if (w0 * o.multisineLastLine >= M_PI / Ts)
        throw std::invalid_argument("excitation: multisine lines reach the Nyquist frequency");
      const double a = o.amplitude / std::sqrt(static_cast<double>(lines));
      for (int l = o.multisineFirstLine; l <= o.multisineLastLine; ++l) {
        const double phase = 2.0 * M_PI * rng.uniform();
        const double w = w0 * l;
        for (std::size_t k = 0; k < n; ++k)
          x[k] += a * std::cos(w * static_cast<double>(k) * Ts + phase);
      }
      break;
    }
    case ExcitationKind::Prbs: {
      const std::uint32_t mask = (1u << o.prbsBits) - 1u;
      std::uint32_t reg = static_cast<std::uint32_t>(rng.next()) & mask;
      if (reg == 0) reg = 1;
      const std::uint32_t taps = prbsTaps(o.prbsBits);
      long clock = -1;
      double level = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        const long c = static_cast<long>(std::floor(static_cast<double>(k) * Ts / o.prbsClockS + 1e-9));
        while (clock < c) {
          level = (reg & 1u) ? o.amplitude : -o.amplitude;
          reg = ((reg >> 1) | (static_cast<std::uint32_t>(parity(reg & taps)) << (o.prbsBits - 1))) & mask;
          ++clock;
        }
        x[k] = level;
      }
      break;
    }
  }
  if (o.taperS > 0.0) {
    for (std::size_t k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) * Ts;
      const double fromEnd = duration - Ts - t;
      const double edge = std::min(t, fromEnd);
      if (edge < o.taperS) x[k] *= 0.5 - 0.5 * std::cos(M_PI * std::max(edge, 0.0) / o.taperS);
    }
  }
  return x;
}

}  // namespace flexarm
