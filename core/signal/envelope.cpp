#include "core/signal/envelope.h"

#include <algorithm>
#include <stdexcept>

namespace flexarm {

EnvelopePyramid::EnvelopePyramid(const std::vector<double>& values) : values_(values) {
  if (values.size() >= (std::size_t{1} << 32))
    throw std::invalid_argument("EnvelopePyramid: at most 2^32 - 1 samples");
  // Level 0 from the samples, each further level from the one below.
  std::size_t n = values_.size();
  if (n <= kFanout) return;
  std::vector<Block> first((n + kFanout - 1) / kFanout);
  for (std::size_t b = 0; b < first.size(); ++b) {
    const std::size_t s = b * kFanout, e = std::min(n, s + kFanout);
    Block k{values_[s], values_[s], static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(s)};
    for (std::size_t i = s + 1; i < e; ++i) {
      if (values_[i] < k.min) k.min = values_[i], k.argmin = static_cast<std::uint32_t>(i);
      if (values_[i] > k.max) k.max = values_[i], k.argmax = static_cast<std::uint32_t>(i);
    }
    first[b] = k;
  }
  levels_.push_back(std::move(first));
  while (levels_.back().size() > kFanout) {
    const auto& below = levels_.back();
    std::vector<Block> up((below.size() + kFanout - 1) / kFanout);
    for (std::size_t b = 0; b < up.size(); ++b) {
      const std::size_t s = b * kFanout, e = std::min(below.size(), s + kFanout);
      Block k = below[s];
      for (std::size_t i = s + 1; i < e; ++i) {
        if (below[i].min < k.min) k.min = below[i].min, k.argmin = below[i].argmin;
        if (below[i].max > k.max) k.max = below[i].max, k.argmax = below[i].argmax;
      }
      up[b] = k;
    }
    levels_.push_back(std::move(up));
  }
}

void EnvelopePyramid::visiblePoints(std::size_t begin, std::size_t end, std::size_t maxPoints,
                                    std::vector<double>& position, std::vector<double>& value) const {
  position.clear();
  value.clear();
  end = std::min(end, values_.size());
  if (begin >= end) return;
  maxPoints = std::max<std::size_t>(maxPoints, 4);
  const std::size_t count = end - begin;
  if (count <= maxPoints || levels_.empty()) {
    position.reserve(count);
    value.reserve(count);
    for (std::size_t i = begin; i < end; ++i) {
      position.push_back(static_cast<double>(i));
      value.push_back(values_[i]);
    }
    return;
  }
  // The finest level whose blocks over the range give at most maxPoints points (two each).
  std::size_t level = 0, blockSize = kFanout;
  while (level + 1 < levels_.size() && 2 * (count / blockSize + 2) > maxPoints) {
    ++level;
    blockSize *= kFanout;
  }
  const auto& blocks = levels_[level];
  const std::size_t first = begin / blockSize, last = (end - 1) / blockSize;
  position.reserve(2 * (last - first + 1));
  value.reserve(2 * (last - first + 1));
  for (std::size_t b = first; b <= last; ++b) {
    const Block& k = blocks[b];
    const bool minFirst = k.argmin <= k.argmax;
    const std::uint32_t i0 = minFirst ? k.argmin : k.argmax, i1 = minFirst ? k.argmax : k.argmin;
    position.push_back(i0);
    value.push_back(minFirst ? k.min : k.max);
    if (i1 != i0) {
      position.push_back(i1);
      value.push_back(minFirst ? k.max : k.min);
    }
  }
}

}  // namespace flexarm
