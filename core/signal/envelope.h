#pragma once
// Min/max envelope pyramid of a long signal, for drawing millions of samples quickly: for any
// visible range it yields at most about maxPoints points that keep every peak (each block's
// minimum and maximum, in the order they occur), so a plot looks like the full data.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace flexarm {

class EnvelopePyramid {
 public:
  explicit EnvelopePyramid(const std::vector<double>& values);

  std::size_t size() const { return values_.size(); }
  // Sample positions (indices, possibly of block extremes) and values to draw the samples in
  // [begin, end) with at most about maxPoints points. Raw samples when they fit.
  void visiblePoints(std::size_t begin, std::size_t end, std::size_t maxPoints,
                     std::vector<double>& position, std::vector<double>& value) const;

 private:
  struct Block {
    double min, max;
    std::uint32_t argmin, argmax;
  };
  static constexpr std::size_t kFanout = 4;
  std::vector<double> values_;
  std::vector<std::vector<Block>> levels_;  // levels_[k]: blocks of kFanout^(k+1) samples
};

}  // namespace flexarm
