#pragma once
// Evaluation of estimated models: simulation, k-step prediction, fit % (5.2), frequency
// response with standard deviations and confidence bands (Gauss approximation), poles, zeros
// and the notch and peak frequencies of the seed's Tables 5.1, 5.3 and 5.5.
#include <complex>
#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"
#include "core/models/analysis.h"

namespace flexarm {

// Simulated output G(q) u = B/(A F) u with zero initial state.
Eigen::VectorXd simulate(const PolynomialModel& m, const Eigen::VectorXd& u);

// k-step-ahead prediction y(t | t-k) (k = 1 gives the predictor (4.5); k <= 0 simulates).
Eigen::VectorXd predict(const PolynomialModel& m, const Eigen::VectorXd& u,
                        const Eigen::VectorXd& y, int k);

// Fit % both ways, from the same sums (S_e = sum (y - yhat)^2, S_y = sum (y - mean y)^2):
//   seed52: the seed's (5.2), (1 - S_e / S_y) * 100, the share of the output's variance the
//           model explains (what FlexArm has always called "fit %");
//   nrmse:  MATLAB's compare / goodnessOfFit NRMSE fit, (1 - sqrt(S_e / S_y)) * 100.
// They are related by nrmse = 100 (1 - sqrt(1 - seed52 / 100)): 96.4 % (5.2) is 81.0 % NRMSE.
// Both are negative when the model is worse than the mean, -infinity when S_y is zero.
struct FitPercents {
  double seed52 = 0.0;
  double nrmse = 0.0;
};
// The one place both are formed: from the sums S_e and S_y (several experiments pool theirs).
FitPercents fitPercentsFromSums(double squaredErrors, double squaredDeviations);
// Over samples [begin, end) (end 0 means the whole signal).
FitPercents fitPercents(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, Eigen::Index begin = 0,
                        Eigen::Index end = 0);
// Fit % (5.2) alone: fitPercents(...).seed52.
double fitPercent(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, Eigen::Index begin = 0,
                  Eigen::Index end = 0);

// Frequency response with its uncertainty. Magnitude is |G|, phase in radians (unwrapped).
struct FrequencyResponse {
  std::vector<double> omega;  // rad/s
  std::vector<std::complex<double>> value;
  std::vector<double> magnitude, phase;
  std::vector<double> magnitudeStd, phaseStd;  // empty when there is no covariance
  double level = 0.99;                         // confidence level of the bands
  std::vector<double> magnitudeLower, magnitudeUpper, phaseLower, phaseUpper;
  bool hasBands() const { return !magnitudeStd.empty(); }
};

// Normal quantile z with P(|N(0,1)| <= z) = level (2.576 for 0.99).
double twoSidedNormalQuantile(double level);

// Logarithmic frequency grid of n points from wMin to wMax rad/s.
std::vector<double> logGrid(double wMin, double wMax, int n);

// G(e^{i w T}) of B/(A F) at the given frequencies (rad/s) and, when the model has a
// covariance P, std of magnitude and phase by linearization: Var = J P J^T with J = dG/dtheta
// (the Gauss approximation of Section 4.4.3); bands are value +- z std at `level`.
FrequencyResponse frequencyResponse(const PolynomialModel& m, const std::vector<double>& omega,
                                    double level = 0.99);

// Fills magnitude, phase (unwrapped) and bands from value and the 2x2 covariances of
// (Re G, Im G) per frequency (empty cov: no bands).
void finishFrequencyResponse(FrequencyResponse& r, const std::vector<Eigen::Matrix2d>& cov);

// Poles (roots of A F) and zeros (roots of B) in z.
std::vector<std::complex<double>> poles(const PolynomialModel& m);
std::vector<std::complex<double>> zeros(const PolynomialModel& m);

// Notches and peaks of a sampled response: magnitudeExtrema (core/models/analysis.h, FlexArm's
// one definition) of r.magnitude over r.omega, refined on `exact` |G| when given.
NotchesPeaks notchesAndPeaks(const FrequencyResponse& r, double minDepthDb = 1.0,
                             const std::function<double(double)>& exact = {});

// Notches and peaks from roots: complex zeros (notches) and poles (peaks) with damping ratio
// below maxDamping, as the frequency |log z| / T of each lightly damped pair.
NotchesPeaks notchesAndPeaksFromRoots(const std::vector<std::complex<double>>& zerosZ,
                                      const std::vector<std::complex<double>>& polesZ,
                                      double sampleTime, double maxDamping = 0.3);

}  // namespace flexarm
