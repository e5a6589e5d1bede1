#pragma once
// Confidence regions of an estimate's poles and zeros: each pole (zero) moves with the
// estimated parameters, and the Gauss approximation of Section 4.4.3 carried to it gives the
// covariance of its real and imaginary parts, P_z = J P J^T (J by central differences, each
// perturbed root matched to the nearest of the nominal ones). The region at a level is the
// ellipse (z - z0)^T P_z^{-1} (z - z0) <= chi2_2(level) = -2 ln(1 - level). A real root of a
// real polynomial stays real under small changes, so its region is an interval on the axis
// (a flat ellipse). Physical models: the poles and transmission zeros of the continuous model
// (rad/s, core/models/analysis.h); black-box: the discrete poles of A F and zeros of B.
#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"
#include "core/models/physical_models.h"

namespace flexarm {

struct RootRegion {
  std::complex<double> value;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // of (Re, Im)
  bool zero = false;                                     // a zero, else a pole
  // Whether z lies inside the region at the level the regions were made for.
  bool contains(std::complex<double> z) const;
  double radiusSquared = 0.0;  // chi2_2(level)
  // The region's boundary, `points` points (closed: the first repeated at the end).
  std::vector<std::complex<double>> boundary(int points = 48) const;
};

// One region per pole and zero (poles first, as poles() and zeros() list them). Empty when
// the covariance is empty or does not match the free parameters. Exactly one model; throws
// std::invalid_argument otherwise.
std::vector<RootRegion> poleZeroRegions(const PhysicalModel* physical, const Eigen::MatrixXd& covariance,
                                        const std::vector<int>& freeIndices, const PolynomialModel* polynomial,
                                        double level = 0.99);

}  // namespace flexarm
