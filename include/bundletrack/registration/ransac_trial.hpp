#pragma once

// How RANSAC trial k picks its three matches (paper IV-B), in plain arithmetic that the CPU
// RANSAC and the CUDA backend's trial kernel share, so both draw the same samples.

#include <cmath>
#include <cstdint>

#include "bundletrack/core/macros.hpp"

namespace bundletrack {

/// SplitMix64: trial k's sample depends only on (seed, k), whatever the thread schedule.
BUNDLETRACK_HOST_DEVICE inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// The three match indices in [0, n) of trial `trial`; false when two coincide.
BUNDLETRACK_HOST_DEVICE inline bool trialSample(std::uint64_t seed, std::uint64_t trial, int n, int sample[3]) {
  std::uint64_t state = splitmix64(seed ^ splitmix64(trial));
  for (int k = 0; k < 3; ++k) {
    state = splitmix64(state);
    sample[k] = int(state % std::uint64_t(n));
  }
  return sample[0] != sample[1] && sample[0] != sample[2] && sample[1] != sample[2];
}

/// Whether the triangle a, b, c (3 floats each) is far from collinear: its smallest height,
/// |ab x ac| / longest side, is at least min_height.
BUNDLETRACK_HOST_DEVICE inline bool wellSpread(const float* a, const float* b, const float* c, float min_height) {
  const float ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const float ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const float bc[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
  const auto norm = [](const float* v) { return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  const float cross[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
  float longest = norm(ab);
  if (norm(ac) > longest) longest = norm(ac);
  if (norm(bc) > longest) longest = norm(bc);
  return longest > 0.0f && norm(cross) / longest >= min_height;
}

}  // namespace bundletrack
