#pragma once

#include <vector>

#include <Eigen/Core>

namespace bundletrack {

/// An axis-aligned box in the object frame (the model's bounds), placed in the camera by a pose.
struct ObjectBox {
  Eigen::Vector3d min, max;

  static ObjectBox bounding(const std::vector<Eigen::Vector3f>& points) {
    ObjectBox box{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
    for (const auto& p : points) box.min = box.min.cwiseMin(p.cast<double>()), box.max = box.max.cwiseMax(p.cast<double>());
    return box;
  }
  double volume() const { return (max - min).prod(); }
  std::vector<Eigen::Vector3d> corners() const {
    std::vector<Eigen::Vector3d> c;
    for (int k = 0; k < 8; ++k) c.emplace_back(k & 1 ? max.x() : min.x(), k & 2 ? max.y() : min.y(), k & 4 ? max.z() : min.z());
    return c;
  }
};

}  // namespace bundletrack
