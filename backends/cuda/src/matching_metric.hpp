#pragma once

// The distances and the two-nearest update of the GPU matching kernel, host and device.

#include <cmath>
#include <cstdint>

#include "bundletrack/core/macros.hpp"

namespace bundletrack::cuda::detail {

/// Euclidean distance of two rows of `width` floats (cv::NORM_L2).
struct L2 {
  BUNDLETRACK_HOST_DEVICE static float distance(const float* a, const float* b, int width) {
    float sum = 0.0f;
    for (int k = 0; k < width; ++k) {
      const float d = a[k] - b[k];
      sum += d * d;
    }
    return sqrtf(sum);
  }
};

/// Differing bits of two rows of `width` 32-bit words (cv::NORM_HAMMING on the packed bytes).
struct Hamming {
  BUNDLETRACK_HOST_DEVICE static float distance(const std::uint32_t* a, const std::uint32_t* b, int width) {
    int bits = 0;
#ifdef __CUDA_ARCH__
    for (int k = 0; k < width; ++k) bits += __popc(a[k] ^ b[k]);
#else  // host: clears the lowest set bit until none is left
    for (int k = 0; k < width; ++k)
      for (std::uint32_t x = a[k] ^ b[k]; x != 0u; x &= x - 1u) ++bits;
#endif
    return float(bits);
  }
};

/// Keeps the nearest (`best`, its train row `nearest`) and second-nearest distances seen so far;
/// rows come in increasing order, so a tie keeps the lower index, as the CPU matcher does.
BUNDLETRACK_HOST_DEVICE inline void keepTwoNearest(float d, int row, float& best, float& second, int& nearest) {
  if (d < best) second = best, best = d, nearest = row;
  else if (d < second) second = d;
}

}  // namespace bundletrack::cuda::detail
