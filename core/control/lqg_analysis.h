#pragma once
// Everything chapter 8 shows about an LQG design, computed in one call for one set of design
// variables: the Nyquist curve of F_y G with its encirclements of -1 (Section 8.6), |S| and
// |T| with max |S| and the distance to -1 (8.38), Bode's integral against its prediction
// (8.37), the disturbance steps of Figure 8.3, input saturation with and without
// anti-windup (8.31)-(8.32), the describing-function check (8.30) on F_y G and G_0 (8.35),
// and the T_a G_a^-1 criterion of Section 8.4.
#include <complex>
#include <string>
#include <vector>

#include "core/control/loop_analysis.h"
#include "core/control/lqg.h"

namespace flexarm {

// Unit step disturbances: w at wStepTime, v at vStepTime (Figure 8.3), optionally through an
// input saturation |u| <= saturationLimit.
struct DisturbanceStepOptions {
  double horizon = 3.0;                       // s
  double sampleTime = 1e-3;                   // s, output spacing
  double wStepTime = 0.0, vStepTime = 1.0;    // s
  double wAmplitude = 1.0, vAmplitude = 1.0;  // N m
  // 0: linear loop, simulated exactly. > 0: the applied torque is limited to this level and
  // the regulator runs on a sub-step of sampleTime / subSteps holding u constant.
  double saturationLimit = 0.0;
  bool antiWindup = false;  // (8.32): the estimator sees the applied u instead of u_bar
  int subSteps = 10;
  bool isValid(std::string* why = nullptr) const;
};

struct DisturbanceResponse {
  std::vector<double> time, armAngle, motorAngle, torque;  // s, rad, rad, N m (applied)
  std::vector<double> computedTorque;                      // u_bar before the saturation
  double peakArmDeviation = 0.0;                           // max |phi_a|, rad
  bool diverged = false;  // the response grew without bound (|state| > 1e6)
};

// Response of the closed loop of a successful design to the disturbance steps. Throws
// std::invalid_argument for invalid options or a failed design.
DisturbanceResponse disturbanceSteps(const LqgDesign& design,
                                     const DisturbanceStepOptions& options = {});

// Section 8.4: can a regulator using phi_m alone give the arm the complementary sensitivity
// T_a(s) = 1/(1 + s/w0)^3 of the given -3 dB bandwidth while being stable? It cannot when
// T_m = T_a G_a^-1 (8.26) encircles +1, i.e. when 1 - T_m has zeros in the right half plane.
struct BandwidthCriterion {
  double bandwidth = 0.0;  // rad/s, where |T_a| = 1/sqrt(2)
  double omega0 = 0.0;     // rad/s, the triple pole of T_a
  NyquistCurve curve;      // T_a(iw) G_a^-1(iw) and its counter-clockwise turns around +1
  int rhpZeros = 0;        // zeros of 1 - T_m in the open right half plane, from its numerator
  bool unstableRegulatorNeeded() const { return rhpZeros > 0; }
};

// The T_a G_a^-1 criterion for the arm of `parameters`. Throws std::invalid_argument for a
// non-positive bandwidth or invalid parameters.
BandwidthCriterion bandwidthCriterion(const TwoMassLqgParameters& parameters, double bandwidth,
                                      const NyquistOptions& options = {});

struct LqgAnalysisOptions {
  NyquistOptions nyquist;
  DisturbanceStepOptions steps;  // its saturationLimit is ignored: see below
  // > 0: also simulate the steps with this torque limit, without and with anti-windup.
  double saturationLimit = 0.0;
  double taBandwidth = 50.0;  // rad/s for the Section 8.4 criterion; 0 skips it
  bool isValid(std::string* why = nullptr) const;
};

struct LqgAnalysis {
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
  LqgDesign design;

  NyquistCurve loop;                  // F_y(iw) G(iw), encirclements of -1 (counter-clockwise)
  std::vector<double> sensitivity;    // |S(iw)| on loop.frequencies (8.36)
  std::vector<double> complementary;  // |T(iw)| = |L / (1 + L)|
  double maxSensitivity = 0.0, maxSensitivityFrequency = 0.0;
  double minDistanceToMinusOne = 0.0;  // min |1 + L| = 1 / max |S| (8.38)
  int openLoopRhpPoles = 0;            // of F_y G: the regulator's (the arm has none)
  int expectedEncirclements = 0;       // P - Z from the poles, for comparison with loop's
  double bodeIntegral = 0.0;           // left side of (8.37)
  double bodePrediction = 0.0;         // pi * sum of Re(p_i) over right-half-plane poles of F_y G

  NyquistCurve g0;  // G_0(iw) of (8.35) on its own grid, encirclements of -1
  std::vector<DescribingFunctionCrossing> loopCrossings, g0Crossings;

  DisturbanceResponse steps;                           // linear loop, Figure 8.3
  DisturbanceResponse saturated, saturatedAntiWindup;  // empty without a saturation limit
  BandwidthCriterion bandwidth;                        // empty when taBandwidth is 0

  bool ok() const { return termination == Termination::Converged; }
};

// Designs (designLqg) and analyses the regulator: the data of every chapter-8 plot for one
// choice of design variables. A failed design is reported in the result; throws
// std::invalid_argument for invalid options.
LqgAnalysis analyzeLqg(const LqgOptions& design, const LqgAnalysisOptions& options = {});

}  // namespace flexarm
