#pragma once
// Inverse-dynamics identification of the rigid part of an axis with friction (IDIM, as robot
// makers identify their arms: Gautier 1997; Janot, Gautier and Brunot, EMPS 2019): the
// inverse dynamic model written linearly in its parameters,
//   tau = J q'' + F_v q' + F_c sign(q') + offset                        (symmetric friction)
//   tau = J q'' + F_v+ q'_+ + F_v- q'_- + F_c+ s_+ - F_c- s_-          (asymmetric, EMPS (12))
// with q'_+ = q' when q' > 0 (else 0), s_+ = 1 when q' > 0 (else 0) and the same for the
// negative side, solved in closed form on band-limited data:
//   1. the position q is low-passed by a Butterworth filter run forwards and backwards (no
//      lag), so that the central differences q', q'' are exact below its cut-off;
//   2. every column of the observation matrix and the torque pass the same anti-alias low-pass
//      and are decimated ("parallel filtering": the torque ripple the controller rejects is
//      removed from both sides alike);
//   3. least squares theta = (Phi^T Phi)^-1 Phi^T y (IDIM-LS), or instrumental variables
//      theta = (Z^T Phi)^-1 Z^T y (IDIM-IV) with Z the same regressors built from the position
//      reference, which the noise the controller feeds back does not reach (closed loop).
// The same call serves a rotary axis (q in rad, J in kg m^2, torque in N m) and a prismatic
// one (q in m, a mass in kg, force in N); its result starts the flexible fits (the seed's 9.2
// asks for good initial values).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"

namespace flexarm {

enum class IdimFriction { Symmetric, Asymmetric };
const char* toString(IdimFriction f);  // "symmetric", "asymmetric"

struct IdimOptions {
  // Cut-off of the position's Butterworth filter (Hz); 0: a twentieth of the sample rate
  // (EMPS: 50 Hz at 1 kHz; the rule of thumb asks for five times the closed loop's bandwidth).
  double cutoffHz = 0.0;
  int filterOrder = 4;  // of the Butterworth filter (even, 2..12)
  // Keep one sample in this many after the parallel low-pass; 0: as many as put its band
  // (0.8 of the new Nyquist frequency) at half the cut-off, where the filtered position's
  // derivatives are exact (the description's omega_Fp below omega_fq).
  int decimation = 0;
  IdimFriction friction = IdimFriction::Symmetric;
  bool instrumentalVariables = false;  // IDIM-IV with instruments from the reference
  // Seconds left out at each end after filtering (the filters' transients); 0: 4 periods of
  // the cut-off.
  double edgeSeconds = 0.0;
  // The torque is held over each sample (a controller's output through its D/A converter), so
  // the torque logged at sample k acts on average at k + 1/2: the regressors are taken there
  // (the mean of samples k and k + 1). Without it, a held torque's half-sample lag reads as a
  // viscous friction lower by J T omega^2 / 2 (17 % on a simulated axis at 2 kHz).
  bool heldTorque = true;
  // The axis is prismatic: q in m, the inertia a mass in kg, forces in N.
  bool prismatic = false;
  double level = 0.99;  // of the reported intervals
  bool isValid(std::string* why) const;
};

struct IdimParameter {
  std::string name, unit;
  double value = 0.0, std = 0.0, lower = 0.0, upper = 0.0;
};

struct IdimResult {
  Termination termination = Termination::Failed;
  std::string message;
  // J (or M), F_v, F_c, offset; or J, F_v+, F_v-, F_c+, F_c-.
  std::vector<IdimParameter> parameters;
  Eigen::MatrixXd covariance;
  double cutoffHz = 0.0;
  int decimation = 1;
  int samples = 0;             // rows of the observation matrix
  double relativeError = 0.0;  // 100 ||y - Phi theta|| / ||y||, the EMPS description's (11)
  double torqueFitPercent = 0.0;  // (5.2) of the filtered torque
  double conditionNumber = 0.0;   // of the observation matrix
  // The filtered torque and its reconstruction Phi theta at the kept samples, and their times
  // (s from the first sample of the input).
  Eigen::VectorXd torque, predicted, time;
  bool ok() const { return termination == Termination::Converged; }
  // The value of a parameter by name; nullopt when there is none.
  std::optional<double> value(const std::string& name) const;
};

// IDIM-LS (or IDIM-IV with a reference) of q and tau sampled every sampleTime s. reference
// is needed for instrumental variables (else ignored) and has q's length. Data failures (too
// few samples, no motion, a rank-deficient observation matrix) end as Failed with a sentence;
// invalid options or mismatched lengths throw std::invalid_argument.
IdimResult idim(const Eigen::VectorXd& position, const Eigen::VectorXd& torque, double sampleTime,
                const IdimOptions& options = {}, const Eigen::VectorXd& reference = {});

// Zero-phase Butterworth low-pass of x (cut-off in cycles per sample, 0 < cutoff < 0.5): the
// filter run forwards and backwards, the ends extended by odd reflection.
std::vector<double> butterworthFiltFilt(const std::vector<double>& x, int order, double cutoff);

}  // namespace flexarm
