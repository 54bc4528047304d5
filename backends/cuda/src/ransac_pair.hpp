#pragma once

// The inlier test of the GPU RANSAC kernel (paper IV-B), host and device, on the plain layout of
// ransac_device.hpp.

#include "host_device.hpp"

namespace bundletrack::cuda::detail {

/// Whether hypothesis T (row-major 3x4 [R | t]) moves the pair's first point within
/// max_squared_distance of its second and turns its first normal closer than cos_max_angle to the
/// second; `pair` is first point, second point, first normal, second normal (12 floats). The same
/// strict comparisons as bundletrack::InlierGate.
BUNDLETRACK_HOST_DEVICE inline bool isInlier(const float* T, const float* pair, float max_squared_distance,
                                             float cos_max_angle) {
  float distance = 0.0f, cosine = 0.0f;
  for (int r = 0; r < 3; ++r) {
    const float moved = T[4 * r] * pair[0] + T[4 * r + 1] * pair[1] + T[4 * r + 2] * pair[2] + T[4 * r + 3];
    const float turned = T[4 * r] * pair[6] + T[4 * r + 1] * pair[7] + T[4 * r + 2] * pair[8];
    distance += (moved - pair[3 + r]) * (moved - pair[3 + r]);
    cosine += turned * pair[9 + r];
  }
  return distance < max_squared_distance && cosine > cos_max_angle;
}

}  // namespace bundletrack::cuda::detail
