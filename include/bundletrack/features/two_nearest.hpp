#pragma once

// The nearest and second-nearest candidate of one keypoint, as the CPU matchers and the CUDA
// matching kernel keep them: one body for both compilers.

#include <cmath>

#include "bundletrack/core/macros.hpp"

namespace bundletrack {

struct TwoNearest {
  int index = -1;  ///< of the nearest candidate; -1: none yet
  float best = INFINITY, second = INFINITY;

  /// A tie keeps the lower index (as cv::BFMatcher, which offers in index order), in whatever order
  /// the candidates come.
  BUNDLETRACK_HOST_DEVICE void offer(float distance, int candidate) {
    if (distance < best || (distance == best && candidate < index)) second = best, best = distance, index = candidate;
    else if (distance < second) second = distance;
  }
  /// Lowe's ratio test; a lone candidate passes.
  BUNDLETRACK_HOST_DEVICE bool distinct(float ratio) const { return index >= 0 && best < ratio * second; }
};

}  // namespace bundletrack
