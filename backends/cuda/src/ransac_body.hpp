#pragma once

// The per-thread bodies of the GPU RANSAC kernels (paper IV-B), host and device, on the plain
// layout of ransac_device.hpp: a pair is 12 floats (first point, second point, first normal,
// second normal), a hypothesis a row-major 3x4 [R | t].

#include <cstdint>

#include "bundletrack/core/macros.hpp"
#include "bundletrack/registration/ransac_trial.hpp"
#include "rigid_fit.hpp"

namespace bundletrack::cuda::detail {

/// Trial `trial` on n pairs: its sample by bundletrack::drawTrial's rules and, when the sample is
/// valid, the least-squares fit of its three pairs (double, and rounded to float for scoring).
BUNDLETRACK_HOST_DEVICE inline bool fitTrial(const float* pairs, int n, std::uint64_t seed, std::uint64_t trial,
                                             float min_spread, double fit[12], float hypothesis[12]) {
  int sample[3];
  if (!trialSample(seed, trial, n, sample)) return false;
  const float* first[3] = {pairs + 12 * sample[0], pairs + 12 * sample[1], pairs + 12 * sample[2]};
  const float* second[3] = {first[0] + 3, first[1] + 3, first[2] + 3};
  if (!wellSpread(first[0], first[1], first[2], min_spread) || !wellSpread(second[0], second[1], second[2], min_spread))
    return false;
  fitRigid3(first, second, fit);
  for (int i = 0; i < 12; ++i) hypothesis[i] = float(fit[i]);
  return true;
}

/// Whether hypothesis T moves the pair's first point within max_squared_distance of its second
/// and turns its first normal closer than cos_max_angle to the second: the same strict
/// comparisons as bundletrack::InlierGate.
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
