#pragma once
// Several experiments joined in one input and output record (PolyEstimateOptions and
// SubspaceOptions::experimentLengths): where each one starts and how long it is.
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

namespace flexarm {

// An experiment's first sample and sample count in the joined u and y.
struct ExperimentSegment {
  Eigen::Index from, n;
};

// The experiments of lengths (empty: one of every sample); throws std::invalid_argument when
// they do not add up to total.
inline std::vector<ExperimentSegment> experimentSegments(const std::vector<Eigen::Index>& lengths, Eigen::Index total) {
  if (lengths.empty()) return {{0, total}};
  std::vector<ExperimentSegment> out;
  Eigen::Index from = 0;
  for (Eigen::Index n : lengths) {
    out.push_back({from, n});
    from += n;
  }
  if (from != total) throw std::invalid_argument("the experiments' lengths must add up to the samples of u and y");
  return out;
}

}  // namespace flexarm
