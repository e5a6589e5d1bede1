#pragma once
// Non-parametric frequency-response estimates of Section 4.3: the empirical transfer function
// estimate ETFE (4.24) smoothed by (4.25), and the spectral analysis estimate SPA (4.28) with a
// Hann or Hamming lag window and SITB-like confidence region. Closed-loop data bias both (4.30).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "core/common/progress.h"
#include "core/ident/evaluation.h"
#include "core/signal/id_data.h"

namespace flexarm {

enum class LagWindow { Hann, Hamming };
const char* toString(LagWindow w);
std::optional<LagWindow> lagWindowFromString(std::string_view s);

// The sentence shown with a non-parametric estimate of closed-loop data.
extern const char* const kClosedLoopBiasWarning;

struct NonparametricEstimate {
  FrequencyResponse response;  // bands only for SPA
  bool closedLoopBias = false; // true when the data carry a reference channel (4.30)
  std::string warning;         // kClosedLoopBiasWarning when closedLoopBias
  int omittedFrequencies = 0;  // SPA: requested frequencies left out (no input power there)
  int window = 0;              // SPA: the lag window M used; ETFE: the smoothing width
  Termination termination = Termination::Failed;
  std::string message;
  double seconds = 0.0;
};

struct EtfeOptions {
  // Width in DFT bins of the Hann frequency window of (4.25); 0 or 1 gives the raw ETFE.
  int smoothingWidth = 0;
  // Frequencies (rad/s) to report; empty: every DFT frequency 2 pi k / (N T), k = 1..N/2.
  std::vector<double> omega;
  bool isValid(std::string* why) const;
};

// SPA's default lag window, chosen from the record length N and the sample time T: the
// window spans 1 s (a resolution of about 2 pi rad/s, fine enough for the
// resonances of an arm), at most N/10 lags (variance), and SITB's min(N/10, 30) where 1 s is
// fewer than 30 samples. SITB's 30 lags at 2 kHz span 15 ms: the covariances of an arm's
// velocity are cut while still large, and the estimate ripples every 2 pi / (30 T) = 419
// rad/s with notches and peaks that are not there. `reason` says which rule gave the width.
struct SpaWindow {
  int width = 0;
  std::string reason;
};
SpaWindow spaDefaultWindow(Eigen::Index samples, double sampleTime);

struct SpaOptions {
  // Lag-window width M (samples); 0 picks spaDefaultWindow (its reason is in the message).
  int windowWidth = 0;
  LagWindow window = LagWindow::Hann;
  // Frequencies (rad/s) to report; empty: 128 frequencies linear up to pi/T, as SITB.
  std::vector<double> omega;
  double level = 0.99;  // confidence level of the bands
  bool isValid(std::string* why) const;
};

// ETFE (4.24) Y_N/U_N; with smoothing (4.25) the weights are alpha_k = W(w - w_k) |U_N(w_k)|^2
// (a Hann window of smoothingWidth bins), i.e. smoothed cross spectrum over smoothed input
// spectrum. No confidence region.
NonparametricEstimate etfe(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double sampleTime,
                           const EtfeOptions& options = {});

// SPA (4.28): Blackman-Tukey spectra Phi_yu / Phi_u with covariances up to lag M weighted by the
// lag window. Variance Var G = C_W/N * Phi_v/Phi_u with Phi_v = Phi_y - |Phi_yu|^2/Phi_u and
// C_W = sum W(tau)^2 (Ljung 1999, (6.62)); bands on magnitude and phase at options.level.
NonparametricEstimate spa(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double sampleTime,
                          const SpaOptions& options = {});

// The same on a data set's input and output channels; sets closedLoopBias and warning when
// IdData::isClosedLoop(). Throws std::invalid_argument when input or output is missing.
NonparametricEstimate etfe(const IdData& data, const EtfeOptions& options = {});
NonparametricEstimate spa(const IdData& data, const SpaOptions& options = {});

// Input and output channels of data as vectors over a range (empty range: all samples).
// Throws std::invalid_argument when either channel is missing.
void inputOutput(const IdData& data, Eigen::VectorXd& u, Eigen::VectorXd& y,
                 SampleRange range = {});

}  // namespace flexarm
