#pragma once
// Whether a channel carries a signal an estimator can learn from. A stuck encoder, a torque
// that is all zero, or values so large (1e308) or so small (1e-315) that their squares
// overflow or vanish give a fit nothing to fit, yet the numbers of a fit or a diagnosis on
// them look like answers. Every analysis refuses such data through this one check before it
// starts: prepareFitData (the fit, the recursive estimator, discovery, the diagnosis) and the
// command line's verbs, which exit with "bad input" naming the channel.
#include <string>
#include <string_view>
#include <vector>

#include "core/signal/id_data.h"

namespace flexarm {

// Values whose squares stay finite and normal over a log of up to 1e12 samples: a channel
// whose largest magnitude lies outside [kMinSignalScale, kMaxSignalScale] cannot be analysed.
inline constexpr double kMaxSignalScale = 1e140;
inline constexpr double kMinSignalScale = 1e-140;

// Empty when the values vary at a scale an analysis can use; otherwise a sentence naming what
// is wrong, e.g. "is constant (every sample is 0)", "varies by only 2e-17 around 1000 (a
// stuck sensor)", "reaches 1e+308, too large to square", "is at most 1e-315 in magnitude".
// Non-finite values are named too (sample numbers start at 1).
std::string deadSignalProblem(const std::vector<double>& values);

// Checks the named channels of data (a name not in data is skipped) and, when names is empty,
// the input and output channels by role and the arm encoder (arm_angle_rad) when logged. Empty when all carry a signal; otherwise a sentence
// naming the first channel that does not: "the channel torque_ref_nm carries no signal: it is
// constant (every sample is 0)".
std::string deadDataProblem(const IdData& data, const std::vector<std::string>& names = {});

}  // namespace flexarm
