#pragma once

// The descriptor distances of the GPU matching kernel, host and device.

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

}  // namespace bundletrack::cuda::detail
