#pragma once

#include <algorithm>
#include <vector>

#include "bundletrack/core/object_box.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// 3-D IoU of the box posed by A and by B (oriented boxes). The intersection volume is measured
/// on a regular grid of samples^3 cell centres spanning box A: exact up to the grid's resolution
/// (relative error ~ 1 / samples on the boundary cells, below 1% at the default 128).
inline double boxIoU(const ObjectBox& box, const SE3d& A, const SE3d& B, int samples = 128) {
  const SE3d B_from_A = B.inverse() * A;  // A's object frame into B's object frame
  const Eigen::Vector3d size = box.max - box.min, step = size / double(samples);
  const Eigen::Matrix3d R = B_from_A.rotationMatrix();
  long inside = 0;
  for (int i = 0; i < samples; ++i) {
    for (int j = 0; j < samples; ++j) {
      // Along the k axis the samples inside B form one interval: intersect the line with B's slabs.
      const Eigen::Vector3d base = box.min + Eigen::Vector3d((i + 0.5) * step.x(), (j + 0.5) * step.y(), 0.0);
      const Eigen::Vector3d origin = B_from_A * base, direction = R.col(2);
      double lo = 0.0, hi = size.z();
      for (int a = 0; a < 3 && lo <= hi; ++a) {
        if (std::abs(direction[a]) < 1e-15) {
          if (origin[a] < box.min[a] || origin[a] > box.max[a]) hi = -1.0;
          continue;
        }
        double t0 = (box.min[a] - origin[a]) / direction[a], t1 = (box.max[a] - origin[a]) / direction[a];
        if (t0 > t1) std::swap(t0, t1);
        lo = std::max(lo, t0), hi = std::min(hi, t1);
      }
      if (hi < lo) continue;
      // Count cell centres z_k = (k + 0.5) step.z in [lo, hi].
      const long first = long(std::ceil(lo / step.z() - 0.5)), last = long(std::floor(hi / step.z() - 0.5));
      inside += std::max(0L, std::min<long>(last, samples - 1) - std::max<long>(first, 0) + 1);
    }
  }
  const double intersection = box.volume() * double(inside) / double(samples) / double(samples) / double(samples);
  return intersection / (2.0 * box.volume() - intersection);
}

}  // namespace bundletrack
