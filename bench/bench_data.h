#pragma once
// Synthetic robot logs for the bench programs: 2 kHz, torque reference, motor angle and angle
// reference, like the seed's logs (Section 5.1) but of any length.
#include <cmath>

#include "core/signal/id_data.h"

namespace flexarm::bench {

// A log of `samples` samples at 2 kHz: a slow chirp reference, the angle following it with a
// 17 Hz ripple, and a torque with a 211 Hz component (above the Nyquist frequency after
// decimation by ten, so the anti-alias filter matters).
inline IdData syntheticLog(std::size_t samples) {
  IdData d;
  d.sampleTime = 0.0005;
  std::vector<double> angle(samples), torque(samples), ref(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) * d.sampleTime;
    ref[i] = 0.05 * std::sin(2 * M_PI * (0.5 + 0.02 * t) * t);
    angle[i] = ref[i] + 1e-4 * std::sin(2 * M_PI * 17 * t);
    torque[i] = 0.1 * std::cos(2 * M_PI * 3.1 * t) + 0.01 * std::sin(2 * M_PI * 211 * t);
  }
  d.setChannel({columns::kMotorAngle, "", ChannelRole::Output, angle});
  d.setChannel({columns::kTorqueRef, "", ChannelRole::Input, torque});
  d.setChannel({columns::kAngleRef, "", ChannelRole::Reference, ref});
  return d;
}

// The ten-minute log of the seed's experiments is 16 of these units (1.2 million samples).
inline constexpr std::size_t kLogUnit = 2000 * 600 / 16;

}  // namespace flexarm::bench
