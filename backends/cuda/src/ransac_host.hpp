#pragma once

// What the host hands the RANSAC kernels and takes back: matched pairs in the plain layout of
// ransac_device.hpp, and fits as poses.

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

/// The pose of a row-major 3x4 [R | t].
inline SE3d poseOf(const double T[12]) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = T[4 * r + c];
  return SE3d(SO3d::fromMatrix(R), Eigen::Vector3d(T[3], T[7], T[11]));
}

}  // namespace bundletrack::cuda::detail
