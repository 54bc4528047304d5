#pragma once

// What the host hands the RANSAC kernel: matched pairs and hypotheses in the plain layout of
// ransac_device.hpp.

#include <vector>

#include "bundletrack/registration/ransac.hpp"

namespace bundletrack::cuda::detail {

/// 12 floats a pair: first point, second point, first normal, second normal.
inline void packPairs(const MatchedPoints& pairs, std::vector<float>& out) {
  out.resize(12 * pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    float* pair = out.data() + 12 * k;
    for (int r = 0; r < 3; ++r) {
      pair[r] = pairs.first[k][r];
      pair[3 + r] = pairs.second[k][r];
      pair[6 + r] = pairs.first_normals[k][r];
      pair[9 + r] = pairs.second_normals[k][r];
    }
  }
}

/// 12 floats a hypothesis: row-major 3x4 [R | t].
inline void packHypotheses(const std::vector<SE3f>& hypotheses, std::vector<float>& out) {
  out.resize(12 * hypotheses.size());
  for (std::size_t h = 0; h < hypotheses.size(); ++h) {
    const Eigen::Matrix4f T = hypotheses[h].matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out[12 * h + std::size_t(4 * r + c)] = T(r, c);
  }
}

}  // namespace bundletrack::cuda::detail
