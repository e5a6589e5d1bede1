#include "core/diagnosis/friction_temperature.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace flexarm {

double FrictionTemperatureModel::toReference(double fm, double temperatureC) const {
  return fm / (1.0 + alpha * (temperatureC - referenceC));
}

double FrictionTemperatureModel::atTemperature(double fm0, double temperatureC) const {
  return fm0 * (1.0 + alpha * (temperatureC - referenceC));
}

bool FrictionTemperatureModel::isValid(std::string* why) const {
  auto fail = [&](const std::string& s) {
    if (why) *why = s;
    return false;
  };
  if (!std::isfinite(alpha) || !std::isfinite(alphaStd) || alphaStd < 0.0)
    return fail("the friction temperature coefficient alpha must be a finite number");
  if (!std::isfinite(referenceC) || referenceC < -100.0 || referenceC > 300.0)
    return fail("the reference temperature must lie between -100 and 300 degC");
  for (double dt : {-40.0, 40.0})
    if (1.0 + alpha * dt <= 0.0)
      return fail("alpha = " + std::to_string(alpha) +
                  " 1/degC would make the friction negative within 40 degC of the reference");
  return true;
}

FrictionTemperatureFit fitFrictionTemperature(const std::vector<double>& temperatureC,
                                              const std::vector<double>& fm,
                                              const std::vector<double>& fmStd,
                                              double referenceC) {
  const std::size_t n = temperatureC.size();
  if (fm.size() != n || (!fmStd.empty() && fmStd.size() != n))
    throw std::invalid_argument("fitFrictionTemperature: temperatures, f_m and stds differ in length");
  if (!std::isfinite(referenceC))
    throw std::invalid_argument("fitFrictionTemperature: the reference temperature is not finite");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(temperatureC[i]) || !std::isfinite(fm[i]))
      throw std::invalid_argument("fitFrictionTemperature: a temperature or f_m is not finite");
    if (!fmStd.empty() && !(std::isfinite(fmStd[i]) && fmStd[i] > 0.0))
      throw std::invalid_argument("fitFrictionTemperature: every std of f_m must be positive");
  }
  FrictionTemperatureFit fit;
  fit.model.referenceC = referenceC;
  fit.model.logs = static_cast<int>(n);
  if (n < 3) {
    fit.message = "alpha needs healthy logs at three or more temperatures; " +
                  std::to_string(n) + " given, so f_m is compared without a temperature correction";
    return fit;
  }
  const auto [lo, hi] = std::minmax_element(temperatureC.begin(), temperatureC.end());
  if (*hi - *lo < 2.0) {
    std::ostringstream s;
    s << "the healthy logs span only " << (*hi - *lo)
      << " degC, too little to tell how f_m moves with temperature (2 degC at least)";
    fit.message = s.str();
    return fit;
  }
  // Straight line f_m = a + b (T - T_ref), weighted by 1/std^2.
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = fmStd.empty() ? 1.0 : 1.0 / (fmStd[i] * fmStd[i]);
    const double x = temperatureC[i] - referenceC;
    sw += w; sx += w * x; sy += w * fm[i]; sxx += w * x * x; sxy += w * x * fm[i];
  }
  const double det = sw * sxx - sx * sx;
  const double a = (sxx * sy - sx * sxy) / det;
  const double b = (sw * sxy - sx * sy) / det;
  double chi2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = fmStd.empty() ? 1.0 : 1.0 / (fmStd[i] * fmStd[i]);
    const double r = fm[i] - a - b * (temperatureC[i] - referenceC);
    chi2 += w * r * r;
  }
  const double dof = static_cast<double>(n - 2);
  // Without stds the weights are 1 and the scatter is the residual variance itself; with
  // stds it scales the covariance only when the logs scatter more than their stds say.
  const double scale = fmStd.empty() ? chi2 / dof : std::max(1.0, chi2 / dof);
  fit.scatter = fmStd.empty() ? 1.0 : chi2 / dof;
  const double varA = scale * sxx / det, varB = scale * sw / det, covAB = -scale * sx / det;
  if (!(a > 0.0)) {
    fit.message = "the healthy logs' friction at the reference temperature comes out " +
                  std::to_string(a) + ", not positive: no temperature correction";
    return fit;
  }
  fit.fm0 = a;
  fit.fm0Std = std::sqrt(std::max(0.0, varA));
  fit.model.alpha = b / a;
  // Delta method for alpha = b / a.
  const double da = -b / (a * a), db = 1.0 / a;
  fit.model.alphaStd = std::sqrt(std::max(0.0, da * da * varA + db * db * varB + 2 * da * db * covAB));
  std::string why;
  if (!fit.model.isValid(&why)) {
    fit.model.alpha = 0.0;
    fit.model.alphaStd = 0.0;
    fit.message = why;
    return fit;
  }
  fit.termination = Termination::Converged;
  std::ostringstream s;
  s << "alpha = " << fit.model.alpha * 100.0 << " +- " << fit.model.alphaStd * 100.0
    << " %/degC from " << n << " healthy logs at " << *lo << " to " << *hi << " degC (f_m0 "
    << a << " at " << referenceC << " degC)";
  fit.message = s.str();
  return fit;
}

}  // namespace flexarm
