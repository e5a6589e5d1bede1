#include "core/diagnosis/hypothesis_statistics.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace flexarm {

void WindowedSum::add(double value) {
  const double square = value * value;
  if (window_ == 0) {
    sum_ += square;
    ++count_;
    return;
  }
  if (ring_.empty()) ring_.assign(window_, 0.0);
  const std::size_t slot = count_ % window_;
  sum_ += square - ring_[slot];
  ring_[slot] = square;
  ++count_;
  // Adding and removing leaves rounding behind; a fresh sum every window keeps it exact.
  if (count_ % window_ == 0) recompute();
}

void WindowedSum::recompute() {
  sum_ = 0.0;
  for (double v : ring_) sum_ += v;
}

HypothesisStatistics::HypothesisStatistics(std::size_t hypotheses, std::size_t window)
    : sums_(hypotheses, WindowedSum(window)), full_(window), t_(hypotheses, 1.0) {
  if (hypotheses == 0) throw std::invalid_argument("the hypothesis bank needs a hypothesis");
}

const std::vector<double>& HypothesisStatistics::update(const std::vector<double>& errors,
                                                        double full) {
  if (errors.size() != sums_.size())
    throw std::invalid_argument("the hypothesis bank expects one error per hypothesis");
  full_.add(full);
  const double denominator = full_.sum();
  for (std::size_t h = 0; h < sums_.size(); ++h) {
    sums_[h].add(errors[h]);
    const double numerator = sums_[h].sum();
    // Before any error energy has been seen every hypothesis explains the data equally well.
    t_[h] = denominator > std::numeric_limits<double>::min()
                ? numerator / denominator
                : (numerator > 0.0 ? std::numeric_limits<double>::infinity() : 1.0);
  }
  return t_;
}

}  // namespace flexarm
